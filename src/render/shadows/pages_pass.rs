//! The paged clipmap's node: after the depth prepass, for the frame's paged sun, the
//! receivers mark the pages they read ([`PageMark`]), the pages a moved caster or a turned
//! light made stale are invalidated ([`page_changes`](crate::render::shadows::page_changes)),
//! the allocator maps the needed pages into the pool
//! ([`PageAllocator`](crate::render::shadows::page_allocate::PageAllocator)), and the listed
//! pages are cleared and drawn into the pool's atlas ([`PageRenderer`]); the lighting pass
//! then reads them through the page table. Everything runs on the GPU within the frame: the
//! CPU never learns which pages were needed. A frame that would mark what the last marked
//! frame did (the same camera, view size, instances, light, levels and footprint, and no
//! page stale) skips the marking, allocation and drawing: the pages are as they were. Culled
//! (nothing declared) without a paged sun or without the prepass; a multisampled camera
//! depth is marked from its sample 0.

use glam::{Mat4, UVec2, Vec2};

use crate::ecs::assets::{MaterialHandle, MeshHandle};
use crate::layout::ShadowStorage;
use crate::math::pages::{MarkRule, PagedLevel, pixel_per_depth};
use crate::render::frame::FrameContext;
use crate::render::frame_inputs::FrameInputs;
use crate::render::graph::{FrameResources, GraphResources, PassBuilder, RenderNode, TextureId};
use crate::render::scene_gpu::IndexList;
use crate::render::shadows::page_allocate::MAX_PAGED_LEVELS;
use crate::render::shadows::page_changes::{PagedFrame, TrackedCaster, invalidation};
use crate::render::shadows::page_mark::{MarkInput, PageMark};
use crate::render::shadows::page_moments::PageMoments;
use crate::render::shadows::page_pool::{PAGE_PASSES, PoolKey};
use crate::render::shadows::page_render::{PageCaster, PageRenderer, PageScene};
use crate::render::shadows::storage::DepthArray;
use crate::render::shadows::sun_moments::{cascade_moments, paged_moment_format};
use crate::settings::{ShadowBias, ShadowMode};
use crate::shader::contract::MAX_PENUMBRA_TEXELS;

/// Texels a level's window keeps clear for the receivers it serves (WGSL
/// `LEVEL_MARGIN_TEXELS`: the widest filter and a bilinear footprint).
const LEVEL_MARGIN_TEXELS: f64 = MAX_PENUMBRA_TEXELS as f64 + 2.0;

/// What the page drawing pipelines were made for.
#[derive(Clone, Copy, Debug, PartialEq)]
struct RendererKey {
    pool: PoolKey,
    atlas: u64,
    max_casters: u32,
    bias: ShadowBias,
    unclipped: bool,
}

/// How a caster of the frame is drawn: its mesh, and for an alpha-masked caster its material
/// with its base colour alpha and alpha cutoff.
type CasterDraw = (MeshHandle, Option<(MaterialHandle, Vec2)>);

/// What a frame's marking reads besides the pool, the light and the levels: a frame whose
/// key, light and levels are the last marked frame's, with no page stale, would mark and
/// allocate the same pages again.
#[derive(Clone, Copy, Debug, PartialEq)]
struct MarkKey {
    world_from_clip: Mat4,
    size: UVec2,
    multisampled: bool,
    rule: MarkRule,
    /// The instances' generation (any drawable changed: the camera depth may have).
    generation: u64,
}

/// This frame's work, found in `setup`.
struct Frame {
    depth: TextureId,
    atlas: TextureId,
    mark: MarkKey,
    bias: ShadowBias,
    /// How each caster of `now` is drawn.
    meshes: Vec<CasterDraw>,
    now: PagedFrame,
}

/// The page passes' node.
#[derive(Default)]
pub struct PagesPass {
    /// The marking, and whether it reads a multisampled depth.
    mark: Option<(bool, PageMark)>,
    /// The moments bake of a paged sun that filters moments.
    moments: Option<PageMoments>,
    renderer: Option<(RendererKey, PageRenderer)>,
    frame: Option<Frame>,
    /// What the last recorded frame's pages were drawn from (None: nothing drawn yet).
    last: Option<(PoolKey, PagedFrame)>,
    /// Frames allocated so far (the allocator's clock).
    frames: u32,
    /// What the last marked frame read.
    marked: Option<MarkKey>,
    /// Lists of an earlier frame, refilled by the next.
    spare: PagedFrame,
    spare_meshes: Vec<CasterDraw>,
    casters: Vec<PageCaster>,
}

