//! Shadow resources on the GPU: one depth array per kind of shadow storage (cascades, spot
//! lights, point-light cubes), VSM moments for spot and point lights and EVSM/MSM moments
//! for the suns' cascades, the frame's lights (the first 256 in a uniform array, read through
//! the constant cache, which is faster per pixel than a storage buffer on the H200; the rest
//! in a storage buffer that grows with the scene) and shadow views (a uniform array), the casters' per-view matrices, and the shadow bind
//! group (group 3) every material samples through `penumbra::lights`.
//! [`ShadowResources::prepare`] uploads one frame; the depth pass ([`depth_pass`]) renders
//! every view.

pub mod cascade_moments_pass;
pub mod casters;
pub mod clear;
pub mod depth_pass;
pub mod gpu;
mod groups;
pub mod jobs;
pub mod moment_storage;
pub mod moments_pass;
pub mod page_allocate;
pub mod page_changes;
pub mod page_mark;
pub mod page_moments;
pub mod page_pool;
pub mod page_render;
pub mod pages_pass;
pub mod shift;
pub mod standalone;
pub mod storage;
pub mod sun_moments;
pub mod visibility;

use std::sync::Arc;

use wgpu::util::DeviceExt;

use crate::ecs::light_views::FrameLights;
use crate::ecs::view_list::{ShadowViewKind, ShadowViews};
use crate::layout::{ShadowStorage, StorageMoments};
use crate::render::context::GpuContext;
use crate::render::counters::RenderCounters;
use crate::render::gpu_types::PoissonTapsGpu;
use crate::render::grow_buffer::GrowBuffer;
use crate::render::layouts::Layouts;
use crate::render::limits::{LimitError, UploadProblems};
use crate::render::shadows::casters::caster_clip_from_clip;
use crate::render::shadows::gpu::{
    CasterViewGpu, LightGpu, MAX_LIGHTS, MAX_SHADOW_VIEWS, SHADOW_FLAG_CONTACT_ONLY, SINGLE_PASS_VIEWS, ShadowViewGpu,
    assign_resolve_layers, pack_lights, pack_view, wrap_origin,
};
use crate::render::shadows::groups::{caster_groups, shadow_group};
use crate::render::shadows::moment_storage::MomentArray;
use crate::render::shadows::page_allocate::EntryGpu;
use crate::render::shadows::page_pool::{PagePool, PoolKey};
use crate::render::shadows::shift::ShiftScratch;
use crate::render::shadows::storage::{DepthArray, SHADOW_FORMAT};
use crate::render::shadows::sun_moments::sun_moment_need;
use crate::render::shadows::visibility::{ResolvePlan, VisibilityTarget};
use crate::settings::ShadowMode;
use crate::shader::ShaderLibrary;

