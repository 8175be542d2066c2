//! What one frame is rendered from: the ECS data ([`FrameInputs`]) and what a render-graph
//! node sees while recording ([`FrameContext`]).

use bevy_ecs::entity::Entity;

use crate::ecs::draw_groups::ViewDrawGroups;
use crate::ecs::light_views::FrameLights;
use crate::ecs::view_list::ShadowViews;
use crate::render::context::GpuContext;
use crate::render::counters::RenderCounters;
use crate::render::draw_args::DrawArgs;
use crate::render::fragment_count::FragmentCounter;
pub use crate::render::frame_inputs::FrameInputs;
use crate::render::layouts::Layouts;
use crate::render::occlusion::OcclusionGpu;
use crate::render::scene_gpu::SceneGpu;
use crate::render::seen_readback::SeenReadback;
use crate::render::shadow_cull::ShadowCullGpu;
use crate::render::shadows::ShadowResources;
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
    /// Shadow storage, light and view buffers, and the shadow bind group (the storages are
    /// imported into the graph).
    pub shadows: &'a ShadowResources,
    /// The shadow views and their culled casters.
    pub shadow_views: &'a ShadowViews,
    /// Culled instances of the camera.
    pub view_groups: &'a ViewDrawGroups,
    /// The lights of the frame.
    pub lights: &'a FrameLights,
    /// Timestamp queries.
    pub timer: &'a mut GpuTimer,
    /// Counts the lighting pass's fragment invocations, when asked for.
    pub fragments: Option<&'a FragmentCounter>,
    /// The frame's multi-draw arguments.
    pub draw_args: &'a mut DrawArgs,
    /// The camera view's occlusion culling (prepared for this frame).
    pub occlusion: &'a mut OcclusionGpu,
    /// The GPU culling of shadow casters (prepared for this frame).
    pub shadow_cull: &'a mut ShadowCullGpu,
    /// Draw commands recorded so far this frame (a multi-draw counts once).
    pub draw_calls: u32,
    /// The prepass's pixels of untextured materials were lit in one pass this frame
    /// ([`crate::render::deferred`]).
    pub deferred_lighting: bool,
    /// Shadow views drawn so far this frame (views whose layer already held them are not).
    pub shadow_views_drawn: u32,
    /// Draw calls of shadow views so far this frame (also counted in `draw_calls`).
    pub shadow_draw_calls: u32,
    /// Shadow-map texels cleared so far this frame.
    pub shadow_cleared_texels: u64,
    /// Clipmap levels moved by whole texels and drawn only where needed so far this frame.
    pub shadow_views_scrolled: u32,
    /// Shadow-map texels drawn so far this frame (a whole view's, or its regions').
    pub shadow_drawn_texels: u64,
    /// GPU objects created so far.
    pub counters: &'a mut RenderCounters,
    /// The last pipeline build that failed (the previous pipeline was kept).
    pub pipeline_error: &'a mut Option<String>,
    /// The depth-bounds reduction's readback ring.
    pub seen: &'a mut SeenReadback,
    /// Scrolling views drawn whole from a draw group of an earlier window this frame
    /// (light entity, level): culling is asked for them again.
    pub scroll_resync: &'a mut Vec<(Entity, u32)>,
}
