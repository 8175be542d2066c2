//! The VSM moments pass (`shaders/shadow_moments.wgsl`): after the depth pass, every spot or
//! point light that filters with VSM and whose depth changed gets its moments made again —
//! one compute pass per light (`shadow moments spot k`, `shadow moments point k`) that turns
//! its depth layers into moments `(z, z²)` of its normalised distance and, with
//! `vsm_blur > 0`, blurs them along x into the scratch (one light's layers) and along y back. A point
//! light's six faces are made together, so the blur can cross their edges. Like the depth
//! pass, it remembers which content version each layer's moments hold, so a still light costs
//! nothing.

use std::borrow::Cow;
use std::fmt::Write;

use bytemuck::{Pod, Zeroable};

use crate::layout::{ShadowStorage, StorageMoments};
use crate::math::light_budget::LightKind;
use crate::math::point::FACES;
use crate::render::frame::FrameContext;
use crate::render::frame_inputs::FrameInputs;
use crate::render::graph::{FrameResources, GraphResources, PassBuilder, RenderNode, TextureId};
use crate::render::layouts::entry;
use crate::render::shadows::depth_pass::short_word;
use crate::render::shadows::jobs::{
    JobBuffer, array_texture_entry, compute_pipeline, job_binding, job_entry, moments_out_entry,
};
use crate::render::shadows::moment_storage::MomentArray;
use crate::render::shadows::storage::DepthArray;
use crate::render::shadows::vsm_use;
use crate::settings::ShadowMode;
use crate::shader::ShaderLibrary;

/// What a layer's moments were made from: the depth's content version and the pre-blur
/// radius.
type MadeFrom = (u64, u32);

/// Mirror of WGSL `MomentsJob`, padded to the 256-byte dynamic-offset alignment.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct MomentsJobGpu {
    src_layer: u32,
    dst_layer: u32,
    side: u32,
    radius: u32,
    axis: u32,
    near: f32,
    range: f32,
    _pad: [u32; 57],
}

/// One light whose moments are made this frame.
#[derive(Clone, Copy, Debug)]
struct Job {
    /// The storage of its layers.
    storage: ShadowStorage,
    /// First layer (slot) and how many.
    first: u32,
    layers: u32,
    near: f32,
    range: f32,
    blur: u32,
    /// The light's kind and index among its kind (for the pass name).
    light: (LightKind, usize),
}

/// The pipelines, built on first use for the device's moments format.
struct Pipelines {
    resolve_layout: wgpu::BindGroupLayout,
    /// Blur layouts and pipelines for spot lights (2D array) and point lights (cube array).
    blur_layouts: [wgpu::BindGroupLayout; 2],
    resolve: [wgpu::ComputePipeline; 2],
    blur: [wgpu::ComputePipeline; 2],
}

/// The moments node.
#[derive(Default)]
pub struct MomentsPass {
    pipelines: Option<Pipelines>,
    /// The per-dispatch uniforms.
    jobs_buffer: JobBuffer,
    /// Per storage, at [`ShadowStorage::index`]: its bind groups, kept while nothing behind
    /// them changes.
    groups: [Option<StorageGroups>; ShadowStorage::COUNT],
    /// Per storage: the moments and depth allocations `versions` refer to, and what each
    /// layer's moments were made from.
    held: [(u64, u64, Vec<MadeFrom>); ShadowStorage::COUNT],
    /// This frame's depth arrays and moments in the graph, at [`ShadowStorage::index`].
    handles: Option<([TextureId; ShadowStorage::COUNT], [TextureId; ShadowStorage::COUNT])>,
    cache: bool,
    jobs: Vec<Job>,
    data: Vec<MomentsJobGpu>,
    name: String,
}

/// One storage's resolve and blur groups (x: moments → scratch, y: scratch → moments), with
/// the depth and moments allocations and the buffer generation they were made for.
type StorageGroups = ((u64, u64, u64), [wgpu::BindGroup; 3]);

impl Job {
    /// Dispatches of its pass: the resolve, then with a blur both axes.
    fn stages(&self) -> usize {
        if self.blur > 0 { 3 } else { 1 }
    }
}

