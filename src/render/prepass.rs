//! The depth prepass: writes the camera's depth of every opaque and alpha-masked receiver
//! before the lighting pass, which then tests `GreaterEqual` against it without writing, so
//! each covered pixel is shaded once however much geometry overlaps it. It creates the
//! frame's camera depth (a transient of the graph) that the forward pass and later passes
//! read. When it does not run ([`RenderOptions::depth_prepass`](crate::render::RenderOptions):
//! off, or `Auto` on a view of more triangles than pixels), it declares nothing and is culled;
//! the forward pass then creates and writes the depth itself.

use std::borrow::Cow;

use crate::ecs::draw_groups::DrawBatch;
use crate::render::draw::{draw_batches, vertex_layout};
use crate::render::frame::{FrameContext, FrameInputs};
use crate::render::graph::{FrameResources, GraphResources, PassBuilder, RenderNode, TextureDesc, TextureId};
use crate::render::layouts::Layouts;
use crate::render::target::DEPTH_FORMAT;
use crate::shader::ShaderLibrary;

/// Name of the prepass in GPU timings and the graph.
pub const PREPASS_NAME: &str = "depth prepass";

/// The camera's depth buffer at the target's size.
pub fn camera_depth((width, height): (u32, u32)) -> TextureDesc {
    TextureDesc {
        label: "camera depth",
        width,
        height,
        layers: 1,
        format: DEPTH_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
    }
}

/// The prepass node; its four pipelines (opaque or masked, single- or double-sided) are built
/// on first use.
#[derive(Default)]
pub struct DepthPrepass {
    /// Indexed by `masked as usize * 2 + double_sided as usize`.
    pipelines: [Option<wgpu::RenderPipeline>; 4],
    depth: Option<TextureId>,
}

impl DepthPrepass {
    fn pipeline(
        &mut self,
        device: &wgpu::Device,
        layouts: &Layouts,
        library: &mut ShaderLibrary,
        masked: bool,
        double_sided: bool,
    ) -> &wgpu::RenderPipeline {
        self.pipelines[masked as usize * 2 + double_sided as usize]
            .get_or_insert_with(|| create_pipeline(device, layouts, library, masked, double_sided))
    }
}

fn create_pipeline(
    device: &wgpu::Device,
    layouts: &Layouts,
    library: &mut ShaderLibrary,
    masked: bool,
    double_sided: bool,
) -> wgpu::RenderPipeline {
    let module = library
        .prepass()
        .expect("the shipped prepass shader composes (checked by tests)");
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("depth prepass"),
        source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
    });
    let material = masked.then_some(&layouts.material);
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("depth prepass"),
        bind_group_layouts: &[Some(&layouts.view), Some(&layouts.instances), material],
        immediate_size: 0,
    });
    let buffers = [Some(vertex_layout())];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(PREPASS_NAME),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &shader,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &buffers,
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: if double_sided { None } else { Some(wgpu::Face::Back) },
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Greater),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: masked.then(|| wgpu::FragmentState {
            module: &shader,
            entry_point: Some("fs_masked"),
            compilation_options: Default::default(),
            targets: &[],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Triangles the camera's view draws this frame (every instance of every batch).
fn visible_triangles(inputs: &FrameInputs<'_>) -> u64 {
    let group = &inputs.view_groups.group;
    group
        .opaque
        .iter()
        .chain(&group.masked)
        .map(|b| {
            let indices = inputs.meshes.get(b.mesh).map_or(0, |m| m.indices.len() as u64);
            indices / 3 * u64::from(b.count)
        })
        .sum()
}

impl RenderNode for DepthPrepass {
    fn name(&self) -> &'static str {
        PREPASS_NAME
    }

    /// Creates the camera depth and writes it (nothing when off).
    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, inputs: &FrameInputs<'_>) {
        self.depth = None;
        let pixels = u64::from(frame.size.0) * u64::from(frame.size.1);
        let runs = inputs.options.depth_prepass.runs(|| visible_triangles(inputs), pixels);
        if runs && frame.depth.is_none() {
            let depth = pass.create_texture(camera_depth(frame.size));
            frame.depth = Some(depth);
            self.depth = Some(depth);
        }
    }

    fn record(&mut self, ctx: &mut FrameContext<'_>, resources: &GraphResources, encoder: &mut wgpu::CommandEncoder) {
        let Some(depth) = self.depth else { return };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(PREPASS_NAME),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: resources.view(depth),
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: ctx.timer.pass(PREPASS_NAME),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let Some((vertices, indices)) = ctx.scene.mesh_buffers() else {
            return;
        };
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.set_bind_group(0, &ctx.scene.view_group, &[]);
        pass.set_bind_group(1, &ctx.scene.view_instances_group, &[]);
        let group = &ctx.view_groups.group;
        for (masked, batches) in [(false, &group.opaque), (true, &group.masked)] {
            // NOTE: batches are sorted single-sided first (the draw key), as in the forward pass.
            let split = batches.partition_point(|b: &DrawBatch| !b.double_sided);
            for (double_sided, part) in [(false, &batches[..split]), (true, &batches[split..])] {
                if part.is_empty() {
                    continue;
                }
                let device = &ctx.gpu.device;
                pass.set_pipeline(self.pipeline(device, ctx.layouts, ctx.library, masked, double_sided));
                ctx.draw_calls += draw_batches(&mut pass, ctx.scene, part, masked);
            }
        }
    }
}
