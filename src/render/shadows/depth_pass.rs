//! The depth pass: renders the casters of every shadow view of the frame whose layer does not
//! already hold it into its layer of its kind's storage (a paged storage's views are drawn
//! by the page passes, [`pages_pass`](crate::render::shadows::pages_pass)). A layer remembers the content
//! version ([`ShadowView::version`]) it was last drawn with, the storage allocation it
//! belongs to, and the tiles its casters wrote ([`ShadowView::footprint`]); a view whose
//! version is already there is skipped (a still scene draws no shadow map after its first
//! frame). Per view drawn: clear what the layer holds to the reverse-Z far value (0) — only
//! the tiles the last draw wrote, with a scissored quad, unless those are unknown or most of
//! the layer (a whole 2048² clear costs about 0.3 ms on the H100, more than drawing a small
//! scene's casters); a view with no caster over a clean layer records no pass at all — then
//! restrict the viewport to the view's resolution, draw the opaque group with the depth-only
//! pipeline (no fragment stage), then the alpha-masked group with the alpha-test pipeline,
//! both with the light's slope-scaled depth bias and, where the adapter allows, unclipped
//! depth so casters in front of the near plane are flattened onto it.
//!
//! With single-pass cascades, the cascades of a sun that must be drawn go through one
//! multiview pass per run of consecutive layers: the sun's casters listed once
//! ([`ShadowViews::single_pass`](crate::ecs::ShadowViews::single_pass)), one instanced draw per
//! batch, each instance dropped in the vertex stage from the cascades it does not touch.

use std::fmt::Write;
use std::num::NonZeroU32;
use std::sync::Arc;

use crate::ecs::draw_groups::DrawGroup;
use crate::ecs::light_views::FrameLights;
use crate::ecs::view_list::{ShadowView, ShadowViewKind};
use crate::layout::ShadowStorage;
use crate::math::cascades::MAX_SUN_VIEWS;
use crate::math::footprint::{TILES, TexelRect, TileMask};
use crate::math::light_budget::LightKind;
use crate::render::draw::{draw_batches, draw_culled};
use crate::render::frame::FrameContext;
use crate::render::frame_inputs::FrameInputs;
use crate::render::graph::{FrameResources, GraphResources, PassBuilder, RenderNode, TextureId};
use crate::render::scene_gpu::IndexList;
use crate::render::shadows::casters::{CasterKey, CasterPipelines};
use crate::render::shadows::clear::ClearPipelines;
use crate::render::shadows::gpu::CasterViewGpu;
use crate::render::shadows::shift::LevelShift;
use crate::render::shadows::storage::DepthArray;
use crate::settings::MAX_CASCADES;

/// The shadow-map node.
#[derive(Default)]
pub struct DepthPass {
    pipelines: CasterPipelines,
    /// Timing names, one per view, reused between frames.
    names: Vec<String>,
    /// Partial clears of a layer.
    clears: ClearPipelines,
    /// Per storage (cascades, spot lights, point lights): the allocation `held` refers to, and
    /// what each layer holds.
    held: [(u64, Vec<Layer>); ShadowStorage::COUNT],
    /// Views whose layer holds them are skipped ([`RenderOptions::shadow_cache`](crate::render::RenderOptions)).
    cache: bool,
    /// Views of consecutive cascade layers made for multiview passes: (storage id, first
    /// layer, layers, view).
    ranges: Vec<(u64, u32, u32, wgpu::TextureView)>,
    /// The texel rectangles of this draw's partial clear.
    runs: Vec<TexelRect>,
    /// Moves scrolling views' layers with their windows.
    shift: LevelShift,
    /// This frame's storages' handles in the graph, at [`ShadowStorage::index`].
    maps: Vec<TextureId>,
    /// This frame's storages, from the graph's resources.
    storages: Vec<Arc<DepthArray>>,
    /// Per view: it is culled on the GPU and drawn this frame (claimed before the culling).
    gpu_drawn: Vec<bool>,
}

/// What a layer of a storage holds.
#[derive(Clone, Copy, Debug, Default)]
struct Layer {
    /// Content version of the view last drawn into it (0: none).
    version: u64,
    /// Tiles that may hold a caster's depth (the rest holds the far depth); `None`: not
    /// known, the whole layer.
    written: Option<TileMask>,
    /// The window a scrolling view's content was drawn for (grid texel of its first texel).
    window: Option<glam::I64Vec2>,
    /// Where the layer holds that window's first texel (`[0, 0]` unless it wraps).
    origin: [u32; 2],
}

