//! The shadow-caster pipelines, cached by everything that changes one: whether the material
//! is alpha-masked, the slope-scaled depth bias and its clamp, unclipped depth, the views of a
//! single-pass (multiview) pass, and the depth format drawn into. Views of several lights with different biases each get
//! theirs; a key seen before reuses its pipeline.

use std::borrow::Cow;
use std::collections::HashMap;

use glam::{Mat4, Vec3};

use crate::render::draw::mesh_vertex_state;
use crate::render::layouts::Layouts;
use crate::settings::ShadowSettings;
use crate::shader::ShaderLibrary;

/// Everything that selects a caster pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CasterKey {
    /// Alpha-tested (fragment stage) instead of depth-only.
    pub masked: bool,
    /// `f32::to_bits` of the slope-scaled bias.
    pub slope_bias: u32,
    /// `f32::to_bits` of the bias clamp.
    pub bias_clamp: u32,
    /// Casters in front of the near plane are flattened onto it instead of clipped.
    pub unclipped: bool,
    /// Views of the multiview pass it draws in (0: one view per pass).
    pub views: u32,
    /// The depth format of the layers it draws into.
    pub format: wgpu::TextureFormat,
}

impl CasterKey {
    /// The key for a light's settings on a device that does (or does not) support unclipped
    /// depth, drawing into layers of depth format `format` (its storage's).
    pub fn new(
        settings: &ShadowSettings,
        masked: bool,
        unclipped_supported: bool,
        format: wgpu::TextureFormat,
    ) -> Self {
        Self {
            masked,
            slope_bias: settings.bias.slope_bias.to_bits(),
            bias_clamp: settings.bias.bias_clamp.to_bits(),
            unclipped: settings.map.depth_clamp && unclipped_supported,
            views: 0,
            format,
        }
    }

    /// This key for a multiview pass of `views` views.
    pub fn with_views(self, views: u32) -> Self {
        Self { views, ..self }
    }
}

/// Built caster pipelines.
#[derive(Default)]
pub struct CasterPipelines {
    pipelines: HashMap<CasterKey, wgpu::RenderPipeline>,
    /// The caster shader: one view per pass, and multiview.
    shaders: [Option<wgpu::ShaderModule>; 2],
}

impl CasterPipelines {
    /// The pipeline for `key`, built on first use; `built` is incremented when one is made.
    pub fn get(
        &mut self,
        device: &wgpu::Device,
        layouts: &Layouts,
        library: &mut ShaderLibrary,
        key: CasterKey,
        built: &mut u32,
    ) -> &wgpu::RenderPipeline {
        let multiview = key.views > 0;
        let shader = self.shaders[usize::from(multiview)].get_or_insert_with(|| {
            let module = library
                .caster(multiview)
                .expect("the shipped caster shader composes (checked by tests)");
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(if multiview { "caster (multiview)" } else { "caster" }),
                source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
            })
        });
        self.pipelines.entry(key).or_insert_with(|| {
            *built += 1;
            create_pipeline(device, layouts, shader, key)
        })
    }
}

/// The hardware depth bias of a caster pipeline with slope-scaled bias `slope` clamped at
/// `clamp`. Reverse-Z stores larger depth nearer the light, so the bias is negative: it
/// pushes casters away from the light. The clamp is negative too (Vulkan takes max(bias,
/// clamp)). No constant bias: a unit of it is the implementation's choice for fixed-point
/// formats; a `Depth16Unorm` layer's rounding is met by [`caster_clip_from_clip`] instead.
pub fn caster_bias(slope: f32, clamp: f32) -> wgpu::DepthBiasState {
    wgpu::DepthBiasState {
        constant: 0,
        slope_scale: -slope,
        clamp: -clamp,
    }
}

/// Steps of `Depth16Unorm` over 0–1 (a view's depth range).
pub const UNORM16_STEPS: f32 = 65_535.0;

/// Half a step of `Depth16Unorm`.
pub const UNORM16_HALF_STEP: f32 = 0.5 / UNORM16_STEPS;

/// The shift applied to a caster's clip position when it is drawn into `format`. A
/// `Depth16Unorm` layer rounds each depth to one of its 65 536 steps, by up to half a step
/// towards the light where it rounds to the nearest: its casters are drawn
/// [`UNORM16_HALF_STEP`] further from the light (reverse-Z: smaller depth, in normalised
/// depth whatever the projection), so a stored depth lies 0–1 step behind the caster's and a
/// lit surface never shadows itself through rounding, on every implementation alike.
/// Float formats keep their depth (the identity).
pub fn caster_clip_from_clip(format: wgpu::TextureFormat) -> Mat4 {
    match format {
        wgpu::TextureFormat::Depth16Unorm => Mat4::from_translation(Vec3::new(0.0, 0.0, -UNORM16_HALF_STEP)),
        _ => Mat4::IDENTITY,
    }
}

fn create_pipeline(
    device: &wgpu::Device,
    layouts: &Layouts,
    shader: &wgpu::ShaderModule,
    key: CasterKey,
) -> wgpu::RenderPipeline {
    let views = if key.views > 0 {
        &layouts.caster_views
    } else {
        &layouts.caster_view
    };
    let layout = if key.masked {
        device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow masked"),
            bind_group_layouts: &[Some(views), Some(&layouts.instances), Some(&layouts.material)],
            immediate_size: 0,
        })
    } else {
        device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow opaque"),
            bind_group_layouts: &[Some(views), Some(&layouts.instances)],
            immediate_size: 0,
        })
    };
    let depth_stencil = wgpu::DepthStencilState {
        format: key.format,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Greater),
        stencil: wgpu::StencilState::default(),
        bias: caster_bias(f32::from_bits(key.slope_bias), f32::from_bits(key.bias_clamp)),
    };
    let primitive = wgpu::PrimitiveState {
        // Two-sided: single-sided casters (planes, cards) must cast from both sides.
        cull_mode: None,
        unclipped_depth: key.unclipped,
        ..Default::default()
    };
    let fragment = key.masked.then(|| wgpu::FragmentState {
        module: shader,
        entry_point: Some("fs_masked"),
        compilation_options: Default::default(),
        targets: &[],
    });
    let label = if key.masked {
        "shadow masked (alpha test)"
    } else {
        "shadow opaque (depth only)"
    };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(&layout),
        vertex: mesh_vertex_state(shader),
        primitive,
        depth_stencil: Some(depth_stencil),
        multisample: wgpu::MultisampleState::default(),
        fragment,
        multiview_mask: std::num::NonZeroU32::new((1 << key.views) - 1),
        cache: None,
    })
}
