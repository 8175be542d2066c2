//! Forward pass: draws what the camera sees, shading receivers with the sun's diffuse light
//! times the cascaded shadow factor from `penumbra::shadow`, plus ambient light.

use std::borrow::Cow;
use std::collections::HashMap;

use crate::render::frame::FrameContext;
use crate::render::graph::RenderNode;
use crate::render::layouts::Layouts;
use crate::render::shadow_pass::{draw_batches, vertex_layout};
use crate::render::target::{ANALYSIS_FORMAT, DEPTH_FORMAT};
use crate::shader::{ForwardVariant, ShaderLibrary};

/// Name of the forward pass in GPU timings.
pub const FORWARD_PASS_NAME: &str = "forward";

/// The forward node; pipelines are created on first use of each variant.
#[derive(Default)]
pub struct ForwardPass {
    pipelines: HashMap<(ForwardVariant, wgpu::TextureFormat), wgpu::RenderPipeline>,
    /// Colour the target is cleared to (linear RGB).
    pub clear_color: [f64; 3],
}

fn create_pipeline(
    device: &wgpu::Device,
    layouts: &Layouts,
    library: &mut ShaderLibrary,
    variant: ForwardVariant,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    let module = library
        .forward(variant)
        .expect("the shipped forward shader composes (checked by tests)");
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("forward"),
        source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("forward"),
        bind_group_layouts: &[Some(&layouts.view), Some(&layouts.instances), Some(&layouts.material)],
        immediate_size: 0,
    });
    let buffers = [Some(vertex_layout())];
    let mut targets = vec![Some(format.into())];
    if variant.analysis {
        targets.extend((0..3).map(|_| Some(ANALYSIS_FORMAT.into())));
    }
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(&format!("forward {}", variant.label())),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &shader,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &buffers,
        },
        primitive: wgpu::PrimitiveState {
            // Masked cards are seen from both sides; opaque meshes are closed or face up.
            cull_mode: if variant.alpha_mask {
                None
            } else {
                Some(wgpu::Face::Back)
            },
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
        fragment: Some(wgpu::FragmentState {
            module: &shader,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

impl ForwardPass {
    /// A forward pass clearing to `clear_color` (linear RGB).
    pub fn new(clear_color: [f64; 3]) -> Self {
        Self {
            pipelines: HashMap::new(),
            clear_color,
        }
    }

    fn pipeline(&mut self, ctx: &mut FrameContext<'_>, variant: ForwardVariant) -> wgpu::RenderPipeline {
        let format = ctx.target.format;
        self.pipelines
            .entry((variant, format))
            .or_insert_with(|| create_pipeline(&ctx.gpu.device, ctx.layouts, ctx.library, variant, format))
            .clone()
    }
}

impl RenderNode for ForwardPass {
    fn name(&self) -> &'static str {
        FORWARD_PASS_NAME
    }

    fn reads(&self) -> &'static [&'static str] {
        &["shadow_map", "instances"]
    }

    fn writes(&self) -> &'static [&'static str] {
        &["color", "depth"]
    }

    fn record(&mut self, ctx: &mut FrameContext<'_>, encoder: &mut wgpu::CommandEncoder) {
        let settings = ctx.sun.map(|s| s.settings).unwrap_or_default();
        let analysis = ctx.target.analysis.is_some();
        let variant = |mask| ForwardVariant {
            analysis,
            ..ForwardVariant::for_settings(&settings, mask)
        };
        let opaque = self.pipeline(ctx, variant(false));
        let masked = self.pipeline(ctx, variant(true));
        let [r, g, b] = self.clear_color;
        let attachment = |view, clear| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(clear),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        // NOTE: a fixed array, not a Vec: nothing is allocated per frame.
        let mut color_attachments = [const { None }; 4];
        color_attachments[0] = attachment(&ctx.target.color, wgpu::Color { r, g, b, a: 1.0 });
        let mut used = 1;
        // Background: shadow factor 1 (nothing shadows the sky), cascade -1, position w = 0.
        let clears = [
            wgpu::Color {
                r: 1.0,
                g: -1.0,
                b: 0.0,
                a: 0.0,
            },
            wgpu::Color::TRANSPARENT,
            wgpu::Color::TRANSPARENT,
        ];
        for (view, clear) in ctx.target.analysis.iter().flatten().zip(clears) {
            color_attachments[used] = attachment(view, clear);
            used += 1;
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(FORWARD_PASS_NAME),
            color_attachments: &color_attachments[..used],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &ctx.target.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: ctx.timer.pass(FORWARD_PASS_NAME),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let (Some((vertices, indices)), Some(view_group)) = (ctx.scene.mesh_buffers(), ctx.scene.view_group.as_ref())
        else {
            return;
        };
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.set_bind_group(0, view_group, &[]);
        pass.set_bind_group(1, &ctx.scene.view_instances_group, &[]);
        let group = &ctx.view_groups.group;
        pass.set_pipeline(&opaque);
        ctx.draw_calls += draw_batches(&mut pass, ctx.scene, &group.opaque, true);
        pass.set_pipeline(&masked);
        ctx.draw_calls += draw_batches(&mut pass, ctx.scene, &group.masked, true);
    }
}
