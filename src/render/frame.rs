//! What a render-graph node sees while recording one frame.

use crate::ecs::draw_groups::{ShadowDrawGroups, ViewDrawGroups};
use crate::ecs::view::SunView;
use crate::render::context::GpuContext;
use crate::render::layouts::Layouts;
use crate::render::scene_gpu::SceneGpu;
use crate::render::shadow_map::ShadowMap;
use crate::render::target::TargetViews;
use crate::render::timer::GpuTimer;
use crate::shader::ShaderLibrary;

/// Shared state for the nodes of one frame.
pub struct FrameContext<'a> {
    /// Device and queue.
    pub gpu: &'a GpuContext,
    /// Bind group layouts and samplers.
    pub layouts: &'a Layouts,
    /// Shader composer, for pipelines created on first use.
    pub library: &'a mut ShaderLibrary,
    /// Scene buffers and bind groups, already prepared for this frame.
    pub scene: &'a SceneGpu,
    /// The directional shadow map (imported resource `shadow_map`).
    pub shadow_map: &'a ShadowMap,
    /// Culled casters per cascade.
    pub shadow_groups: &'a ShadowDrawGroups,
    /// Culled instances of the camera.
    pub view_groups: &'a ViewDrawGroups,
    /// The sun, if there is one.
    pub sun: Option<&'a SunView>,
    /// The colour and depth targets the camera renders to.
    pub target: &'a TargetViews,
    /// Timestamp queries.
    pub timer: &'a mut GpuTimer,
    /// Draw calls recorded so far this frame.
    pub draw_calls: u32,
}
