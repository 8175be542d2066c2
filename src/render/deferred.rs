//! Deferred lighting of the prepass's pixels: where the frame lights them so
//! ([`FrameResources::deferred_lighting`](crate::render::graph::FrameResources::deferred_lighting)),
//! the prepass also writes each pixel's shading id (the instance it saw, when that instance's
//! material is opaque and untextured), and one pass lights those pixels from the prepass's
//! depth and normals with the shipped material's lighting (`shaders/deferred.wgsl`, sharing
//! `penumbra::shading` with the forward shader). The lighting pass then draws only the other
//! materials' batches, over the colour this pass wrote. A frame whose triangles cost more than
//! its pixels (the 100k field draws about three triangles per pixel) stops drawing them twice.
//!
//! Where the target has a storage view ([`TargetViews::storage`](crate::render::target::TargetViews)),
//! the lighting runs in a compute pass that writes every pixel (the lit colour or the clear
//! colour); elsewhere (a window's swapchain) in a full-screen render pass over a cleared
//! target. The forward pass owns it and records it first, into the same colour target, so both
//! see the same shadow group and clear colour.

use std::borrow::Cow;
use std::collections::HashMap;

use crate::render::frame::FrameContext;
use crate::render::gpu_types::InstanceGpu;
use crate::render::graph::{GraphResources, TextureId};
use crate::render::layouts::{Layouts, camera_texture_entry, entry, main_compute_pipeline, storage};
use crate::render::scene_gpu::uniform_buffer;
use crate::render::target::HEADLESS_STORAGE_FORMAT;
use crate::shader::{ForwardVariant, ShaderLibrary};

/// Name of the deferred lighting pass in GPU timings.
pub const DEFERRED_NAME: &str = "deferred lighting";

/// What the pass reads this frame: the prepass's depth, normals and shading ids.
#[derive(Clone, Copy, Debug)]
pub struct DeferredInputs {
    /// The camera depth.
    pub depth: TextureId,
    /// The packed normals (`penumbra::normal_packing`).
    pub normals: TextureId,
    /// The shading ids.
    pub ids: TextureId,
}

/// Where the pass writes: the target's colour view and format, its storage view when it has
/// one (then the pass runs in compute), and the clear colour.
pub struct DeferredTarget<'a> {
    /// The colour attachment.
    pub color: &'a wgpu::TextureView,
    /// Its format.
    pub format: wgpu::TextureFormat,
    /// The same texture as [`HEADLESS_STORAGE_FORMAT`] storage.
    pub storage: Option<&'a wgpu::TextureView>,
    /// Colour of the pixels nothing lit (linear RGB).
    pub clear: wgpu::Color,
    /// Its size in pixels.
    pub size: (u32, u32),
}

/// A built pipeline of either kind.
enum Pipeline {
    Render(wgpu::RenderPipeline),
    Compute(wgpu::ComputePipeline),
}

/// The pass's input layouts (group 2; indexed by `compute as usize`) and its pipelines, one
/// per forward variant, target format and kind; a pipeline that fails to build is remembered
/// as missing (the forward pass then draws every material). The compute kind's clear colour
/// lives in a uniform rewritten when it changes.
#[derive(Default)]
pub struct DeferredPass {
    layouts: [Option<wgpu::BindGroupLayout>; 2],
    pipelines: HashMap<(ForwardVariant, wgpu::TextureFormat, bool), Option<Pipeline>>,
    clear: Option<(wgpu::Buffer, [f32; 4])>,
}

fn create_layout(device: &wgpu::Device, compute: bool) -> wgpu::BindGroupLayout {
    let stage = if compute {
        wgpu::ShaderStages::COMPUTE
    } else {
        wgpu::ShaderStages::FRAGMENT
    };
    let texture = |binding, sample_type| wgpu::BindGroupLayoutEntry {
        visibility: stage,
        ..camera_texture_entry(binding, sample_type, false)
    };
    let entries = [
        texture(0, wgpu::TextureSampleType::Depth),
        texture(1, wgpu::TextureSampleType::Uint),
        texture(2, wgpu::TextureSampleType::Uint),
        entry(3, stage, storage::<InstanceGpu>()),
        entry(
            4,
            stage,
            wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: HEADLESS_STORAGE_FORMAT,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
        ),
        entry(
            5,
            stage,
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
        ),
    ];
    // NOTE: the compute kind also writes the target and reads the clear colour.
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(DEFERRED_NAME),
        entries: &entries[..if compute { 6 } else { 4 }],
    })
}

