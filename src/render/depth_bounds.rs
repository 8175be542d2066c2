//! The depth-bounds reduction of the sample-distribution (SDSM) cascade fit: after the camera's
//! depth is complete, one compute pass reduces it to the view-depth range and per-band world
//! boxes the frame covered ([`SeenDepths`](crate::math::seen_depths::SeenDepths)), into a buffer copied to one slot of a small
//! ring of mappable buffers. After submission the slot is mapped without waiting; a later
//! frame decodes whichever slot has come back ([`SeenReadback::latest`](crate::render::seen_readback::SeenReadback::latest)), so the CPU never
//! stalls on the GPU. It runs only while a shadowed sun fits its cascades with
//! [`CascadeFit::DepthBounds`]; otherwise it declares nothing and is culled.

use glam::Vec3;

use crate::render::frame::FrameContext;
use crate::render::frame_inputs::FrameInputs;
use crate::render::graph::{FrameResources, GraphResources, PassBuilder, RenderNode, TextureId};
use crate::render::layouts::{Layouts, camera_texture_entry, entry, main_compute_pipeline};
use crate::render::seen_readback::BYTES;
use crate::settings::CascadeFit;
use crate::shader::ShaderLibrary;

/// Name of the reduction in GPU timings and the graph.
pub const DEPTH_BOUNDS_NAME: &str = "depth bounds";

/// What the reduction reads this frame.
#[derive(Clone, Copy)]
struct Handles {
    depth: TextureId,
    samples: u32,
    /// The depth's size in pixels.
    size: (u32, u32),
    /// The camera's near and far planes (the bands' limits).
    planes: (f32, f32),
    origin: Vec3,
}

/// The reduction node: a layout and a pipeline per depth kind (single-sample, multisampled).
#[derive(Default)]
pub struct DepthBoundsPass {
    layouts: [Option<wgpu::BindGroupLayout>; 2],
    pipelines: [Option<wgpu::ComputePipeline>; 2],
    handles: Option<Handles>,
}

fn create_layout(device: &wgpu::Device, multisampled: bool) -> wgpu::BindGroupLayout {
    let entry = |binding, ty| entry(binding, wgpu::ShaderStages::COMPUTE, ty);
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(DEPTH_BOUNDS_NAME),
        entries: &[
            camera_texture_entry(0, wgpu::TextureSampleType::Depth, multisampled),
            entry(
                1,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: false },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
            ),
        ],
    })
}

fn create_pipeline(
    device: &wgpu::Device,
    layouts: &Layouts,
    library: &mut ShaderLibrary,
    layout: &wgpu::BindGroupLayout,
    multisampled: bool,
) -> wgpu::ComputePipeline {
    let module = library
        .depth_bounds(multisampled)
        .expect("the shipped depth-bounds shader composes (checked by tests)");
    main_compute_pipeline(device, DEPTH_BOUNDS_NAME, module, &[Some(&layouts.view), Some(layout)])
}

/// Whether a shadowed sun of the frame fits its cascades to the depths seen.
pub fn wants_depth_bounds(inputs: &FrameInputs<'_>) -> bool {
    inputs.lights.suns.iter().any(|sun| {
        sun.settings.map.cascades.fit == CascadeFit::DepthBounds && sun.cascades.count > 0 && !sun.cascades.clipmap
    })
}

impl RenderNode for DepthBoundsPass {
    fn name(&self) -> &'static str {
        DEPTH_BOUNDS_NAME
    }

    /// Reads the camera's depth; kept for its readback. Nothing when no sun fits to it.
    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, inputs: &FrameInputs<'_>) {
        self.handles = None;
        let (Some(depth), Some((camera, _))) = (frame.depth, inputs.view.camera) else {
            return;
        };
        if !wants_depth_bounds(inputs) {
            return;
        }
        pass.read(depth);
        pass.side_effect();
        self.handles = Some(Handles {
            depth,
            samples: frame.samples.max(1),
            size: frame.size,
            planes: (camera.near, camera.far),
            origin: inputs.origin,
        });
    }

    fn record(&mut self, ctx: &mut FrameContext<'_>, resources: &GraphResources, encoder: &mut wgpu::CommandEncoder) {
        let Some(handles) = self.handles else {
            return;
        };
        let (near, far) = handles.planes;
        if !(near > 0.0 && far > near && far.is_finite()) {
            return;
        }
        let device = &ctx.gpu.device;
        let Some(slot) = ctx.seen.take_slot(device, handles.origin) else {
            return;
        };
        let multisampled = handles.samples > 1;
        let layout = self.layouts[multisampled as usize].get_or_insert_with(|| create_layout(device, multisampled));
        let pipeline = self.pipelines[multisampled as usize]
            .get_or_insert_with(|| create_pipeline(device, ctx.layouts, ctx.library, layout, multisampled));
        ctx.seen.reset((device, &ctx.gpu.queue), encoder, (near, far));
        let seen = &*ctx.seen;
        let Some(reduce) = &seen.reduce else {
            return;
        };
        // NOTE: the depth is a transient of this frame, so the group is made per frame.
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(DEPTH_BOUNDS_NAME),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(resources.view(handles.depth)),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: reduce.as_entire_binding(),
                },
            ],
        });
        let (width, height) = handles.size;
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(DEPTH_BOUNDS_NAME),
                timestamp_writes: ctx.timer.compute_pass(DEPTH_BOUNDS_NAME),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &ctx.scene.view_group, &[]);
            pass.set_bind_group(1, &group, &[]);
            pass.dispatch_workgroups(width.div_ceil(16), height.div_ceil(16), 1);
        }
        encoder.copy_buffer_to_buffer(reduce, 0, &seen.buffers[slot], 0, BYTES);
    }
}
