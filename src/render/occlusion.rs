//! GPU culling of the camera view (`shaders/occlusion_cull.wgsl`, `occlusion_pyramid.wgsl`;
//! the math is `math::occlusion`): instance by instance against the frustum, and with
//! occlusion culling in two phases. The view comes as runs of instances ([`InstanceRun`]):
//! those the ECS listed by culling chunk ([`ViewDrawGroups::runs`]), or runs over the list the
//! CPU culled. At the frame's start the early phase lists every run member in the frustum
//! (with occlusion culling, only those seen last frame), in the batch of the mesh level its
//! size on screen allows, and the prepass draws them; with
//! occlusion culling a depth pyramid is then built from that depth and the late phase tests
//! every member's bounding sphere against the frustum and the pyramid, keeps the answer as the
//! instance's "seen" flag for the next frame, and lists the instances seen now but not
//! before, which the prepass then draws too. The lighting pass draws both lists. Each list has
//! a batch's instances at the batch's range of the view's list, counted by the batch's
//! indirect draw arguments, so the passes draw with one multi-draw per run of batches as
//! before. Occlusion culling runs for views of at least [`MIN_INSTANCES`] entries where the
//! prepass runs with one sample per pixel and the device draws indirect with a first
//! instance ([`OcclusionGpu::occluding`]); the frustum test alone whenever the ECS listed runs
//! ([`OcclusionGpu::active`]).

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};

use crate::ecs::camera_runs::GPU_CAMERA_MIN_INSTANCES;
use crate::ecs::draw_groups::{InstanceRun, ViewDrawGroups};
use crate::ecs::instances::RenderInstances;
use crate::math::frustum::{CameraView, Frustum};
use crate::math::occlusion::level_count;
use crate::render::context::GpuContext;
use crate::render::draw_args::IndexedArgs;
use crate::render::frame_inputs::FrameInputs;
use crate::render::grow_buffer::GrowBuffer;
use crate::render::layouts::Layouts;
use crate::render::limits::LimitError;
use crate::render::occlusion_kernels::{Kernels, Pyramid};
use crate::render::options::Msaa;
use crate::render::readback::{copy_and_read, read_indirect_lists};
use crate::render::scene_gpu::{SceneGpu, instances_group, uniform_buffer};
use crate::render::timer::GpuTimer;
use crate::shader::ShaderLibrary;

/// The culling's uniforms, as `Cull` in the shader.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct CullGpu {
    pub(crate) clip_from_view: Mat4,
    pub(crate) view_from_world: Mat4,
    pub(crate) planes: [Vec4; 6],
    /// The camera's position (relative to the render origin) and the error its levels may
    /// have at unit view depth (0: no coarser level).
    pub(crate) eye: Vec4,
    /// The camera's unit forward direction.
    pub(crate) forward: Vec4,
    pub(crate) size: [f32; 2],
    pub(crate) levels: u32,
    pub(crate) runs: u32,
    pub(crate) near: f32,
    pub(crate) occluding: u32,
    /// Workgroups per row of the dispatch (runs past it continue on the next row).
    pub(crate) row: u32,
    pub(crate) _pad: u32,
}

/// Timing names of the culling's passes.
pub const EARLY_NAME: &str = "occlusion early";
/// The depth pyramid's build.
pub const PYRAMID_NAME: &str = "occlusion pyramid";
/// The late test.
pub const LATE_NAME: &str = "occlusion late";

/// The fewest entries in the camera's list a frame culls by occlusion: below it the pyramid
/// and the two phases (about 0.13 ms at 1920×1080 on an H200) outweigh what the few hidden
/// instances could save (the 2 065-instance walkers bench took 2.54 ms without and 2.72 ms
/// with; the million's 783 770 went from 54.5 to 18.4 ms). The ECS lists runs for the GPU
/// from the same count.
pub const MIN_INSTANCES: usize = GPU_CAMERA_MIN_INSTANCES;