fn create_pipelines(device: &wgpu::Device, library: &mut ShaderLibrary, format: wgpu::TextureFormat) -> Pipelines {
    let compute = wgpu::ShaderStages::COMPUTE;
    let storage = moments_out_entry(format);
    let job = job_entry::<MomentsJobGpu>();
    let resolve_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("shadow moments resolve"),
        entries: &[array_texture_entry(0, wgpu::TextureSampleType::Depth), storage, job],
    });
    let blur_layout = |dimension| {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow moments blur"),
            entries: &[
                storage,
                job,
                entry(
                    3,
                    compute,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
                entry(
                    4,
                    compute,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: dimension,
                        multisampled: false,
                    },
                ),
            ],
        })
    };
    let blur_layouts = [
        blur_layout(wgpu::TextureViewDimension::D2Array),
        blur_layout(wgpu::TextureViewDimension::CubeArray),
    ];
    let fp32 = format == wgpu::TextureFormat::Rgba32Float;
    // One module per storage (spot layers, point cubes) holds both entry points.
    let [spot, point] = [false, true].map(|point| {
        let module = library
            .shadow_moments(point, fp32)
            .expect("the shipped moments shader composes (checked by tests)");
        device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("shadow moments"),
            source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
        })
    });
    let pipeline =
        |shader, layout, entry_point| compute_pipeline(device, "shadow moments", shader, layout, entry_point);
    let resolve = [
        pipeline(&spot, &resolve_layout, "resolve"),
        pipeline(&point, &resolve_layout, "resolve"),
    ];
    let blur = [
        pipeline(&spot, &blur_layouts[0], "blur"),
        pipeline(&point, &blur_layouts[1], "blur"),
    ];
    Pipelines {
        resolve_layout,
        blur_layouts,
        resolve,
        blur,
    }
}

impl RenderNode for MomentsPass {
    fn name(&self) -> &'static str {
        "shadow moments"
    }

    /// Reads the depth and writes the moments of each storage with a VSM light this frame;
    /// with none, nothing (the node is culled).
    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, inputs: &FrameInputs<'_>) {
        self.cache = inputs.options.shadow_cache;
        let uses_vsm = |storage| vsm_use(inputs.lights, inputs.shadow_views, storage).0;
        self.handles = Some((frame.shadow_maps, frame.shadow_moments));
        for storage in ShadowStorage::with_moments(StorageMoments::Vsm) {
            if uses_vsm(storage) {
                pass.read(frame.maps(storage));
                pass.write(frame.moments(storage));
            }
        }
    }

    fn record(&mut self, ctx: &mut FrameContext<'_>, res: &GraphResources, encoder: &mut wgpu::CommandEncoder) {
        let Some((maps, moments)) = self.handles else {
            return;
        };
        let depth_of = |s: ShadowStorage| res.object::<DepthArray>(maps[s.index()]);
        let moments_of = |s: ShadowStorage| res.object::<MomentArray>(moments[s.index()]);
        self.plan(ctx, |s| (moments_of(s).id, depth_of(s).id));
        let Some(first) = self.jobs.first() else {
            return;
        };
        let device = &ctx.gpu.device;
        let format = moments_of(first.storage).moments.texture.format();
        let pipelines = self
            .pipelines
            .get_or_insert_with(|| create_pipelines(device, ctx.library, format));
        // NOTE: one uniform entry per dispatch: resolve depth → moments; blur x moments →
        // scratch (layer 0 on); blur y scratch → moments.
        self.data.clear();
        for job in &self.jobs {
            let side = depth_of(job.storage).side;
            let stages = [(job.first, job.first, 0), (job.first, 0, 0), (0, job.first, 1)];
            for &(src_layer, dst_layer, axis) in &stages[..job.stages()] {
                self.data.push(MomentsJobGpu {
                    src_layer,
                    dst_layer,
                    side,
                    radius: job.blur,
                    axis,
                    near: job.near,
                    range: job.range,
                    _pad: [0; 57],
                });
            }
        }
        let uploaded = self
            .jobs_buffer
            .upload(device, &ctx.gpu.queue, "shadow moments jobs", &self.data);
        let Some((buffer, generation)) = uploaded else {
            return;
        };
        // NOTE: the groups are made again only when an allocation behind them changed.
        for storage in ShadowStorage::with_moments(StorageMoments::Vsm) {
            let (depth, moments) = (depth_of(storage), moments_of(storage));
            let key = (depth.id, moments.id, generation);
            let k = storage.index();
            let used = self.jobs.iter().any(|j| j.storage == storage);
            if used && self.groups[k].as_ref().is_none_or(|(held, _)| *held != key) {
                let sampler = &ctx.layouts.moments_sampler;
                self.groups[k] = Some((key, bind_groups(device, pipelines, buffer, sampler, depth, moments)));
            }
        }
        let mut entry = 0;
        for job in &self.jobs {
            let Some((_, groups)) = &self.groups[job.storage.index()] else {
                continue;
            };
            let side = self.data[entry].side;
            self.name.clear();
            let (kind, light) = job.light;
            // NOTE: writing to a String cannot fail.
            let _ = write!(self.name, "shadow moments {} {light}", short_word(kind));
            let cube = usize::from(job.storage.desc().cube);
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(&self.name),
                timestamp_writes: ctx.timer.compute_pass(&self.name),
            });
            for (stage, group) in groups.iter().enumerate().take(job.stages()) {
                let pipeline = if stage == 0 {
                    &pipelines.resolve[cube]
                } else {
                    &pipelines.blur[cube]
                };
                let offset = (entry * size_of::<MomentsJobGpu>()) as u32;
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, group, &[offset]);
                pass.dispatch_workgroups(side.div_ceil(8), side.div_ceil(8), job.layers);
                entry += 1;
            }
        }
    }
}

