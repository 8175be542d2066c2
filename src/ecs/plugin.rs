//! [`ShadowPlugin`]: registers the shadow resources and the per-frame systems, in a fixed
//! order: transform propagation → pose skinned meshes, sync instances, gather the skinning jobs → find the camera, collect the lights and
//! their shadow views → cull casters per shadow view and cull the camera view. Rendering is added by
//! [`RenderPlugin`](crate::render::RenderPlugin).

use bevy_app::{App, Plugin, PostStartup, PostUpdate};
use bevy_ecs::schedule::{IntoScheduleConfigs, SystemSet};
use bevy_transform::systems::propagate_parent_transforms;
use bevy_transform::{StaticTransformOptimizations, TransformPlugin, TransformSystems};

use crate::ecs::assets::{Images, Materials, Meshes};
use crate::ecs::caster_changes::CasterChanges;
use crate::ecs::clipmap_scroll::ScrollResync;
use crate::ecs::components::{AmbientLight, ViewportSize};
use crate::ecs::culling::cull_view;
use crate::ecs::draw_groups::ViewDrawGroups;
use crate::ecs::frame_lights::update_frame_lights;
use crate::ecs::instance_changes::InstanceSync;
use crate::ecs::instance_sync::sync_instances;
use crate::ecs::instances::RenderInstances;
use crate::ecs::light_views::FrameLights;
use crate::ecs::mobility::{StaticChanges, sync_moving_transforms};
use crate::ecs::origin::{RenderOrigin, update_render_origin};
use crate::ecs::receiver_culling::ShadowCulling;
use crate::ecs::shadow_lods::ShadowLods;
use crate::ecs::shadow_memory::{ShadowMemory, ShadowMemoryBudget};
use crate::ecs::shadow_views::update_shadow_views;
use crate::ecs::skinning::{AnimationClock, SkinSources, SkinningFrame, animate_skins, collect_skinning};
use crate::ecs::stats::{
    FrameClock, ShadowDiagnostics, ShadowStats, log_diagnostics, start_frame_clock, stop_frame_clock,
};
use crate::ecs::view::{ActiveView, SeenByCamera, update_active_view};
use crate::ecs::view_list::{ShadowLightBudget, ShadowViews};
use crate::ecs::view_lod::CameraLod;

/// The stages of the shadow systems, run in this order in `PostUpdate`, after
/// [`TransformSystems::Propagate`] (so every system reads this frame's `GlobalTransform`).
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShadowSystems {
    /// Pose skinned meshes, mirror mesh entities into [`RenderInstances`], gather the
    /// skinning jobs.
    SyncInstances,
    /// Find the camera; collect the lights, choose the shadowed ones under the budget and
    /// compute their views (cascades, spot views).
    ComputeCascades,
    /// Cull casters per shadow view, and instances for the camera.
    Cull,
}

/// Adds lights and their shadows to an app: components are in [`crate::ecs`], settings in
/// [`ShadowSettings`](crate::settings::ShadowSettings). Unless the app already has
/// `bevy_transform`'s [`TransformPlugin`], propagates transforms itself in
/// [`TransformSystems::Propagate`]: hierarchies with `bevy_transform`'s own system, flat
/// entities with [`sync_moving_transforms`], which skips [`Static`](crate::ecs::Static)
/// entities, so a still frame of static casters touches none of them.
#[derive(Default)]
pub struct ShadowPlugin;

impl Plugin for ShadowPlugin {
    fn build(&self, app: &mut App) {
        if !app.is_plugin_added::<TransformPlugin>() {
            // NOTE: `TransformPlugin`'s flat-entity system scans every entity with a
            // `Transform` each frame, static or not, and its static-scene optimisation
            // (`StaticTransformOptimizations`) adds a second scan for flat entities: a still
            // frame of 100k unmarked casters took 443 µs with it and 334 µs without, of 100k
            // `Static` ones 10 µs under this propagation (`cargo bench --bench cascades --
            // still_frame`). The marker filters static archetypes out without looking at
            // their entities. An app that adds `TransformPlugin` itself keeps Bevy's.
            app.insert_resource(StaticTransformOptimizations::Disabled);
            let propagate = || {
                (propagate_parent_transforms, sync_moving_transforms)
                    .chain()
                    .in_set(TransformSystems::Propagate)
            };
            app.add_systems(PostStartup, propagate());
            app.add_systems(PostUpdate, propagate());
        }
        app.init_resource::<Meshes>()
            .init_resource::<Materials>()
            .init_resource::<Images>()
            .init_resource::<AmbientLight>()
            .init_resource::<ViewportSize>()
            .init_resource::<RenderInstances>()
            .init_resource::<CasterChanges>()
            .init_resource::<StaticChanges>()
            .init_resource::<FrameClock>()
            .init_resource::<InstanceSync>()
            .init_resource::<ScrollResync>()
            .init_resource::<RenderOrigin>()
            .init_resource::<ActiveView>()
            .init_resource::<SeenByCamera>()
            .init_resource::<FrameLights>()
            .init_resource::<ShadowViews>()
            .init_resource::<ViewDrawGroups>()
            .init_resource::<ShadowStats>()
            .init_resource::<ShadowDiagnostics>()
            .init_resource::<ShadowLightBudget>()
            .init_resource::<ShadowMemoryBudget>()
            .init_resource::<ShadowMemory>()
            .init_resource::<ShadowCulling>()
            .init_resource::<ShadowLods>()
            .init_resource::<CameraLod>()
            .init_resource::<SkinSources>()
            .init_resource::<SkinningFrame>()
            .init_resource::<AnimationClock>()
            .configure_sets(
                PostUpdate,
                (
                    ShadowSystems::SyncInstances,
                    ShadowSystems::ComputeCascades,
                    ShadowSystems::Cull,
                )
                    .chain()
                    .after(TransformSystems::Propagate),
            )
            .add_systems(
                PostUpdate,
                (update_render_origin, animate_skins, sync_instances, collect_skinning)
                    .chain()
                    .in_set(ShadowSystems::SyncInstances),
            )
            .add_systems(
                PostUpdate,
                (update_active_view, update_frame_lights)
                    .chain()
                    .in_set(ShadowSystems::ComputeCascades),
            )
            .add_systems(
                PostUpdate,
                (cull_view, update_shadow_views).chain().in_set(ShadowSystems::Cull),
            )
            .add_systems(PostUpdate, log_diagnostics.after(ShadowSystems::Cull))
            .add_systems(PostUpdate, start_frame_clock.before(TransformSystems::Propagate))
            .add_systems(PostUpdate, stop_frame_clock.after(ShadowSystems::Cull));
    }
}