#[path = "depth_scroll.rs"]
mod scroll;

/// The word timing names give a light of `kind`.
pub(crate) fn short_word(kind: LightKind) -> &'static str {
    match kind {
        LightKind::Directional => "sun",
        LightKind::Spot => "spot",
        LightKind::Point => "point",
    }
}

/// Writes the timing name of `view` into `name`: `shadow cascade c` for the first sun's
/// cascades (as before several suns existed), `shadow sun k cascade c` for the others,
/// `shadow spot k` for spot lights, `shadow point k face f` for point lights' cube faces.
pub fn view_name(lights: &FrameLights, view: &ShadowView, name: &mut String) {
    name.clear();
    let kind = view.light_kind;
    let light = view.light as usize - lights.light_index(kind, 0);
    let word = view.kind.storage.desc().view_word;
    // NOTE: writing to a String cannot fail.
    let _ = match (kind, word.is_empty()) {
        // NOTE: the first sun's views are named as before several suns existed.
        (LightKind::Directional, false) if light == 0 => write!(name, "shadow {word} {}", view.kind.index),
        (_, false) => write!(name, "shadow {} {light} {word} {}", short_word(kind), view.kind.index),
        (_, true) => write!(name, "shadow {} {light}", short_word(kind)),
    };
}

impl RenderNode for DepthPass {
    fn name(&self) -> &'static str {
        "shadow"
    }

    /// Writes each storage that has a view this frame (the layer views it renders into
    /// belong to that storage); with no shadow view nothing is written and the node is
    /// culled. Which views are drawn is decided while recording, when the storage is known.
    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, inputs: &FrameInputs<'_>) {
        self.cache = inputs.options.shadow_cache;
        self.maps.clear();
        self.maps.extend(frame.shadow_maps);
        let views = &inputs.shadow_views.views;
        // NOTE: a paged storage's views are drawn by the page passes.
        for storage in ShadowStorage::ALL.into_iter().filter(|s| !s.desc().paged) {
            if views.iter().any(|v| v.kind.storage == storage) {
                pass.write(frame.maps(storage));
            }
        }
    }

    /// Forgets what every layer holds: a scrolling view's changes of this frame (strips,
    /// moved casters) were never drawn, so its layer is drawn whole next.
    fn skipped(&mut self) {
        for (_, layers) in &mut self.held {
            layers.clear();
        }
    }

    fn record(&mut self, ctx: &mut FrameContext<'_>, res: &GraphResources, encoder: &mut wgpu::CommandEncoder) {
        self.shift.begin_frame();
        self.storages.clear();
        self.storages
            .extend(self.maps.iter().map(|&id| res.shared::<DepthArray>(id)));
        if ctx.scene.mesh_buffers().is_none() {
            return;
        }
        let views = ctx.shadow_views;
        if self.names.len() < views.views.len() {
            self.names.resize_with(views.views.len(), String::new);
        }
        // NOTE: the views the GPU culls are claimed first, so one dispatch culls those drawn.
        self.gpu_drawn.clear();
        for v in 0..views.views.len() {
            let drawn = ctx.shadow_cull.culls(v)
                && match views.views[v].scroll {
                    Some(_) => self.claim_scrolled(ctx, v),
                    None => self.claim(ctx, v),
                };
            self.gpu_drawn.push(drawn);
        }
        ctx.shadow_cull
            .record(&ctx.gpu.queue, encoder, ctx.timer, &self.gpu_drawn);
        // NOTE: culling listed a sun's casters once exactly where its cascades are drawn in
        // one pass (ecs::single_pass::single_pass_cascades); a run holds as many as the
        // device draws at once.
        let most = (ctx.gpu.multiview_views as usize).min(MAX_CASCADES);
        let mut v = 0;
        while v < views.views.len() {
            if views.views[v].kind.storage.desc().paged {
                v += 1;
                continue;
            }
            let run_group = views
                .single_pass
                .iter()
                .find(|g| g.first_view as usize == v && g.views >= 2);
            let Some(run_group) = run_group else {
                if ctx.shadow_cull.culls(v) && views.views[v].scroll.is_some() {
                    self.draw_gpu_scrolled(ctx, encoder, v);
                } else if ctx.shadow_cull.culls(v) {
                    if self.gpu_drawn[v] {
                        self.draw(ctx, encoder, v, 1, &views.groups[v]);
                    }
                } else if views.views[v].scroll.is_some() {
                    self.scroll_or_draw(ctx, encoder, v);
                } else if self.claim(ctx, v) {
                    self.draw(ctx, encoder, v, 1, &views.groups[v]);
                }
                v += 1;
                continue;
            };
            // NOTE: the cascades to draw are taken in runs of consecutive layers, each run one
            // multiview pass (a lone cascade gets its own pass and list).
            let count = run_group.views as usize;
            let mut redraw = [false; MAX_SUN_VIEWS];
            for (c, redraw) in redraw.iter_mut().enumerate().take(count) {
                *redraw = self.claim(ctx, v + c);
            }
            let mut c = 0;
            while c < count {
                let end = (c..count)
                    .take(most)
                    .find(|&e| !redraw[e])
                    .unwrap_or(count.min(c + most));
                match end - c {
                    0 => c += 1,
                    1 => {
                        self.draw(ctx, encoder, v + c, 1, &views.groups[v + c]);
                        c = end;
                    }
                    n => {
                        self.draw(ctx, encoder, v + c, n, &run_group.group);
                        c = end;
                    }
                }
            }
            v += count;
        }
    }
}