/// Everything the shadow passes and the materials share.
pub struct ShadowResources {
    /// Each storage's depth array, at [`ShadowStorage::index`].
    maps: [Arc<DepthArray>; ShadowStorage::COUNT],
    /// Each storage's moments, at [`ShadowStorage::index`]: VSM for spot and point lights,
    /// EVSM or MSM (in [`cascade_moment_format`]) for the cascades; a stand-in while none of
    /// the storage's lights filters moments.
    moments: [Arc<MomentArray>; ShadowStorage::COUNT],
    /// The depth format of the suns' storages (those whose
    /// [`StorageDesc::sun_depth`](crate::layout::StorageDesc::sun_depth) is set; the renderer
    /// sets it from [`RenderOptions::sun_depth`](crate::render::RenderOptions::sun_depth)
    /// before [`prepare`](Self::prepare)); every other storage is [`SHADOW_FORMAT`].
    pub cascade_format: wgpu::TextureFormat,
    /// The depth layer scrolling views move their layers through
    /// ([`crate::render::shadows::shift`]), of their storage's side, while a view scrolls.
    pub shift_scratch: Option<ShiftScratch>,
    /// The paged sun's allocator (its table is group 3's `page_table`), while a sun is paged.
    pub pages: Option<PagePool>,
    /// A paged sun's receivers read no level finer than their pixel: its width per metre of
    /// view depth ([`pixel_per_depth`](crate::math::pages::pixel_per_depth)), set by the
    /// renderer each frame (the sun's `Light::range` in WGSL).
    pub page_pixel: f32,
    /// The page table bound while no sun is paged: one empty entry.
    no_page_table: wgpu::Buffer,
    lights: wgpu::Buffer,
    more_lights: GrowBuffer,
    views: wgpu::Buffer,
    caster_views: GrowBuffer,
    poisson_taps: wgpu::Buffer,
    /// Group 3 of the probe pass, the compute resolve, and forward materials when nothing is
    /// resolved (its resolved visibility is the 1×1 stand-in).
    pub group: wgpu::BindGroup,
    /// The resolved visibility and the group 3 that binds it, while the frame resolves
    /// visibility.
    pub resolved: Option<Resolved>,
    no_visibility: VisibilityTarget,
    /// Group 0 of the caster pipelines; bind view `i` at offset `i * 256`.
    pub caster_group: wgpu::BindGroup,
    /// Group 0 of the single-pass caster pipelines: views `i..i + SINGLE_PASS_VIEWS` at
    /// offset `i * 256` (the list is padded so every view can start a run).
    pub caster_run_group: wgpu::BindGroup,
    light_data: Vec<LightGpu>,
    view_data: Vec<ShadowViewGpu>,
    caster_data: Vec<CasterViewGpu>,
    /// The bytes last uploaded to the lights, views and caster views: a frame that packs
    /// the same data uploads nothing.
    uploaded: [Vec<u8>; 3],
}

/// The resolved visibility and the shadow group (group 3 of forward materials) that binds it.
pub struct Resolved {
    /// One layer per shadowed light.
    pub target: VisibilityTarget,
    /// The shadow group with `target` at its [`Slot::Resolved`](crate::layout::group::Slot::Resolved) binding.
    pub group: wgpu::BindGroup,
    /// Every shadowed light's layer holds its filtered shadow (none holds contact shadows
    /// alone), so the lighting pass may leave the filters out.
    pub filters: bool,
}

/// Whether a view of `storage` this frame filters with VSM, and whether one of those blurs
/// its moments.
pub(crate) fn vsm_use(lights: &FrameLights, views: &ShadowViews, storage: ShadowStorage) -> (bool, bool) {
    views
        .views
        .iter()
        .filter(|v| v.kind.storage == storage)
        .filter_map(|v| lights.view_settings(v))
        .filter(|s| s.filter.mode == ShadowMode::Vsm)
        .fold((false, false), |(_, blur), s| (true, blur || s.filter.vsm.blur > 0))
}

/// Writes `data` to `buffer` unless it is what `last` says was written last; returns whether
/// it wrote.
fn write_if_changed(queue: &wgpu::Queue, buffer: &wgpu::Buffer, last: &mut Vec<u8>, data: &[u8]) -> bool {
    if last.as_slice() == data {
        return false;
    }
    queue.write_buffer(buffer, 0, data);
    last.clear();
    last.extend_from_slice(data);
    true
}

