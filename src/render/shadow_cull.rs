//! GPU culling of shadow casters (`shaders/shadow_cull.wgsl`; the math is
//! `math::culling::sphere_reaches_light_box` and `Frustum::intersects_sphere`): the views the
//! ECS culled by chunk ([`ShadowViews::runs`]) are culled caster by caster into lists only the
//! GPU writes. Each such view's batches get indirect draw arguments and room in one list
//! shared by all views; before the depth pass draws, one dispatch tests the members of every
//! run of the views drawn this frame against their view's volume (a cascade's light-space box,
//! a spot light's or a cube face's frustum and reach) and appends those that reach it to their
//! batch, and the depth pass draws each view with one multi-draw per run of batches
//! ([`draw_culled`](crate::render::draw::draw_culled)). The casters' bounds and instances are
//! patched when instances only moved, uploaded whole when the list was rebuilt.

use bytemuck::{Pod, Zeroable};
use glam::Vec4;

use crate::ecs::draw_groups::ShadowRun;
use crate::ecs::instance_rows::NOT_A_CASTER;
use crate::ecs::instances::RenderInstances;
use crate::ecs::view_list::{CullVolume, ShadowViews};
use crate::render::context::GpuContext;
use crate::render::draw_args::IndexedArgs;
use crate::render::grow_buffer::GrowBuffer;
use crate::render::layouts::{Layouts, main_compute_pipeline};
use crate::render::limits::LimitError;
use crate::render::readback::read_indirect_lists;
use crate::render::scene_gpu::{IndexList, SceneGpu, instances_group, uniform_buffer};
use crate::render::shadows::jobs::{buffer_group, storage_entry, uniform_entry};
use crate::render::timer::GpuTimer;
use crate::shader::ShaderLibrary;

/// Timing name of the culling's dispatch.
pub const SHADOW_CULL_NAME: &str = "shadow culling";

/// One view's volume, as `CullView` in the shader.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct CullViewGpu {
    /// A box: the light rotation's rows, the smallest corner, the largest; a frustum: its
    /// planes.
    pub(crate) a: [Vec4; 6],
    /// A cube face's light position and reach (w < 0: none).
    pub(crate) reach: Vec4,
    /// 0: a box; 1: a frustum.
    pub(crate) kind: u32,
    /// 1 when the view is drawn this frame.
    pub(crate) drawn: u32,
    pub(crate) _pad: [u32; 2],
}

/// The dispatch's uniforms, as `Dispatch` in the shader.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct DispatchGpu {
    pub(crate) runs: u32,
    pub(crate) row: u32,
    pub(crate) _pad: [u32; 2],
}

/// Most workgroups in one row of a dispatch (the device limit every adapter has).
const DISPATCH_ROW: u32 = 65_535;

/// The culling's buffers.
struct Buffers {
    dispatch: wgpu::Buffer,
    views: GrowBuffer,
    bounds: GrowBuffer,
    casters: GrowBuffer,
    runs: GrowBuffer,
    args: GrowBuffer,
    list: GrowBuffer,
}

impl Buffers {
    fn new(device: &wgpu::Device) -> Buffers {
        let storage = |label| GrowBuffer::new(device, label, 256);
        Buffers {
            dispatch: uniform_buffer(device, "shadow culling dispatch", size_of::<DispatchGpu>()),
            views: storage("shadow culling views"),
            bounds: storage("shadow culling bounds"),
            casters: storage("shadow culling casters"),
            runs: storage("shadow culling runs"),
            args: GrowBuffer::indirect(device, "shadow culling arguments"),
            list: GrowBuffer::readable(device, "shadow culling list"),
        }
    }
}