/// The resolve group and both blur groups (x: moments → scratch, y: scratch → moments) of
/// one storage.
fn bind_groups(
    device: &wgpu::Device,
    pipelines: &Pipelines,
    buffer: &wgpu::Buffer,
    sampler: &wgpu::Sampler,
    depth: &DepthArray,
    moments: &MomentArray,
) -> [wgpu::BindGroup; 3] {
    let job = job_binding::<MomentsJobGpu>(buffer);
    fn view(binding: u32, view: &wgpu::TextureView) -> wgpu::BindGroupEntry<'_> {
        wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(view),
        }
    }
    let resolve = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("shadow moments resolve"),
        layout: &pipelines.resolve_layout,
        entries: &[
            view(0, &depth.flat_view),
            view(1, &moments.moments.storage),
            job.clone(),
        ],
    });
    let layout = &pipelines.blur_layouts[usize::from(moments.cube)];
    let blur = |from: &wgpu::TextureView, to: &wgpu::TextureView| {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow moments blur"),
            layout,
            entries: &[
                view(1, to),
                job.clone(),
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::Sampler(sampler),
                },
                view(4, from),
            ],
        })
    };
    let blur_x = blur(&moments.moments.sampled, &moments.scratch.storage);
    let blur_y = blur(&moments.scratch.sampled, &moments.moments.storage);
    [resolve, blur_x, blur_y]
}

impl MomentsPass {
    /// Lists the VSM lights whose moments must be made this frame (their depth changed, the
    /// allocations are new, or the cache is off), and marks their layers as holding them.
    /// `ids` gives a storage's moments and depth allocation ids.
    fn plan(&mut self, ctx: &FrameContext<'_>, ids: impl Fn(ShadowStorage) -> (u64, u64)) {
        self.jobs.clear();
        let views = &ctx.shadow_views.views;
        for storage in ShadowStorage::with_moments(StorageMoments::Vsm) {
            let held = &mut self.held[storage.index()];
            let (moments, depth) = ids(storage);
            if (held.0, held.1) != (moments, depth) {
                *held = (moments, depth, Vec::new());
            }
        }
        let mut v = 0;
        while v < views.len() {
            let view = &views[v];
            let storage = view.kind.storage;
            if storage.desc().moments != StorageMoments::Vsm {
                v += 1;
                continue;
            }
            if view.kind.index != 0 {
                v += 1;
                continue;
            }
            let layers = if view.kind.storage.desc().cube { FACES } else { 1 };
            let group = &views[v..(v + layers).min(views.len())];
            v += layers;
            let Some(settings) = ctx.lights.view_settings(view) else {
                continue;
            };
            if settings.filter.mode != ShadowMode::Vsm {
                continue;
            }
            let (near, range) = (view.shading.near, view.shading.far);
            let versions = &mut self.held[storage.index()].2;
            let last = group.iter().map(|g| g.slot as usize + 1).max().unwrap_or(0);
            if versions.len() < last {
                versions.resize(last, (0, 0));
            }
            let blur = settings.filter.vsm.blur;
            let fresh = group.iter().all(|g| versions[g.slot as usize] == (g.version, blur));
            if self.cache && fresh {
                continue;
            }
            for g in group {
                versions[g.slot as usize] = (g.version, blur);
            }
            let first_of_kind = ctx.lights.light_index(view.light_kind, 0);
            self.jobs.push(Job {
                storage,
                first: view.slot,
                layers: group.len() as u32,
                near,
                range,
                blur: settings.filter.vsm.blur,
                light: (view.light_kind, (view.light as usize).saturating_sub(first_of_kind)),
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use std::mem::offset_of;

    use super::*;

    #[test]
    fn the_job_uniform_matches_the_wgsl_layout() {
        let mut library = ShaderLibrary::new().unwrap();
        let module = library.shadow_moments(true, true).unwrap();
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref().is_some_and(|n| n.starts_with("MomentsJob")))
            .expect("MomentsJob in the moments shader");
        let naga::TypeInner::Struct { members, .. } = &ty.inner else {
            panic!("MomentsJob is not a struct")
        };
        let wgsl: Vec<(&str, usize)> = members
            .iter()
            .take(7)
            .map(|m| (m.name.as_deref().unwrap_or(""), m.offset as usize))
            .collect();
        let rust = [
            ("src_layer", offset_of!(MomentsJobGpu, src_layer)),
            ("dst_layer", offset_of!(MomentsJobGpu, dst_layer)),
            ("side", offset_of!(MomentsJobGpu, side)),
            ("radius", offset_of!(MomentsJobGpu, radius)),
            ("axis", offset_of!(MomentsJobGpu, axis)),
            ("near", offset_of!(MomentsJobGpu, near)),
            ("range", offset_of!(MomentsJobGpu, range)),
        ];
        assert_eq!(wgsl, rust);
        // Padded to the dynamic-offset alignment every adapter accepts.
        assert_eq!(size_of::<MomentsJobGpu>(), 256);
    }
}