/// Whether the options and the view ask for occlusion culling this frame: it is on, with
/// multi-draw, one sample per pixel, and at least [`MIN_INSTANCES`] entries in the camera's
/// list.
pub fn occlusion_wanted(inputs: &FrameInputs<'_>) -> bool {
    let options = &inputs.options;
    options.occlusion_culling
        && options.multi_draw
        && options.msaa == Msaa::Off
        && inputs.view_groups.candidate_count() >= MIN_INSTANCES
}

/// Invocations per culling workgroup (the shader's `workgroup_size`): one run each, a run
/// holding at most one culling chunk.
const CULL_WORKGROUP: u32 = 64;

/// Most workgroups in one row of a dispatch (the device limit every adapter has).
const DISPATCH_ROW: u32 = 65_535;

/// Bind groups over this frame's buffers: the two phases' culling and drawing groups.
struct Groups {
    early_cull: wgpu::BindGroup,
    late_cull: wgpu::BindGroup,
    early_draw: wgpu::BindGroup,
    late_draw: wgpu::BindGroup,
}

/// The occlusion culling's buffers, pyramid and pipelines.
#[derive(Default)]
pub struct OcclusionGpu {
    kernels: Option<Kernels>,
    /// Uniforms, bounds, seen flags, entry batches, early and late lists and arguments.
    buffers: Option<Buffers>,
    pyramid: Option<Pyramid>,
    groups: Option<Groups>,
    /// The buffers `groups` were made over (instances, view list), to notice replacements.
    bound: Option<(wgpu::Buffer, wgpu::Buffer)>,
    template: Vec<IndexedArgs>,
    /// Runs over a list the CPU culled (kept for their allocation).
    listed_runs: Vec<InstanceRun>,
    /// Runs uploaded for the view's list.
    run_count: u32,
    /// Bounds and seen flags as uploaded (kept to reuse their allocations).
    bounds: Vec<Vec4>,
    ones: Vec<u32>,
    instance_generation: Option<u64>,
    view_generation: Option<u64>,
    active: bool,
    occluding: bool,
}

/// The culling's buffers.
struct Buffers {
    uniform: wgpu::Buffer,
    bounds: GrowBuffer,
    seen: GrowBuffer,
    runs: GrowBuffer,
    early_list: GrowBuffer,
    late_list: GrowBuffer,
    early_args: GrowBuffer,
    late_args: GrowBuffer,
}

impl Buffers {
    fn new(device: &wgpu::Device) -> Buffers {
        let storage = |label| GrowBuffer::new(device, label, 256);
        let (listed, args) = (GrowBuffer::readable, GrowBuffer::indirect);
        Buffers {
            uniform: uniform_buffer(device, "occlusion uniforms", size_of::<CullGpu>()),
            bounds: storage("occlusion bounds"),
            seen: listed(device, "occlusion seen"),
            runs: storage("culling runs"),
            early_list: listed(device, "occlusion early list"),
            late_list: listed(device, "occlusion late list"),
            early_args: args(device, "occlusion early arguments"),
            late_args: args(device, "occlusion late arguments"),
        }
    }
}

/// One phase's draws: the instances bind group (group 1) over its list, and its arguments
/// (one [`IndexedArgs`] per batch of the view, opaque then masked).
pub struct Phase<'a> {
    /// Group 1 over the instances and the phase's list.
    pub instances: &'a wgpu::BindGroup,
    /// The phase's indirect arguments.
    pub args: &'a wgpu::Buffer,
}

/// The view's batches in argument order (opaque, then masked), with their mesh ranges.
fn batch_args(scene: &SceneGpu, views: &ViewDrawGroups, out: &mut Vec<IndexedArgs>) {
    out.clear();
    let group = &views.group;
    out.extend(group.opaque.iter().chain(&group.masked).map(|b| {
        let range = scene.mesh_ranges.get(b.mesh.0 as usize).copied().unwrap_or_default();
        IndexedArgs {
            index_count: range.index_count,
            instance_count: 0,
            first_index: range.first_index,
            base_vertex: range.base_vertex,
            first_instance: b.first,
        }
    }));
}