/// The pipeline and its layout.
struct Kernel {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl Kernel {
    fn new(device: &wgpu::Device, library: &mut ShaderLibrary) -> Kernel {
        let compute = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow culling"),
            entries: &[
                uniform_entry(0, compute, false, size_of::<DispatchGpu>() as u64),
                storage_entry(1, compute, true),
                storage_entry(2, compute, true),
                storage_entry(3, compute, true),
                storage_entry(4, compute, true),
                storage_entry(5, compute, false),
                storage_entry(6, compute, false),
            ],
        });
        let module = library
            .shadow_cull()
            .expect("the shipped shadow culling shader composes (checked by tests)");
        let pipeline = main_compute_pipeline(device, "shadow culling", module, &[Some(&layout)]);
        Kernel { layout, pipeline }
    }
}

/// The GPU culling of shadow casters: its pipeline, buffers and bind groups.
#[derive(Default)]
pub struct ShadowCullGpu {
    kernel: Option<Kernel>,
    buffers: Option<Buffers>,
    /// The culling's group, and group 1 of the depth pass's draws over the list.
    groups: Option<(wgpu::BindGroup, wgpu::BindGroup)>,
    /// The instance buffer the draw group was made over.
    bound: Option<wgpu::Buffer>,
    /// Per view: the first of its arguments (None for a view the CPU listed).
    bases: Vec<Option<u32>>,
    template: Vec<IndexedArgs>,
    views: Vec<CullViewGpu>,
    bounds: Vec<Vec4>,
    patch: Vec<u32>,
    runs: Vec<ShadowRun>,
    instance_generation: Option<u64>,
    view_generation: Option<u64>,
}

/// A view's volume for the shader (not drawn).
fn cull_view(volume: &CullVolume) -> CullViewGpu {
    let (frustum, reach) = match *volume {
        CullVolume::LightBox {
            light_rotation,
            min,
            max,
        } => {
            let rows = light_rotation.transpose();
            let (x, y, z) = (rows.x_axis, rows.y_axis, rows.z_axis);
            let a = [x, y, z, min, max, glam::Vec3::ZERO].map(|v| v.extend(0.0));
            return CullViewGpu {
                a,
                ..CullViewGpu::default()
            };
        }
        CullVolume::Frustum(frustum) => (frustum, Vec4::NEG_ONE),
        CullVolume::CubeFace {
            frustum,
            center,
            radius,
        } => (frustum, center.extend(radius)),
    };
    CullViewGpu {
        a: frustum.planes.map(|p| p.normal.extend(p.d)),
        reach,
        kind: 1,
        ..CullViewGpu::default()
    }
}

impl ShadowCullGpu {
    /// Whether view `v` is culled on the GPU this frame.
    pub fn culls(&self, v: usize) -> bool {
        self.bases.get(v).is_some_and(Option::is_some)
    }

    /// Group 1 of the depth pass's draws of a GPU-culled view (the instances and the list),
    /// and the arguments buffer with the first argument of view `v` (None for a view the CPU
    /// listed).
    pub fn draws(&self, v: usize) -> Option<(&wgpu::BindGroup, &wgpu::Buffer, u32)> {
        let base = (*self.bases.get(v)?)?;
        let ((_, draw), buffers) = (self.groups.as_ref()?, self.buffers.as_ref()?);
        Some((draw, &buffers.args.buffer, base))
    }