/// The filter footprint a paged sun's receivers mark, as `paged_level` in
/// `penumbra::shadows::cascades` checks it: the PCF kernel (at most 5) and a bilinear tap,
/// PCSS's widest search (which a moment filter's contact `hardening` makes too), or a
/// fixed-blur moment filter's bilinear tap.
pub fn mark_radius(mode: ShadowMode, pcf_radius: u32, hardening: bool) -> f64 {
    let search = f64::from(MAX_PENUMBRA_TEXELS) + 2.0;
    match mode {
        ShadowMode::Pcss => search,
        ShadowMode::Evsm | ShadowMode::Evsm4 | ShadowMode::Msm | ShadowMode::Vsm if hardening => search,
        // NOTE: the moments are blurred within their page: a receiver reads a bilinear tap.
        ShadowMode::Evsm | ShadowMode::Evsm4 | ShadowMode::Msm | ShadowMode::Vsm => 2.0,
        _ => f64::from(pcf_radius.min(5)) + 2.0,
    }
}

impl RenderNode for PagesPass {
    fn name(&self) -> &'static str {
        "pages"
    }

    /// Reads the prepass's depth; writes the page pool.
    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, inputs: &FrameInputs<'_>) {
        self.frame = None;
        let lights = inputs.lights;
        let (Some(sun), Some((camera, _)), Some(depth)) = (lights.paged_sun(), inputs.view.camera, frame.depth) else {
            return;
        };
        // NOTE: the lists are the ones two frames back, refilled (their allocations kept).
        let mut now = std::mem::take(&mut self.spare);
        let mut meshes = std::mem::take(&mut self.spare_meshes);
        now.levels.clear();
        now.casters.clear();
        now.moments.clear();
        meshes.clear();
        now.light_rotation = sun.cascades.light_rotation;
        let s = &sun.settings;
        now.raster = (s.bias.slope_bias, s.bias.bias_clamp, s.map.depth_clamp);
        // NOTE: the sun's layout pushes its levels in order.
        let paged = inputs
            .shadow_views
            .views
            .iter()
            .filter(|v| v.kind.storage == ShadowStorage::Pages);
        now.levels.extend(paged.filter_map(|v| {
            let page = v.shading.page?;
            let level = PagedLevel {
                first_texel: page.first_page * i64::from(page.page_size),
                texel: f64::from(v.shading.texel_world_size),
            };
            Some((v.clip_from_world, level))
        }));
        let instances = inputs.instances;
        // NOTE: the alpha-masked casters come after the opaque ones.
        for (k, &i) in instances.casters.iter().enumerate() {
            let (Some(gpu), Some(key)) = (instances.gpu.get(i as usize), instances.keys.get(i as usize)) else {
                continue;
            };
            let masked = k >= instances.opaque_casters;
            let material = Vec2::new(gpu.base_color.w, gpu.alpha_cutoff);
            meshes.push((key.mesh, masked.then_some((key.material, material))));
            now.casters.push(TrackedCaster {
                world_from_local: gpu.world_from_local(),
                sphere: instances.caster_centers[k].extend(instances.caster_radii[k]),
            });
        }
        pass.read(depth);
        pass.write(frame.maps(ShadowStorage::Pages));
        pass.write(frame.moments(ShadowStorage::Pages));
        self.frame = Some(Frame {
            depth,
            atlas: frame.maps(ShadowStorage::Pages),
            mark: MarkKey {
                world_from_clip: camera.clip_from_world().inverse(),
                size: UVec2::new(frame.size.0, frame.size.1),
                multisampled: frame.samples > 1,
                rule: MarkRule {
                    radius: mark_radius(s.filter.mode, s.filter.pcf_radius, s.filter.moments.contact_hardening),
                    margin: LEVEL_MARGIN_TEXELS,
                    blend: f64::from(s.map.cascades.blend_width),
                    pixel: pixel_per_depth(camera.clip_from_world(), frame.size.1),
                },
                generation: instances.generation,
            },
            bias: s.bias,
            meshes,
            now,
        });
    }

    fn record(&mut self, ctx: &mut FrameContext<'_>, resources: &GraphResources, encoder: &mut wgpu::CommandEncoder) {
        let (Some(mut frame), Some(pool), Some((vertices, indices))) =
            (self.frame.take(), ctx.shadows.pages.as_ref(), ctx.scene.mesh_buffers())
        else {
            return;
        };
        let support = ctx.gpu.moment_support();
        let format = paged_moment_format(ctx.lights, support);
        if let (Some(sun), Some(_)) = (ctx.lights.paged_sun(), format) {
            let count = frame.now.levels.len().min(MAX_PAGED_LEVELS);
            let moments = (0..count).map_while(|l| cascade_moments(sun, l, support.fp32_filterable));
            frame.now.moments.extend(moments);
        }
        let (device, queue) = (&ctx.gpu.device, &ctx.gpu.queue);
        let allocator = &pool.allocator;
        let layout = pool.key.layout;
        let levels: Vec<PagedLevel> = frame.now.levels.iter().map(|(_, l)| *l).collect();
        // NOTE: a new pool holds nothing, so nothing in it is stale.
        let last = self.last.as_ref().filter(|(key, _)| *key == pool.key).map(|(_, f)| f);
        let stale = invalidation(&layout, last, &frame.now);
        let repeat = last.is_some_and(|l| l.light_rotation == frame.now.light_rotation && l.levels == frame.now.levels)
            && stale.is_empty()
            && self.marked == Some(frame.mark);
        if repeat {
            allocator.record_still(encoder);
            self.keep(pool.key, frame);
            return;
        }
        self.marked = Some(frame.mark);
        ctx.counters.page_markings += 1;
        let multisampled = frame.mark.multisampled;
        if self.mark.as_ref().is_none_or(|(m, _)| *m != multisampled) {
            self.mark = Some((multisampled, PageMark::new(device, ctx.library, multisampled)));
        }
        let Some((_, mark)) = self.mark.as_mut() else {
            return;
        };
        // NOTE: the depth is a transient of this frame: its group is made per frame.
        let group = mark.group(device, resources.view(frame.depth), &allocator.needed);
        let input = MarkInput {
            world_from_clip: frame.mark.world_from_clip,
            light_rotation: frame.now.light_rotation,
            layout,
            levels: &levels,
            rule: frame.mark.rule,
        };
        let timestamps = ctx.timer.compute_pass(PAGE_PASSES[0]);
        mark.record(
            (queue, encoder),
            (&group, frame.mark.size),
            &input,
            &allocator.needed,
            timestamps,
        );
        if !stale.is_empty() {
            allocator.record_invalidation(queue, encoder, &stale.rects, stale.all);
        }
        self.frames += 1;
        let windows: Vec<_> = levels.iter().map(|l| layout.page_of(l.first_texel)).collect();
        let timestamps = ctx.timer.compute_pass(PAGE_PASSES[1]);
        allocator.record(queue, encoder, (self.frames, &windows), timestamps);
        self.casters.clear();
        for (caster, (mesh, masked)) in frame.now.casters.iter().zip(&frame.meshes) {
            let Some(range) = ctx.scene.mesh_ranges.get(mesh.0 as usize) else {
                continue;
            };
            let first = range.first_of(IndexList::for_caster(masked.is_some(), false));
            self.casters.push(PageCaster {
                world_from_local: caster.world_from_local,
                sphere: caster.sphere,
                indices: (first, range.index_count, range.base_vertex),
                masked: masked.map(|(material, m)| (material.0 as usize, m)),
            });
        }
        let atlas = resources.shared::<DepthArray>(frame.atlas);
        let key = RendererKey {
            pool: pool.key,
            atlas: atlas.id,
            max_casters: (self.casters.len() as u32).max(64).next_power_of_two(),
            bias: frame.bias,
            unclipped: ctx.gpu.unclipped_depth && frame.now.raster.2,
        };
        // NOTE: the pipelines are kept while the caster list fits them.
        let fits = self.renderer.as_ref().is_some_and(|(k, _)| {
            RendererKey {
                max_casters: k.max_casters,
                ..key
            } == *k
                && k.max_casters >= self.casters.len() as u32
        });
        if !fits {
            let renderer = PageRenderer::new(
                (device, queue, ctx.gpu.indirect_first_instance),
                (ctx.library, &ctx.layouts.material),
                (allocator, &atlas),
                key.max_casters,
                &key.bias,
                key.unclipped,
            );
            self.renderer = Some((key, renderer));
        }
        let Some((_, renderer)) = self.renderer.as_mut() else {
            return;
        };
        let scene = PageScene {
            light_rotation: frame.now.light_rotation,
            levels: &frame.now.levels,
            casters: &self.casters,
            materials: &ctx.scene.material_groups,
            geometry: (vertices, indices),
        };
        let timestamps = ctx.timer.pass(PAGE_PASSES[2]);
        renderer.record((queue, encoder), allocator, &scene, timestamps);
        let moments = ctx.shadows.moments(ShadowStorage::Pages);
        if let Some(format) = format.filter(|_| moments.side == atlas.side && !frame.now.moments.is_empty()) {
            if self.moments.as_ref().is_none_or(|m| m.format != format) {
                self.moments = Some(PageMoments::new(device, ctx.library, format));
            }
            if let Some(bake) = self.moments.as_mut() {
                let timestamps = ctx.timer.compute_pass(PAGE_PASSES[3]);
                let size = (pool.key.tiles(), layout.page_size);
                let levels = &frame.now.moments;
                bake.record(
                    (device, queue, encoder),
                    allocator,
                    (&atlas, moments),
                    size,
                    levels,
                    timestamps,
                );
            }
        }
        self.keep(pool.key, frame);
    }
}

impl PagesPass {
    /// Keeps what `frame`'s pages were drawn from (for `pool`) as the last frame's, and the
    /// lists it replaces for the next frame to refill.
    fn keep(&mut self, pool: PoolKey, frame: Frame) {
        if let Some((_, old)) = self.last.replace((pool, frame.now)) {
            self.spare = old;
        }
        self.spare_meshes = frame.meshes;
    }
}
