//! What one frame is rendered from: the ECS data ([`FrameInputs`]) and what a render-graph
//! node sees while recording ([`FrameContext`]).

use bevy_ecs::world::World;
use glam::Vec3;

use crate::ecs::assets::{Images, Materials, Meshes};
use crate::ecs::components::AmbientLight;
use crate::ecs::draw_groups::ViewDrawGroups;
use crate::ecs::frame_lights::FrameLights;
use crate::ecs::instances::RenderInstances;
use crate::ecs::origin::RenderOrigin;
use crate::ecs::shadow_views::ShadowViews;
use crate::ecs::view::ActiveView;
use crate::render::context::GpuContext;
use crate::render::counters::RenderCounters;
use crate::render::depth_bounds::SeenReadback;
use crate::render::fragment_count::FragmentCounter;
use crate::render::layouts::Layouts;
use crate::render::options::RenderOptions;
use crate::render::scene_gpu::SceneGpu;
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
    /// Draw calls recorded so far this frame.
    pub draw_calls: u32,
    /// Shadow views drawn so far this frame (views whose layer already held them are not).
    pub shadow_views_drawn: u32,
    /// Draw calls of shadow views so far this frame (also counted in `draw_calls`).
    pub shadow_draw_calls: u32,
    /// Shadow-map texels cleared so far this frame.
    pub shadow_cleared_texels: u64,
    /// GPU objects created so far.
    pub counters: &'a mut RenderCounters,
    /// The last pipeline build that failed (the previous pipeline was kept).
    pub pipeline_error: &'a mut Option<String>,
    /// The depth-bounds reduction's readback ring.
    pub seen: &'a mut SeenReadback,
}

/// The ECS data one frame is rendered from.
pub struct FrameInputs<'a> {
    /// Mesh store.
    pub meshes: &'a Meshes,
    /// Material store.
    pub materials: &'a Materials,
    /// Image store.
    pub images: &'a Images,
    /// Sorted instances.
    pub instances: &'a RenderInstances,
    /// Shadow views and their culled casters.
    pub shadow_views: &'a ShadowViews,
    /// Culled view instances.
    pub view_groups: &'a ViewDrawGroups,
    /// The camera.
    pub view: &'a ActiveView,
    /// The lights.
    pub lights: &'a FrameLights,
    /// Ambient light.
    pub ambient: &'a AmbientLight,
    /// Frame counter.
    pub frame_index: u32,
    /// Render-wide switches (the world's [`RenderOptions`], or the defaults).
    pub options: RenderOptions,
    /// The render origin every GPU position is relative to ([`RenderOrigin`]).
    pub origin: Vec3,
}

impl<'a> FrameInputs<'a> {
    /// Borrows the inputs from a world that runs [`ShadowPlugin`](crate::ecs::ShadowPlugin).
    pub fn from_world(world: &'a World, frame_index: u32) -> Self {
        Self {
            meshes: world.resource::<Meshes>(),
            materials: world.resource::<Materials>(),
            images: world.resource::<Images>(),
            instances: world.resource::<RenderInstances>(),
            shadow_views: world.resource::<ShadowViews>(),
            view_groups: world.resource::<ViewDrawGroups>(),
            view: world.resource::<ActiveView>(),
            lights: world.resource::<FrameLights>(),
            ambient: world.resource::<AmbientLight>(),
            frame_index,
            options: world.get_resource::<RenderOptions>().copied().unwrap_or_default(),
            origin: world.get_resource::<RenderOrigin>().map_or(Vec3::ZERO, |o| o.0),
        }
    }
}