impl DepthPass {
    /// The storage a view of `kind` renders into, this frame.
    fn storage(&self, kind: ShadowViewKind) -> Arc<DepthArray> {
        self.storages[kind.storage.index()].clone()
    }

    /// Whether view `v` must be drawn (its layer does not hold its content version, or the
    /// cache is off); marks the layer as holding it.
    fn claim(&mut self, ctx: &FrameContext<'_>, v: usize) -> bool {
        let view = &ctx.shadow_views.views[v];
        let storage = self.storage(view.kind);
        // NOTE: a new allocation holds nothing; every layer of it is drawn again.
        let (id, layers) = &mut self.held[view.kind.storage.index()];
        if *id != storage.id {
            *id = storage.id;
            layers.clear();
        }
        let slot = view.slot as usize;
        if self.cache && layers.get(slot).map(|l| l.version) == Some(view.version) {
            return false;
        }
        if slot >= storage.layer_views.len() || ctx.lights.view_settings(view).is_none() {
            return false;
        }
        if layers.len() <= slot {
            layers.resize(slot + 1, Layer::default());
        }
        layers[slot].version = view.version;
        true
    }

    /// What must be cleared before views `first..first + count` (claimed, in consecutive
    /// layers) are drawn: the tiles their layers hold, or `None` for the whole layers (not
    /// known, or most of them). Records the views' footprints as what the layers hold next.
    fn take_clear(&mut self, ctx: &FrameContext<'_>, first: usize, count: usize) -> Option<TileMask> {
        let mut clear = Some(TileMask::EMPTY);
        for view in &ctx.shadow_views.views[first..first + count] {
            let layer = &mut self.held[view.kind.storage.index()].1[view.slot as usize];
            clear = clear.zip(layer.written).map(|(c, w)| c.union(w));
            layer.written = Some(view.footprint);
        }
        clear.filter(|c| c.count() * 2 < TILES * TILES)
    }

