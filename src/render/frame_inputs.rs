//! The ECS data one frame is rendered from ([`FrameInputs`]), borrowed from the world.

use bevy_ecs::world::World;
use glam::Vec3;

use crate::ecs::assets::{Images, Materials, Meshes};
use crate::ecs::components::AmbientLight;
use crate::ecs::draw_groups::{DrawGroup, ViewDrawGroups};
use crate::ecs::instances::RenderInstances;
use crate::ecs::light_views::FrameLights;
use crate::ecs::origin::RenderOrigin;
use crate::ecs::skinning::{SkinSources, SkinningFrame};
use crate::ecs::view::ActiveView;
use crate::ecs::view_list::ShadowViews;
use crate::render::options::RenderOptions;
use crate::render::shadows::page_pool::PAGE_PASSES;

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
    /// Bind poses of the skinned meshes (none in a world without [`SkinSources`]).
    pub skin_sources: Option<&'a SkinSources>,
    /// This frame's skinning jobs.
    pub skinning: Option<&'a SkinningFrame>,
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
            skin_sources: world.get_resource::<SkinSources>(),
            skinning: world.get_resource::<SkinningFrame>(),
        }
    }

    /// About how many draws the frame records: the camera's batches twice (prepass and
    /// lighting pass) and every shadow group's once (what [`DrawArgs`](crate::render::draw_args::DrawArgs) reserves room for).
    pub fn expected_draws(&self) -> usize {
        let views = self.shadow_views;
        let shadow: usize = (views.groups.iter())
            .chain(views.single_pass.iter().map(|p| &p.group))
            .chain(views.regions.iter().map(|r| &r.group))
            .map(DrawGroup::draw_count)
            .sum();
        2 * self.view_groups.group.draw_count() + shadow
    }

    /// The most passes a frame of these inputs can time: one per shadow view and one more per
    /// scrolling view (its move, then its regions), one per VSM light's moments and per
    /// cascade's moments, the page passes, the prepass, the resolve and the lighting pass.
    pub fn timed_passes(&self) -> usize {
        let (views, lights) = (&self.shadow_views.views, self.lights);
        let scrolling = views.iter().filter(|v| v.scroll.is_some()).count();
        let cascades: usize = lights.suns.iter().map(|s| s.cascades.count).sum();
        let pages = if lights.paged_sun().is_some() {
            PAGE_PASSES.len()
        } else {
            0
        };
        // NOTE: the skinning, the prepass (twice), the occlusion culling's three passes, the
        // shadow casters' culling, the resolve, the forward pass and the depth-bounds
        // reduction.
        views.len() + scrolling + lights.spots.len() + lights.points.len() + cascades + pages + 10
    }
}
