//! Shadow pass: renders the casters of each active cascade into its layer of the shadow map.
//! Per cascade: clear to the reverse-Z far value (0), draw the opaque group with the
//! depth-only pipeline (no fragment stage), then the alpha-masked group with the alpha-test
//! pipeline. Both use slope-scaled depth bias with a clamp and, where the adapter allows,
//! unclipped depth so casters in front of the near plane are flattened onto it.

use std::borrow::Cow;

use crate::ecs::draw_groups::DrawBatch;
use crate::mesh::Vertex;
use crate::render::frame::FrameContext;
use crate::render::graph::RenderNode;
use crate::render::layouts::Layouts;
use crate::render::scene_gpu::SceneGpu;
use crate::render::shadow_map::SHADOW_FORMAT;
use crate::shader::ShaderLibrary;

/// Pass names used for GPU timings, one per cascade.
pub const CASCADE_PASS_NAMES: [&str; 4] = [
    "shadow cascade 0",
    "shadow cascade 1",
    "shadow cascade 2",
    "shadow cascade 3",
];

/// Pipeline state that forces a rebuild when it changes.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PipelineKey {
    slope_bias: f32,
    bias_clamp: f32,
    unclipped: bool,
}

struct Pipelines {
    key: PipelineKey,
    opaque: wgpu::RenderPipeline,
    masked: wgpu::RenderPipeline,
}

/// The shadow-map node.
#[derive(Default)]
pub struct ShadowPass {
    pipelines: Option<Pipelines>,
}

/// Vertex layout of the mesh buffers: position (0), normal (1), uv (2).
pub const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2];

/// The mesh vertex buffer layout.
pub fn vertex_layout() -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &VERTEX_ATTRIBUTES,
    }
}

fn create_pipelines(
    device: &wgpu::Device,
    layouts: &Layouts,
    library: &mut ShaderLibrary,
    key: PipelineKey,
) -> Pipelines {
    let module = library
        .caster()
        .expect("the shipped caster shader composes (checked by tests)");
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("caster"),
        source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
    });
    let opaque_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("shadow opaque"),
        bind_group_layouts: &[Some(&layouts.cascade_view), Some(&layouts.instances)],
        immediate_size: 0,
    });
    let masked_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("shadow masked"),
        bind_group_layouts: &[
            Some(&layouts.cascade_view),
            Some(&layouts.instances),
            Some(&layouts.material),
        ],
        immediate_size: 0,
    });
    // NOTE: reverse-Z stores larger depth nearer the light, so the bias is negative: it pushes
    // casters away from the light. The clamp is negative too (Vulkan takes max(bias, clamp)).
    let depth_stencil = wgpu::DepthStencilState {
        format: SHADOW_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Greater),
        stencil: wgpu::StencilState::default(),
        bias: wgpu::DepthBiasState {
            constant: 0,
            slope_scale: -key.slope_bias,
            clamp: -key.bias_clamp,
        },
    };
    let primitive = wgpu::PrimitiveState {
        // Two-sided: single-sided casters (planes, cards) must cast from both sides.
        cull_mode: None,
        unclipped_depth: key.unclipped,
        ..Default::default()
    };
    let buffers = [Some(vertex_layout())];
    let build = |label: &str, layout: &wgpu::PipelineLayout, fragment: Option<wgpu::FragmentState<'_>>| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &buffers,
            },
            primitive,
            depth_stencil: Some(depth_stencil.clone()),
            multisample: wgpu::MultisampleState::default(),
            fragment,
            multiview_mask: None,
            cache: None,
        })
    };
    let opaque = build("shadow opaque (depth only)", &opaque_layout, None);
    let masked = build(
        "shadow masked (alpha test)",
        &masked_layout,
        Some(wgpu::FragmentState {
            module: &shader,
            entry_point: Some("fs_masked"),
            compilation_options: Default::default(),
            targets: &[],
        }),
    );
    Pipelines { key, opaque, masked }
}

/// Issues one instanced indexed draw per batch.
pub fn draw_batches(
    pass: &mut wgpu::RenderPass<'_>,
    scene: &SceneGpu,
    batches: &[DrawBatch],
    bind_material: bool,
) -> u32 {
    let mut last_material = None;
    for batch in batches {
        let Some(range) = scene.mesh_ranges.get(batch.mesh.0 as usize) else {
            continue;
        };
        if bind_material && last_material != Some(batch.material) {
            let Some(group) = scene.material_groups.get(batch.material.0 as usize) else {
                continue;
            };
            pass.set_bind_group(2, group, &[]);
            last_material = Some(batch.material);
        }
        pass.draw_indexed(
            range.first_index..range.first_index + range.index_count,
            range.base_vertex,
            batch.first..batch.first + batch.count,
        );
    }
    batches.len() as u32
}

impl RenderNode for ShadowPass {
    fn name(&self) -> &'static str {
        "shadow"
    }

    fn reads(&self) -> &'static [&'static str] {
        &["instances"]
    }

    fn writes(&self) -> &'static [&'static str] {
        &["shadow_map"]
    }

    fn record(&mut self, ctx: &mut FrameContext<'_>, encoder: &mut wgpu::CommandEncoder) {
        let Some(sun) = ctx.sun.filter(|s| s.cascades.count > 0) else {
            return;
        };
        let Some((vertices, indices)) = ctx.scene.mesh_buffers() else {
            return;
        };
        let key = PipelineKey {
            slope_bias: sun.settings.slope_bias,
            bias_clamp: sun.settings.bias_clamp,
            unclipped: sun.settings.depth_clamp && ctx.gpu.unclipped_depth,
        };
        if self.pipelines.as_ref().is_none_or(|p| p.key != key) {
            self.pipelines = Some(create_pipelines(&ctx.gpu.device, ctx.layouts, ctx.library, key));
            ctx.counters.caster_pipelines += 1;
        }
        let Some(pipelines) = &self.pipelines else { return };
        let active = &ctx.shadow_groups.cascades[..ctx.shadow_groups.count];
        for (c, (group, name)) in active.iter().zip(CASCADE_PASS_NAMES).enumerate() {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(name),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &ctx.shadow_map.layer_views[c],
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: ctx.timer.pass(name),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
            let offset = (c * size_of::<crate::render::gpu_types::CascadeViewGpu>()) as u32;
            pass.set_bind_group(0, &ctx.scene.cascade_view_group, &[offset]);
            pass.set_bind_group(1, &ctx.scene.shadow_instances_group, &[]);
            pass.set_pipeline(&pipelines.opaque);
            ctx.draw_calls += draw_batches(&mut pass, ctx.scene, &group.opaque, false);
            if !group.masked.is_empty() {
                pass.set_pipeline(&pipelines.masked);
                ctx.draw_calls += draw_batches(&mut pass, ctx.scene, &group.masked, true);
            }
        }
    }
}