    /// Prepares the frame's culling: uploads the casters' bounds and instances when the
    /// instance list changed (patched when instances only moved), the runs and the list's
    /// room when the views' lists did, and makes every view's arguments (uploaded by
    /// [`record`](Self::record)). Nothing while no view is culled on the GPU.
    pub fn prepare(
        &mut self,
        (gpu, layouts, library): (&GpuContext, &Layouts, &mut ShaderLibrary),
        scene: &SceneGpu,
        instances: &RenderInstances,
        views: &ShadowViews,
    ) -> Result<(), LimitError> {
        if views.runs.is_empty() {
            self.bases.clear();
            return Ok(());
        }
        let device = &gpu.device;
        self.kernel.get_or_insert_with(|| Kernel::new(device, library));
        let buffers = self.buffers.get_or_insert_with(|| Buffers::new(device));
        let mut replaced = false;
        if self.instance_generation != Some(instances.generation) {
            // NOTE: instances that moved (or were appended) keep their casters' places.
            let patch = instances
                .patch_from(self.instance_generation)
                .filter(|_| self.bounds.len() <= instances.casters.len());
            self.patch.clear();
            let caster_bounds = instances.caster_centers.iter().zip(&instances.caster_radii);
            match patch {
                Some(slots) => {
                    let casters = slots.iter().map(|&s| instances.caster_index[s as usize]);
                    self.patch.extend(casters.filter(|&c| c != NOT_A_CASTER));
                    let known = self.bounds.len();
                    self.bounds.extend(caster_bounds.skip(known).map(|(c, &r)| c.extend(r)));
                    for &c in &self.patch {
                        let c = c as usize;
                        self.bounds[c] = instances.caster_centers[c].extend(instances.caster_radii[c]);
                    }
                }
                None => {
                    self.bounds.clear();
                    self.bounds.extend(caster_bounds.map(|(c, &r)| c.extend(r)));
                }
            }
            let patch = patch.map(|_| &self.patch[..]);
            let generation = instances.generation;
            let bounds = bytemuck::cast_slice(&self.bounds);
            replaced |= buffers.bounds.write_patch(gpu, generation, bounds, 16, patch)?;
            let casters = bytemuck::cast_slice(&instances.casters);
            replaced |= buffers.casters.write_patch(gpu, generation, casters, 4, patch)?;
            self.instance_generation = Some(generation);
        }
        // NOTE: the arguments follow the mesh ranges, so they are made every frame (a few per
        // view); the runs and the list's room only with the views' lists.
        self.template.clear();
        self.bases.clear();
        let mut room = 0;
        for (group, &(_, count)) in views.groups.iter().zip(&views.run_ranges) {
            if count == 0 {
                self.bases.push(None);
                continue;
            }
            self.bases.push(Some(self.template.len() as u32));
            let opaque = group.opaque.iter().map(|b| (b, IndexList::for_caster(false, false)));
            let masked = group.masked.iter().map(|b| (b, IndexList::for_caster(true, false)));
            self.template.extend(opaque.chain(masked).map(|(b, list)| {
                let range = scene.mesh_ranges.get(b.mesh.0 as usize).copied().unwrap_or_default();
                IndexedArgs {
                    index_count: range.index_count,
                    instance_count: 0,
                    first_index: range.first_of(list),
                    base_vertex: range.base_vertex,
                    first_instance: room + b.first,
                }
            }));
            room += group.instance_count();
        }
        if self.view_generation != Some(views.generation) {
            self.runs.clear();
            let bases = &self.bases;
            self.runs.extend(views.runs.iter().map(|r| ShadowRun {
                batch: bases[r.view as usize].unwrap_or(0) + r.batch,
                ..*r
            }));
            replaced |= buffers.runs.write(gpu, bytemuck::cast_slice(&self.runs))?;
            replaced |= buffers.list.reserve(gpu, u64::from(room.max(1)) * 4)?;
            self.view_generation = Some(views.generation);
        }
        // NOTE: the arguments are written when a view is culled (`record`): a still frame
        // uploads nothing.
        let bytes = (self.template.len() * size_of::<IndexedArgs>()) as u64;
        replaced |= buffers.args.reserve(gpu, bytes)?;
        self.views.clear();
        self.views.extend(views.views.iter().map(|v| cull_view(&v.cull)));
        replaced |= buffers
            .views
            .reserve(gpu, (self.views.len() * size_of::<CullViewGpu>()) as u64)?;
        let dispatch = DispatchGpu {
            runs: self.runs.len() as u32,
            row: DISPATCH_ROW,
            _pad: [0; 2],
        };
        gpu.queue
            .write_buffer(&buffers.dispatch, 0, bytemuck::bytes_of(&dispatch));
        let (instance_buffer, _) = scene.view_buffers();
        replaced |= self.bound.as_ref() != Some(instance_buffer);
        if let (true, Some(kernel)) = (replaced || self.groups.is_none(), &self.kernel) {
            let cull = [
                &buffers.dispatch,
                &buffers.views.buffer,
                &buffers.bounds.buffer,
                &buffers.casters.buffer,
                &buffers.runs.buffer,
                &buffers.args.buffer,
                &buffers.list.buffer,
            ];
            let cull = buffer_group(device, "shadow culling", &kernel.layout, &cull);
            let draw = instances_group(device, layouts, instance_buffer, &buffers.list.buffer, "shadow culled");
            self.groups = Some((cull, draw));
            self.bound = Some(instance_buffer.clone());
        }
        Ok(())
    }

