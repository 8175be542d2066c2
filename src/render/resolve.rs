//! The compute visibility resolve: after the depth prepass, one compute pass evaluates every
//! resolved light's shadow filter per pixel from the prepass's depth and normals and writes
//! it into the resolved visibility ([`VisibilityTarget`](crate::render::shadows::visibility::VisibilityTarget));
//! the lighting pass then reads one texel per light instead of filtering. It runs when the
//! frame resolves ([`RenderOptions::visibility_resolve`](crate::render::RenderOptions), on by
//! default, and the prepass runs); otherwise it declares nothing and is culled. With MSAA it
//! reads the multisampled depth and normals at each pixel's sample 0
//! (`texture_depth_multisampled_2d`), with a layout and pipelines of their own.

use std::collections::HashMap;

use crate::render::frame::FrameContext;
use crate::render::frame_inputs::FrameInputs;
use crate::render::graph::{FrameResources, GraphResources, PassBuilder, RenderNode, TextureId};
use crate::render::layouts::{Layouts, camera_texture_entry, entry, main_compute_pipeline};
use crate::render::shadows::visibility::VISIBILITY_FORMAT;
use crate::render::variant::forward_variant;
use crate::shader::{ForwardVariant, ShaderLibrary};

/// Name of the resolve in GPU timings and the graph.
pub const RESOLVE_NAME: &str = "visibility resolve";

/// What the resolve reads and writes this frame.
#[derive(Clone, Copy)]
struct Handles {
    depth: TextureId,
    normals: TextureId,
    /// Samples per pixel of both.
    samples: u32,
}

/// The resolve node: its bind group layouts (single-sample and multisampled inputs), and one
/// pipeline per filter variant and sample count.
#[derive(Default)]
pub struct VisibilityResolve {
    /// Indexed by `multisampled as usize`.
    layouts: [Option<wgpu::BindGroupLayout>; 2],
    pipelines: HashMap<(ForwardVariant, u32), wgpu::ComputePipeline>,
    handles: Option<Handles>,
}

fn create_layout(device: &wgpu::Device, multisampled: bool) -> wgpu::BindGroupLayout {
    let entry = |binding, ty| entry(binding, wgpu::ShaderStages::COMPUTE, ty);
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(RESOLVE_NAME),
        entries: &[
            camera_texture_entry(0, wgpu::TextureSampleType::Depth, multisampled),
            camera_texture_entry(1, wgpu::TextureSampleType::Uint, multisampled),
            entry(
                2,
                wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: VISIBILITY_FORMAT,
                    view_dimension: wgpu::TextureViewDimension::D2Array,
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
    (variant, samples): (ForwardVariant, u32),
) -> wgpu::ComputePipeline {
    let module = library
        .resolve_multisampled(variant, samples)
        .expect("the shipped resolve shader composes (checked by tests)");
    main_compute_pipeline(
        device,
        RESOLVE_NAME,
        module,
        &[Some(&layouts.view), Some(layout), None, Some(&layouts.shadows)],
    )
}

impl RenderNode for VisibilityResolve {
    fn name(&self) -> &'static str {
        RESOLVE_NAME
    }

    /// Reads the prepass's depth and normals and both shadow storages; writes the resolved
    /// visibility. Nothing when the frame does not resolve.
    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, _: &FrameInputs<'_>) {
        self.handles = None;
        let (Some(visibility), Some(depth), Some(normals)) = (frame.visibility, frame.depth, frame.normals) else {
            return;
        };
        pass.read(depth);
        pass.read(normals);
        for texture in frame.shadow_textures() {
            pass.read(texture);
        }
        pass.write(visibility);
        self.handles = Some(Handles {
            depth,
            normals,
            samples: frame.samples.max(1),
        });
    }

    fn record(&mut self, ctx: &mut FrameContext<'_>, resources: &GraphResources, encoder: &mut wgpu::CommandEncoder) {
        let (Some(handles), Some(target)) = (self.handles, ctx.shadows.resolved.as_ref().map(|r| &r.target)) else {
            return;
        };
        let device = &ctx.gpu.device;
        let multisampled = handles.samples > 1;
        let layout = self.layouts[multisampled as usize].get_or_insert_with(|| create_layout(device, multisampled));
        let variant = ForwardVariant {
            debug_cascades: false,
            alpha_mask: false,
            analysis: false,
            ..forward_variant(ctx.lights, false)
        };
        let key = (variant, handles.samples);
        let pipeline = self
            .pipelines
            .entry(key)
            .or_insert_with(|| create_pipeline(device, ctx.layouts, ctx.library, layout, key));
        // NOTE: the depth and normals are transients of this frame, so the group is made per
        // frame (three entries).
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(RESOLVE_NAME),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(resources.view(handles.depth)),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(resources.view(handles.normals)),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&target.storage_view),
                },
            ],
        });
        let (width, height, _) = target.extent;
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(RESOLVE_NAME),
            timestamp_writes: ctx.timer.compute_pass(RESOLVE_NAME),
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &ctx.scene.view_group, &[]);
        pass.set_bind_group(1, &group, &[]);
        // NOTE: the plain shadow group: its resolved visibility is the stand-in, so the pass
        // never samples the texture it writes.
        pass.set_bind_group(3, &ctx.shadows.group, &[]);
        pass.dispatch_workgroups(width.div_ceil(8), height.div_ceil(8), 1);
    }
}