/// Builds the pipeline of `variant` (the compute one, or the render one drawing into
/// `format`), catching shader and pipeline errors.
fn create_pipeline(
    device: &wgpu::Device,
    layouts: &Layouts,
    library: &mut ShaderLibrary,
    inputs: &wgpu::BindGroupLayout,
    (variant, format, compute): (ForwardVariant, wgpu::TextureFormat, bool),
) -> Result<Pipeline, String> {
    let module = library.deferred(variant, compute).map_err(|e| e.to_string())?;
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let groups = [Some(&layouts.view), None, Some(inputs), Some(&layouts.shadows)];
    let pipeline = if compute {
        Pipeline::Compute(main_compute_pipeline(device, DEFERRED_NAME, module, &groups))
    } else {
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(DEFERRED_NAME),
            source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(DEFERRED_NAME),
            bind_group_layouts: &groups,
            immediate_size: 0,
        });
        Pipeline::Render(device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(DEFERRED_NAME),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(format.into())],
            }),
            multiview_mask: None,
            cache: None,
        }))
    };
    match pollster::block_on(scope.pop()) {
        None => Ok(pipeline),
        Some(error) => Err(format!("deferred lighting `{}`: {error}", variant.label())),
    }
}

impl DeferredPass {
    /// Records the pass into `target` for forward `variant`, with the frame's `shadow_group`
    /// (group 3, as the forward pass binds it). False when nothing was recorded (its pipeline
    /// could not be built): the caller must then clear the target and draw every material.
    pub fn record(
        &mut self,
        ctx: &mut FrameContext<'_>,
        resources: &GraphResources,
        encoder: &mut wgpu::CommandEncoder,
        (inputs, variant, shadow_group): (DeferredInputs, ForwardVariant, &wgpu::BindGroup),
        target: DeferredTarget<'_>,
    ) -> bool {
        let device = &ctx.gpu.device;
        let compute = target.storage.is_some();
        let layout = self.layouts[compute as usize].get_or_insert_with(|| create_layout(device, compute));
        let key = (variant, target.format, compute);
        let pipeline = self.pipelines.entry(key).or_insert_with(|| {
            create_pipeline(device, ctx.layouts, ctx.library, layout, key)
                .inspect_err(|message| {
                    log::error!("{message}; the lighting pass draws every material");
                    *ctx.pipeline_error = Some(message.clone());
                })
                .ok()
        });
        let Some(pipeline) = pipeline else {
            return false;
        };
        let texture = |binding, view| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(view),
        };
        let instances = ctx.scene.view_buffers().0.as_entire_binding();
        // NOTE: a fixed array, not a Vec: nothing is allocated per frame.
        let mut entries = [
            texture(0, resources.view(inputs.depth)),
            texture(1, resources.view(inputs.normals)),
            texture(2, resources.view(inputs.ids)),
            wgpu::BindGroupEntry {
                binding: 3,
                resource: instances,
            },
            // Placeholders for the compute kind's target and clear colour, set below.
            texture(4, resources.view(inputs.ids)),
            texture(5, resources.view(inputs.ids)),
        ];
        let mut used = 4;
        let wgpu::Color { r, g, b, .. } = target.clear;
        let clear = [
            r as f32,
            g as f32,
            b as f32,
            f32::from(u8::from(target.format.is_srgb())),
        ];
        if let Some(storage) = target.storage {
            let (buffer, written) = self
                .clear
                .get_or_insert_with(|| (uniform_buffer(device, DEFERRED_NAME, 16), [f32::NAN; 4]));
            if *written != clear {
                ctx.gpu.queue.write_buffer(buffer, 0, bytemuck::cast_slice(&clear));
                *written = clear;
            }
            entries[4] = texture(4, storage);
            entries[5] = wgpu::BindGroupEntry {
                binding: 5,
                resource: buffer.as_entire_binding(),
            };
            used = 6;
        }
        // NOTE: the inputs are transients of this frame, so the group is made per frame.
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(DEFERRED_NAME),
            layout,
            entries: &entries[..used],
        });
        match pipeline {
            Pipeline::Compute(pipeline) => {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(DEFERRED_NAME),
                    timestamp_writes: ctx.timer.compute_pass(DEFERRED_NAME),
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &ctx.scene.view_group, &[]);
                pass.set_bind_group(2, &group, &[]);
                pass.set_bind_group(3, shadow_group, &[]);
                let (width, height) = target.size;
                pass.dispatch_workgroups(width.div_ceil(8), height.div_ceil(8), 1);
            }
            Pipeline::Render(pipeline) => {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(DEFERRED_NAME),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: target.color,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(target.clear),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: ctx.timer.pass(DEFERRED_NAME),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &ctx.scene.view_group, &[]);
                pass.set_bind_group(2, &group, &[]);
                pass.set_bind_group(3, shadow_group, &[]);
                pass.draw(0..3, 0..1);
            }
        }
        true
    }
}