    /// The view of `count` layers from `first` of the cascade storage, made on first use.
    fn layer_range(&mut self, storage: &DepthArray, first: u32, count: u32) -> wgpu::TextureView {
        self.ranges.retain(|r| r.0 == storage.id);
        if let Some(r) = self.ranges.iter().find(|r| (r.1, r.2) == (first, count)) {
            return r.3.clone();
        }
        let view = storage.texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("cascade run"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            base_array_layer: first,
            array_layer_count: Some(count),
            ..Default::default()
        });
        self.ranges.push((storage.id, first, count, view.clone()));
        view
    }

    /// Draws views `first..first + count` (one light's, in consecutive layers) from `group`:
    /// one view per pass when `count` is 1, else one multiview pass over a packed
    /// single-pass list.
    fn draw(
        &mut self,
        ctx: &mut FrameContext<'_>,
        encoder: &mut wgpu::CommandEncoder,
        first: usize,
        count: usize,
        group: &DrawGroup,
    ) {
        let Some((vertices, indices)) = ctx.scene.mesh_buffers() else {
            return;
        };
        let view = &ctx.shadow_views.views[first];
        let Some(settings) = ctx.lights.view_settings(view) else {
            return;
        };
        let clear = self.take_clear(ctx, first, count);
        if clear.is_some_and(|c| c.is_empty()) && group.opaque.is_empty() && group.masked.is_empty() {
            // NOTE: the layers already hold only the far depth, and nothing is drawn.
            return;
        }
        let views = if count > 1 { count as u32 } else { 0 };
        let unclipped = ctx.gpu.unclipped_depth;
        let format = self.storage(view.kind).format();
        let mut built = 0;
        if let Some(tiles) = clear {
            tiles.texel_runs(view.resolution, &mut self.runs);
        }
        let clear_pipeline = clear
            .filter(|c| !c.is_empty())
            .map(|_| self.clears.get(&ctx.gpu.device, ctx.library, (views, format)).clone());
        let mut pipeline = |masked| {
            let key = CasterKey::new(settings, masked, unclipped, format).with_views(views);
            self.pipelines
                .get(&ctx.gpu.device, ctx.layouts, ctx.library, key, &mut built)
                .clone()
        };
        let opaque = pipeline(false);
        let masked = (!group.masked.is_empty()).then(|| pipeline(true));
        ctx.counters.caster_pipelines += built;
        ctx.shadow_views_drawn += count as u32;
        let storage = self.storage(view.kind);
        // NOTE: a load-op clear clears the whole layer, whatever the view's viewport.
        let layer_texels = u64::from(storage.side).pow(2);
        let runs: u64 = self.runs.iter().map(|r| r.area()).sum();
        ctx.shadow_cleared_texels += clear.map_or(layer_texels, |_| runs) * count as u64;
        ctx.shadow_drawn_texels += u64::from(view.resolution).pow(2) * count as u64;
        let target = if count > 1 {
            self.layer_range(&storage, view.slot, count as u32)
        } else {
            storage.layer_views[view.slot as usize].clone()
        };
        let name = &mut self.names[first];
        if count > 1 {
            run_name(view.light, view.kind.index, count, name);
        } else {
            view_name(ctx.lights, view, name);
        }
        let name = self.names[first].as_str();
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(name),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &target,
                depth_ops: Some(wgpu::Operations {
                    load: match clear {
                        Some(_) => wgpu::LoadOp::Load,
                        None => wgpu::LoadOp::Clear(0.0),
                    },
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: ctx.timer.pass(name),
            occlusion_query_set: None,
            multiview_mask: NonZeroU32::new((1 << views) - 1),
        });
        if view.resolution < storage.side {
            let side = view.resolution as f32;
            pass.set_viewport(0.0, 0.0, side, side, 0.0, 1.0);
        }
        if let Some(pipeline) = &clear_pipeline {
            pass.set_pipeline(pipeline);
            for rect in &self.runs {
                pass.set_scissor_rect(rect.x0, rect.y0, rect.x1 - rect.x0, rect.y1 - rect.y0);
                pass.draw(0..6, 0..1);
            }
            pass.set_scissor_rect(0, 0, storage.side, storage.side);
        }
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
        let offset = (first * size_of::<CasterViewGpu>()) as u32;
        let views_group = if count > 1 {
            &ctx.shadows.caster_run_group
        } else {
            &ctx.shadows.caster_group
        };
        pass.set_bind_group(0, views_group, &[offset]);
        // NOTE: a view the GPU culled draws its batches from the culling's arguments.
        let culled = ctx.shadow_cull.draws(first).filter(|_| count == 1);
        let instances = culled.map_or(&ctx.scene.shadow_instances_group, |(group, ..)| group);
        pass.set_bind_group(1, instances, &[]);
        pass.set_pipeline(&opaque);
        let mut draw = |pass: &mut wgpu::RenderPass<'_>, batches, masked, first_arg| match culled {
            Some((_, args, base)) => draw_culled(
                pass,
                ctx.scene,
                batches,
                (masked, &[]),
                (args, base + first_arg),
                ctx.draw_args,
            ),
            None => {
                let list = IndexList::for_caster(masked, count > 1);
                draw_batches(pass, (ctx.scene, list), batches, (masked, &[]), ctx.draw_args)
            }
        };
        let mut calls = draw(&mut pass, &group.opaque, false, 0);
        if let Some(masked) = &masked {
            pass.set_pipeline(masked);
            calls += draw(&mut pass, &group.masked, true, group.opaque.len() as u32);
        }
        ctx.draw_calls += calls;
        ctx.shadow_draw_calls += calls;
    }
}

/// Writes the timing name of a single-pass run of `count` cascades from cascade `first` of
/// light `light`: `shadow cascades 0-3` for the first sun, `shadow sun k cascades a-b` for
/// the others.
fn run_name(light: u32, first: u32, count: usize, name: &mut String) {
    name.clear();
    let last = first as usize + count - 1;
    // NOTE: writing to a String cannot fail.
    let _ = if light == 0 {
        write!(name, "shadow cascades {first}-{last}")
    } else {
        write!(name, "shadow sun {light} cascades {first}-{last}")
    };
}