impl OcclusionGpu {
    /// Whether this frame culls the camera view on the GPU (set by
    /// [`prepare`](Self::prepare)): its draws are the two phases' lists.
    pub fn active(&self) -> bool {
        self.active
    }

    /// Whether this frame's GPU culling tests occlusion too (a pyramid and a late phase).
    pub fn occluding(&self) -> bool {
        self.active && self.occluding
    }

    /// The two phases' draws (None while inactive).
    pub fn phases(&self) -> Option<[Phase<'_>; 2]> {
        let (groups, buffers) = (self.groups.as_ref()?, self.buffers.as_ref()?);
        self.active.then_some([
            Phase {
                instances: &groups.early_draw,
                args: &buffers.early_args.buffer,
            },
            Phase {
                instances: &groups.late_draw,
                args: &buffers.late_args.buffer,
            },
        ])
    }

    /// Prepares the frame's culling: with occlusion when `wanted` (the prepass runs with one
    /// sample, the options ask for it, the device draws indirect with a first instance), else
    /// against the frustum alone when the ECS listed the view as runs. Uploads the instances'
    /// bounds (and marks every one seen) when the instance list changed, the runs when the
    /// view's list did, resets both phases' arguments, and sizes the pyramid to `size`.
    #[allow(clippy::too_many_arguments)]
    pub fn prepare(
        &mut self,
        (gpu, layouts, library): (&GpuContext, &Layouts, &mut ShaderLibrary),
        scene: &SceneGpu,
        (instances, views): (&RenderInstances, &ViewDrawGroups),
        camera: Option<&CameraView>,
        size: (u32, u32),
        wanted: bool,
    ) -> Result<(), LimitError> {
        self.active = false;
        let listed = !views.runs.is_empty();
        let Some(camera) = camera.filter(|_| (wanted || listed) && views.entries() > 0) else {
            return Ok(());
        };
        let device = &gpu.device;
        let kernels = self.kernels.get_or_insert_with(|| Kernels::new(device, library));
        let buffers = self.buffers.get_or_insert_with(|| Buffers::new(device));
        let mut replaced = false;
        // NOTE: a rebuilt instance list renumbers the instances: every one counts as seen, so
        // that frame's early phase draws them all. Instances that only moved keep their
        // numbers and flags; their bounds are patched.
        if self.instance_generation != Some(instances.generation) {
            let patch = instances
                .patch_from(self.instance_generation)
                .filter(|_| self.bounds.len() == instances.centers.len());
            if let Some(slots) = patch {
                for &i in slots {
                    let i = i as usize;
                    self.bounds[i] = instances.centers[i].extend(instances.radii[i]);
                }
            } else {
                self.bounds.clear();
                self.bounds
                    .extend((instances.centers.iter().zip(&instances.radii)).map(|(c, &r)| c.extend(r)));
                self.ones.resize(instances.centers.len(), 1);
                replaced |= buffers
                    .seen
                    .write(gpu, bytemuck::cast_slice(&self.ones[..instances.centers.len()]))?;
            }
            let bounds = bytemuck::cast_slice(&self.bounds);
            replaced |= buffers
                .bounds
                .write_patch(gpu, instances.generation, bounds, 16, patch)?;
            self.instance_generation = Some(instances.generation);
        }
        if self.view_generation != Some(views.generation) {
            // NOTE: the ECS's own runs go up as they are; a list the CPU culled gets runs here.
            let runs = match views.runs.is_empty() {
                true => {
                    list_runs(views, &mut self.listed_runs);
                    &self.listed_runs
                }
                false => &views.runs,
            };
            replaced |= buffers.runs.write(gpu, bytemuck::cast_slice(runs))?;
            self.run_count = runs.len() as u32;
            // NOTE: the lists need room, not contents: the culling writes what the draws read.
            let bytes = views.entries() as u64 * 4;
            replaced |= buffers.early_list.reserve(gpu, bytes)?;
            replaced |= buffers.late_list.reserve(gpu, bytes)?;
            self.view_generation = Some(views.generation);
        }
        batch_args(scene, views, &mut self.template);
        replaced |= buffers.early_args.write(gpu, bytemuck::cast_slice(&self.template))?;
        replaced |= buffers.late_args.write(gpu, bytemuck::cast_slice(&self.template))?;
        self.occluding = wanted;
        let levels = level_count(size.0, size.1);
        let frustum = Frustum::from_clip_from_world(camera.clip_from_world());
        let uniforms = CullGpu {
            clip_from_view: camera.clip_from_view(),
            view_from_world: camera.view_from_world(),
            planes: frustum.planes.map(|p| p.normal.extend(p.d)),
            eye: camera.position().extend(views.lod_error_per_depth),
            forward: camera.forward().extend(0.0),
            size: [size.0 as f32, size.1 as f32],
            levels,
            runs: self.run_count,
            near: camera.near,
            occluding: u32::from(wanted),
            row: DISPATCH_ROW,
            _pad: 0,
        };
        gpu.queue
            .write_buffer(&buffers.uniform, 0, bytemuck::bytes_of(&uniforms));
        if self.pyramid.as_ref().is_none_or(|p| p.size != size) {
            self.pyramid = Some(Pyramid::new(device, &gpu.queue, kernels, size));
            replaced = true;
        }
        let (instance_buffer, view_list) = scene.view_buffers();
        replaced |= self
            .bound
            .as_ref()
            .is_none_or(|(i, v)| i != instance_buffer || v != view_list);
        if replaced || self.groups.is_none() {
            let pyramid = self.pyramid.as_ref().map(|p| &p.buffer);
            let Some(pyramid) = pyramid else {
                return Ok(());
            };
            let cull = |args: &GrowBuffer, list: &GrowBuffer| {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("occlusion cull"),
                    layout: &kernels.cull_layout,
                    entries: &[
                        buffer(0, &buffers.uniform),
                        buffer(1, &buffers.bounds.buffer),
                        buffer(2, view_list),
                        buffer(3, &buffers.runs.buffer),
                        buffer(4, &buffers.seen.buffer),
                        buffer(5, &args.buffer),
                        buffer(6, &list.buffer),
                        buffer(7, pyramid),
                    ],
                })
            };
            self.groups = Some(Groups {
                early_cull: cull(&buffers.early_args, &buffers.early_list),
                late_cull: cull(&buffers.late_args, &buffers.late_list),
                early_draw: instances_group(
                    device,
                    layouts,
                    instance_buffer,
                    &buffers.early_list.buffer,
                    "occlusion early",
                ),
                late_draw: instances_group(
                    device,
                    layouts,
                    instance_buffer,
                    &buffers.late_list.buffer,
                    "occlusion late",
                ),
            });
            self.bound = Some((instance_buffer.clone(), view_list.clone()));
        }
        self.active = true;
        Ok(())
    }

    /// The depth pyramid's levels, read back (waits for the GPU; for tests).
    pub fn read_pyramid(&self, gpu: &GpuContext) -> Vec<(u32, u32, Vec<f32>)> {
        self.pyramid.as_ref().map_or_else(Vec::new, |p| p.read(gpu))
    }

    /// Instances the last frame drew in its early and its late phase (waits for the GPU; for
    /// tests and reports). None while inactive.
    pub fn read_drawn(&self, gpu: &GpuContext) -> Option<(u64, u64)> {
        let buffers = self.buffers.as_ref().filter(|_| self.active)?;
        let bytes = (self.template.len() * size_of::<IndexedArgs>()) as u64;
        let count = |args: &GrowBuffer| -> Option<u64> {
            let data = copy_and_read(&gpu.device, &gpu.queue, &args.buffer, bytes)?;
            let args: &[IndexedArgs] = bytemuck::cast_slice(&data);
            Some(args.iter().map(|a| u64::from(a.instance_count)).sum())
        };
        Some((count(&buffers.early_args)?, count(&buffers.late_args)?))
    }

    /// The instances each batch's early list held after the last frame, batch by batch
    /// (opaque, then masked), in list order (waits for the GPU; for tests). None while
    /// inactive.
    pub fn read_early_lists(&self, gpu: &GpuContext) -> Option<Vec<Vec<u32>>> {
        let buffers = self.buffers.as_ref().filter(|_| self.active)?;
        let buffers = (&buffers.early_args.buffer, &buffers.early_list.buffer);
        read_indirect_lists(&gpu.device, &gpu.queue, buffers, 0, self.template.len())
    }

    /// The instances' seen flags after the last frame (1: seen), the first `n` (waits for
    /// the GPU; for tests).
    pub fn read_seen(&self, gpu: &GpuContext, n: usize) -> Vec<u32> {
        let Some(buffers) = self.buffers.as_ref() else {
            return Vec::new();
        };
        let bytes = (n.min((buffers.seen.buffer.size() / 4) as usize) * 4) as u64;
        let data = copy_and_read(&gpu.device, &gpu.queue, &buffers.seen.buffer, bytes).unwrap_or_default();
        bytemuck::cast_slice(&data).to_vec()
    }

    /// Records the early phase's listing.
    pub fn record_early(&self, encoder: &mut wgpu::CommandEncoder, timer: &mut GpuTimer) {
        self.record_cull(encoder, timer, false);
    }

    /// Records the pyramid's build from the early draws' `depth`, then the late phase's test.
    pub fn record_late(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        depth: &wgpu::TextureView,
    ) {
        let occluding = self.occluding();
        let (Some(kernels), Some(pyramid), true) = (&self.kernels, &mut self.pyramid, occluding) else {
            return;
        };
        pyramid.record(device, kernels, depth, encoder, timer.compute_pass(PYRAMID_NAME));
        self.record_cull(encoder, timer, true);
    }

    fn record_cull(&self, encoder: &mut wgpu::CommandEncoder, timer: &mut GpuTimer, late: bool) {
        let (Some(kernels), Some(groups), true) = (&self.kernels, &self.groups, self.active) else {
            return;
        };
        let name = if late { LATE_NAME } else { EARLY_NAME };
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(name),
            timestamp_writes: timer.compute_pass(name),
        });
        pass.set_pipeline(if late { &kernels.late } else { &kernels.early });
        pass.set_bind_group(0, if late { &groups.late_cull } else { &groups.early_cull }, &[]);
        let runs = self.run_count;
        pass.dispatch_workgroups(runs.min(DISPATCH_ROW), runs.div_ceil(DISPATCH_ROW), 1);
    }
}

/// Runs of at most [`CULL_WORKGROUP`] entries over the list the CPU culled, batch by batch (a
/// view the ECS listed as runs has its own).
fn list_runs(views: &ViewDrawGroups, out: &mut Vec<InstanceRun>) {
    out.clear();
    let group = &views.group;
    for (b, batch) in (0u32..).zip(group.opaque.iter().chain(&group.masked)) {
        let end = batch.first + batch.count;
        out.extend(
            (batch.first..end)
                .step_by(CULL_WORKGROUP as usize)
                .map(|first| InstanceRun {
                    first,
                    count: (end - first).min(CULL_WORKGROUP),
                    batch: b,
                    listed: 1,
                    ..InstanceRun::default()
                }),
        );
    }
}

/// A whole buffer at `binding`.
fn buffer(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}