    /// Records the culling of the runs of the views `drawn` says are drawn this frame (by
    /// view index), after resetting every view's arguments; nothing (no upload either) when
    /// none of them is culled on the GPU.
    pub fn record(
        &mut self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        drawn: &[bool],
    ) {
        let (Some(kernel), Some(buffers), Some((cull, _))) = (&self.kernel, &self.buffers, &self.groups) else {
            return;
        };
        let mut any = false;
        for (v, view) in self.views.iter_mut().enumerate() {
            let on = self.bases.get(v).is_some_and(Option::is_some) && drawn.get(v) == Some(&true);
            view.drawn = u32::from(on);
            any |= on;
        }
        if !any {
            return;
        }
        queue.write_buffer(&buffers.views.buffer, 0, bytemuck::cast_slice(&self.views));
        queue.write_buffer(&buffers.args.buffer, 0, bytemuck::cast_slice(&self.template));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(SHADOW_CULL_NAME),
            timestamp_writes: timer.compute_pass(SHADOW_CULL_NAME),
        });
        pass.set_pipeline(&kernel.pipeline);
        pass.set_bind_group(0, cull, &[]);
        let runs = self.runs.len() as u32;
        pass.dispatch_workgroups(runs.min(DISPATCH_ROW), runs.div_ceil(DISPATCH_ROW), 1);
    }

    /// The instances the last frame's culling listed for view `v`, batch by batch (opaque,
    /// then masked), in list order (waits for the GPU; for tests). None for a view the CPU
    /// listed.
    pub fn read_lists(&self, gpu: &GpuContext, v: usize, batches: usize) -> Option<Vec<Vec<u32>>> {
        let base = (*self.bases.get(v)?)? as usize;
        let buffers = self.buffers.as_ref()?;
        let buffers = (&buffers.args.buffer, &buffers.list.buffer);
        read_indirect_lists(&gpu.device, &gpu.queue, buffers, base, batches)
    }
}

#[cfg(test)]
mod tests {
    use std::mem::offset_of;

    use super::*;
    use crate::render::shadows::jobs::layout_check::wgsl_layout;

    #[test]
    fn the_shader_structs_match_the_rust_ones() {
        let module = ShaderLibrary::new().unwrap().shadow_cull().unwrap();
        let fields = |names: &[(&str, usize)]| names.iter().map(|&(n, o)| (n.to_owned(), o)).collect::<Vec<_>>();
        assert_eq!(
            wgsl_layout(&module, "CullView"),
            (
                fields(&[
                    ("a", offset_of!(CullViewGpu, a)),
                    ("reach", offset_of!(CullViewGpu, reach)),
                    ("kind", offset_of!(CullViewGpu, kind)),
                    ("drawn", offset_of!(CullViewGpu, drawn)),
                ]),
                size_of::<CullViewGpu>()
            )
        );
        assert_eq!(
            wgsl_layout(&module, "Run"),
            (
                fields(&[
                    ("first", offset_of!(ShadowRun, first)),
                    ("count", offset_of!(ShadowRun, count)),
                    ("batch", offset_of!(ShadowRun, batch)),
                    ("view", offset_of!(ShadowRun, view)),
                ]),
                size_of::<ShadowRun>()
            )
        );
        assert_eq!(
            wgsl_layout(&module, "Dispatch"),
            (
                fields(&[
                    ("runs", offset_of!(DispatchGpu, runs)),
                    ("row", offset_of!(DispatchGpu, row))
                ]),
                size_of::<DispatchGpu>()
            )
        );
    }
}
