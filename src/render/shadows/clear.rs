//! The partial clear of shadow layers (`shaders/shadow_clear.wgsl`): a depth-only pipeline
//! that writes the far depth under the scissor rectangle, one per multiview view count (0:
//! one view per pass). On GPUs with few raster units a full 2048² depth clear costs about
//! as much as the whole layer's fill, far more than drawing a small scene's casters; clearing
//! only the rectangle the last draw wrote makes a redraw cost what it draws.

use std::borrow::Cow;
use std::collections::HashMap;
use std::num::NonZeroU32;

use crate::shader::ShaderLibrary;

/// The depth state of a pass that writes every texel it covers whatever it held (a clear, a
/// clipmap level's shift) into `format`: depth test `Always`, writes on, no bias.
pub fn overwrite_depth(format: wgpu::TextureFormat) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Always),
        stencil: wgpu::StencilState::default(),
        bias: wgpu::DepthBiasState::default(),
    }
}

/// A pipeline that writes depth whatever the target held ([`overwrite_depth`]): vertex
/// stage `vertex` of `shader` with no vertex buffers, fragment stage `fragment` when given
/// (none: the rasterised depth is written), over `views` multiview views (0: not multiview),
/// into `format`.
pub fn overwrite_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    (shader, vertex, fragment): (&wgpu::ShaderModule, &str, Option<&str>),
    (views, format): (u32, wgpu::TextureFormat),
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some(vertex),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(overwrite_depth(format)),
        multisample: wgpu::MultisampleState::default(),
        fragment: fragment.map(|entry| wgpu::FragmentState {
            module: shader,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            targets: &[],
        }),
        multiview_mask: NonZeroU32::new((1 << views) - 1),
        cache: None,
    })
}

/// Built clear pipelines, by multiview view count and depth format.
#[derive(Default)]
pub struct ClearPipelines {
    shader: Option<wgpu::ShaderModule>,
    layout: Option<wgpu::PipelineLayout>,
    pipelines: HashMap<(u32, wgpu::TextureFormat), wgpu::RenderPipeline>,
}

impl ClearPipelines {
    /// The pipeline for passes of `views` multiview views (0: not multiview) into `format`,
    /// built on first use (it depends on nothing a scene changes, so it is not counted in
    /// [`RenderCounters`](crate::render::RenderCounters)).
    pub fn get(
        &mut self,
        device: &wgpu::Device,
        library: &mut ShaderLibrary,
        (views, format): (u32, wgpu::TextureFormat),
    ) -> &wgpu::RenderPipeline {
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
        self.pipelines.entry((views, format)).or_insert_with(|| {
            overwrite_pipeline(
                device,
                "shadow clear",
                layout,
                (shader, "vs_main", None),
                (views, format),
            )
        })
    }
}