impl ShadowResources {
    /// Empty buffers and 1×1 stand-in maps; VSM moments in `moments_format`.
    pub fn new(device: &wgpu::Device, layouts: &Layouts, moments_format: wgpu::TextureFormat) -> Self {
        let list = |label, size: usize| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let lights = list("lights", MAX_LIGHTS * size_of::<LightGpu>());
        let more_lights = GrowBuffer::new(device, "more lights", size_of::<LightGpu>() as u64);
        let views = list("shadow views", MAX_SHADOW_VIEWS * size_of::<ShadowViewGpu>());
        let caster_views = GrowBuffer::with_usage(
            device,
            "caster views",
            16 * size_of::<CasterViewGpu>() as u64,
            wgpu::BufferUsages::UNIFORM,
        );
        let poisson_taps = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("poisson taps"),
            contents: bytemuck::bytes_of(&PoissonTapsGpu::standard()),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let maps = ShadowStorage::ALL.map(|s| Arc::new(DepthArray::placeholder(device, s.desc().label, s.desc().cube)));
        let moments = ShadowStorage::ALL.map(|s| {
            Arc::new(MomentArray::placeholder(
                device,
                s.desc().moments_label,
                moments_format,
                s.desc().cube,
            ))
        });
        let no_visibility = VisibilityTarget::new(device, (1, 1, 1));
        let no_page_table = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("no page table"),
            contents: bytemuck::bytes_of(&EntryGpu::EMPTY),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let group = shadow_group(
            device,
            layouts,
            [&lights, &more_lights.buffer, &views, &poisson_taps, &no_page_table],
            &maps,
            &moments,
            &no_visibility,
        );
        let [caster_group, caster_run_group] = caster_groups(device, layouts, &caster_views.buffer);
        Self {
            resolved: None,
            no_visibility,
            maps,
            moments,
            cascade_format: SHADOW_FORMAT,
            shift_scratch: None,
            pages: None,
            page_pixel: 0.0,
            no_page_table,
            lights,
            more_lights,
            views,
            caster_views,
            poisson_taps,
            group,
            caster_group,
            caster_run_group,
            light_data: Vec::new(),
            view_data: Vec::new(),
            caster_data: Vec::new(),
            uploaded: Default::default(),
        }
    }

    /// The storage a view of `kind` renders into.
    pub fn storage(&self, kind: ShadowViewKind) -> &DepthArray {
        self.array(kind.storage)
    }

    /// The depth array of `storage`.
    pub fn array(&self, storage: ShadowStorage) -> &DepthArray {
        &self.maps[storage.index()]
    }

    /// The depth array of `storage`, shared: what the frame's graph imports for the nodes.
    pub fn shared_array(&self, storage: ShadowStorage) -> Arc<DepthArray> {
        self.maps[storage.index()].clone()
    }

    /// The moments of `storage`, shared like [`shared_array`](Self::shared_array).
    pub fn shared_moments(&self, storage: ShadowStorage) -> Arc<MomentArray> {
        self.moments[storage.index()].clone()
    }

    /// Bytes of shadow-map memory (depth and moments).
    pub fn memory_bytes(&self) -> u64 {
        let depth: u64 = self.maps.iter().map(|m| m.memory_bytes()).sum();
        let shift = self.shift_scratch.as_ref().map_or(0, ShiftScratch::memory_bytes);
        depth + shift + self.moments.iter().map(|m| m.memory_bytes()).sum::<u64>()
    }

    /// The moments of `storage`: VSM for spot and point lights, EVSM or MSM for the cascades.
    pub fn moments(&self, storage: ShadowStorage) -> &MomentArray {
        &self.moments[storage.index()]
    }

    /// Bytes of the resolved visibility (0 while nothing is resolved).
    pub fn resolved_memory_bytes(&self) -> u64 {
        self.resolved.as_ref().map_or(0, |r| r.target.memory_bytes())
    }

