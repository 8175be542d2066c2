//! The partial clear of shadow layers (`shaders/shadow_clear.wgsl`): a depth-only pipeline
//! that writes the far depth under the scissor rectangle, one per multiview view count (0:
//! one view per pass). On GPUs with few raster units a full 2048² depth clear costs about
//! as much as the whole layer's fill, far more than drawing a small scene's casters; clearing
//! only the rectangle the last draw wrote makes a redraw cost what it draws.

use std::borrow::Cow;
use std::collections::HashMap;
use std::num::NonZeroU32;

use crate::render::shadows::storage::SHADOW_FORMAT;
use crate::shader::ShaderLibrary;

/// The depth state of a pass that writes every texel it covers whatever it held (a clear, a
/// clipmap level's shift): depth test `Always`, writes on, no bias.
pub fn overwrite_depth() -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: SHADOW_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Always),
        stencil: wgpu::StencilState::default(),
        bias: wgpu::DepthBiasState::default(),
    }
}

/// Built clear pipelines, by multiview view count.
#[derive(Default)]
pub struct ClearPipelines {
    shader: Option<wgpu::ShaderModule>,
    layout: Option<wgpu::PipelineLayout>,
    pipelines: HashMap<u32, wgpu::RenderPipeline>,
}

impl ClearPipelines {
    /// The pipeline for passes of `views` multiview views (0: not multiview), built on first
    /// use (it depends on nothing a scene changes, so it is not counted in
    /// [`RenderCounters`](crate::render::RenderCounters)).
    pub fn get(&mut self, device: &wgpu::Device, library: &mut ShaderLibrary, views: u32) -> &wgpu::RenderPipeline {
        let shader = self.shader.get_or_insert_with(|| {
            let module = library
                .shadow_clear()
                .expect("the shipped clear shader composes (checked by tests)");
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("shadow clear"),
                source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
            })
        });
        let layout = self.layout.get_or_insert_with(|| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("shadow clear"),
                bind_group_layouts: &[],
                immediate_size: 0,
            })
        });
        self.pipelines.entry(views).or_insert_with(|| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("shadow clear"),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module: shader,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: Some(overwrite_depth()),
                multisample: wgpu::MultisampleState::default(),
                fragment: None,
                multiview_mask: NonZeroU32::new((1 << views) - 1),
                cache: None,
            })
        })
    }
}