    /// Sizes the storages for this frame's views (counting new maps in `counters`), uploads
    /// the lights, views and caster matrices, and rebuilds the bind groups whose resources
    /// were replaced; returns true when the shadow group was rebuilt. Data too large for the
    /// device is refused before any upload; the lights past [`MAX_LIGHTS`] go to a storage
    /// buffer that grows with them.
    /// Views past [`MAX_SHADOW_VIEWS`] are left out with a warning in `problems`. With `resolve`,
    /// shadowed lights get layers of the resolved visibility ([`assign_resolve_layers`]).
    #[allow(clippy::too_many_arguments)]
    pub fn prepare(
        &mut self,
        (gpu, layouts, library): (&GpuContext, &Layouts, &mut ShaderLibrary),
        lights: &FrameLights,
        views: &ShadowViews,
        resolve: Option<ResolvePlan>,
        counters: &mut RenderCounters,
        problems: &mut UploadProblems,
    ) -> Result<bool, LimitError> {
        let device = &gpu.device;
        let mut rebuild = false;
        let pool = PoolKey::of(lights);
        if pool != self.pages.as_ref().map(|p| p.key) {
            if let Some(key) = pool {
                gpu.limits.check_target(key.atlas_side(), key.atlas_side())?;
            }
            self.pages = pool.map(|key| PagePool::new(device, &gpu.queue, library, key));
            rebuild = true;
        }
        for kind in ShadowStorage::ALL {
            let desc = kind.desc();
            // NOTE: a paged storage's array is its pool's atlas, not a layer per view.
            let (side, layers) = match (desc.paged, pool) {
                (false, _) => views.extent(kind),
                (true, Some(key)) => (key.atlas_side(), 1),
                (true, None) => (0, 0),
            };
            let format = if desc.sun_depth {
                self.cascade_format
            } else {
                SHADOW_FORMAT
            };
            let storage = &mut self.maps[kind.index()];
            if storage.needs(side, layers, format) {
                gpu.limits.check_target(side, side)?;
                *storage = Arc::new(DepthArray::new(device, desc.label, (side, layers), desc.cube, format));
                counters.shadow_maps += 1;
                rebuild = true;
            }
        }
        // NOTE: only a scrolling view whose layer does not wrap is moved through the scratch.
        let scrolling = views
            .views
            .iter()
            .find(|v| v.scroll.is_some() && wrap_origin(v, self.storage(v.kind).side).is_none());
        let side = scrolling.map_or(0, |v| self.storage(v.kind).side);
        if scrolling.is_none() {
            self.shift_scratch = None;
        } else if (self.shift_scratch.as_ref()).is_none_or(|s| s.side != side || s.format() != self.cascade_format) {
            self.shift_scratch = Some(ShiftScratch::new(device, side, self.cascade_format));
        }
        for kind in ShadowStorage::with_moments(StorageMoments::Vsm) {
            let (uses_vsm, blur) = vsm_use(lights, views, kind);
            let (side, layers) = if uses_vsm { views.extent(kind) } else { (0, 0) };
            let desc = kind.desc();
            let moments = &mut self.moments[kind.index()];
            if moments.needs(side, layers, blur) {
                let format = moments.moments.texture.format();
                *moments = Arc::new(MomentArray::new(
                    device,
                    desc.moments_label,
                    format,
                    (side, layers, 1),
                    desc.cube,
                    blur,
                ));
                counters.shadow_maps += 1;
                rebuild = true;
            }
        }
        let support = gpu.moment_support();
        // NOTE: the suns' moments (EVSM or MSM), in the format, size and mips they need.
        for kind in ShadowStorage::ALL {
            let Some(need) = sun_moment_need(kind, lights, views, pool.map(|k| k.atlas_side()), support) else {
                continue;
            };
            let moments = &mut self.moments[kind.index()];
            let other = moments.moments.texture.format() != need.format || moments.mips() != need.mips;
            if moments.needs(need.side, need.layers, need.blur) || other {
                let (label, extent) = (kind.desc().moments_label, (need.side, need.layers, need.mips));
                *moments = Arc::new(MomentArray::new(device, label, need.format, extent, false, need.blur));
                counters.shadow_maps += 1;
                rebuild = true;
            }
        }
        pack_lights(lights, views, support, &mut self.light_data);
        let unmarched = lights
            .all_settings()
            .skip(MAX_LIGHTS)
            .filter(|s| s.filter.contact.enabled())
            .count();
        if unmarched > 0 {
            problems.warnings.push(format!(
                "{unmarched} lights past the first {MAX_LIGHTS} ask for contact shadows, which are marched for the first {MAX_LIGHTS} lights only (suns, then spots, then points): they are drawn without them"
            ));
        }
        for (light, sun) in self.light_data.iter_mut().zip(&lights.suns) {
            if sun.paged.is_some() {
                light.range = self.page_pixel;
            }
        }
        self.view_data.clear();
        self.caster_data.clear();
        for view in &views.views {
            let storage = self.storage(view.kind);
            let (side, format) = (storage.side, storage.format());
            self.view_data.push(pack_view(lights, view, side, support));
            let clip_from_world = caster_clip_from_clip(format) * view.clip_from_world;
            self.caster_data
                .push(CasterViewGpu::new(clip_from_world, view.kind.single_pass_bit()));
        }
        // NOTE: a single-pass binding starting at the last view still lies inside the buffer.
        let padded = self.caster_data.len() + SINGLE_PASS_VIEWS - 1;
        self.caster_data.resize(padded, CasterViewGpu::new(glam::Mat4::ZERO, 0));
        let views_wanted = self.view_data.len();
        if views_wanted > MAX_SHADOW_VIEWS {
            problems.warnings.push(format!(
                "{views_wanted} shadow views this frame, but the list materials read holds {MAX_SHADOW_VIEWS}: the lights of the views past it are drawn with fewer cascades or faces, or unshadowed (lower ShadowLightBudget: fewer shadowed lights or cascades)"
            ));
        }
        self.view_data.truncate(MAX_SHADOW_VIEWS);
        let layers = assign_resolve_layers(&mut self.light_data, resolve.map(|r| r.filters));
        let contact_only = self.light_data.iter().any(|l| l.flags & SHADOW_FLAG_CONTACT_ONLY != 0);
        let [lights_sent, views_sent, casters_sent] = &mut self.uploaded;
        let light_bytes: &[u8] = bytemuck::cast_slice(&self.light_data);
        // NOTE: the grow buffer only grows for more data, which differs from what was sent.
        if lights_sent.as_slice() != light_bytes {
            let (first, more) = self.light_data.split_at(self.light_data.len().min(MAX_LIGHTS));
            gpu.queue.write_buffer(&self.lights, 0, bytemuck::cast_slice(first));
            rebuild |= self.more_lights.write(gpu, bytemuck::cast_slice(more))?;
            lights_sent.clear();
            lights_sent.extend_from_slice(light_bytes);
        }
        write_if_changed(
            &gpu.queue,
            &self.views,
            views_sent,
            bytemuck::cast_slice(&self.view_data),
        );
        let casters: &[u8] = bytemuck::cast_slice(&self.caster_data);
        // NOTE: the grow buffer only grows for more data, which differs from what was sent.
        if casters_sent.as_slice() != casters {
            if self.caster_views.write(gpu, casters)? {
                [self.caster_group, self.caster_run_group] = caster_groups(device, layouts, &self.caster_views.buffer);
            }
            casters_sent.clear();
            casters_sent.extend_from_slice(casters);
        }
        let table = self
            .pages
            .as_ref()
            .map_or(&self.no_page_table, |p| p.allocator.draw_buffers().2);
        let buffers = [
            &self.lights,
            &self.more_lights.buffer,
            &self.views,
            &self.poisson_taps,
            table,
        ];
        if rebuild {
            self.group = shadow_group(device, layouts, buffers, &self.maps, &self.moments, &self.no_visibility);
            counters.shadow_groups += 1;
        }
        match resolve {
            Some(ResolvePlan {
                size: (width, height), ..
            }) => {
                let extent = (width, height, layers.max(1));
                let kept = self.resolved.take().filter(|r| r.target.extent == extent);
                self.resolved = Some(match kept {
                    Some(resolved) if !rebuild => resolved,
                    kept => {
                        let target = kept.map_or_else(|| VisibilityTarget::new(device, extent), |r| r.target);
                        let group = shadow_group(device, layouts, buffers, &self.maps, &self.moments, &target);
                        counters.shadow_groups += 1;
                        Resolved {
                            target,
                            group,
                            filters: false,
                        }
                    }
                });
                if let Some(resolved) = self.resolved.as_mut() {
                    resolved.filters = !contact_only && resolve.is_some_and(|r| r.filters);
                }
            }
            None => self.resolved = None,
        }
        Ok(rebuild)
    }
}
