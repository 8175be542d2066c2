//! Shadow views of spot lights: each frame, the spot lights that ask for shadows are ranked
//! under the [`ShadowLightBudget`] (largest on screen first), each one kept gets a perspective
//! reverse-Z view (`math::spot`) relative to the [`RenderOrigin`], and its casters are culled
//! into a draw group of [`LightShadowViews`]. Lights over budget are named in
//! [`ShadowDiagnostics`]. The sun's cascades stay in [`ActiveView`] and
//! [`ShadowDrawGroups`](crate::ecs::ShadowDrawGroups) for now.

use bevy_ecs::entity::Entity;
use bevy_ecs::resource::Resource;
use bevy_ecs::system::{Local, Query, Res, ResMut};
use bevy_transform::components::GlobalTransform;

use crate::ecs::draw_groups::{DrawGroup, push_instance};
use crate::ecs::instances::RenderInstances;
use crate::ecs::lights::SpotLight;
use crate::ecs::origin::RenderOrigin;
use crate::ecs::placement::world_pose;
use crate::ecs::stats::ShadowDiagnostics;
use crate::ecs::view::ActiveView;
use crate::math::chunks::cull_spheres_frustum_chunked;
use crate::math::light_budget::{
    BudgetChoice, LightCandidate, LightKind, RankScratch, RankingView, ShadowBudget, choose_shadowed_lights_into,
};
use crate::math::spot::{SpotInput, SpotView, spot_view};

/// How many lights of each kind may cast shadows, and the shadow-map size of a spot light.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowLightBudget {
    /// Most shadowed lights per kind (the seed's layout: 8 spot lights, 4 point lights).
    pub lights: ShadowBudget,
    /// Side of a spot light's shadow map, texels.
    pub spot_resolution: u32,
}

impl Default for ShadowLightBudget {
    fn default() -> Self {
        Self {
            lights: ShadowBudget {
                directional: 1,
                spot: 8,
                point: 4,
            },
            spot_resolution: 1024,
        }
    }
}

/// Near plane of a spot light's shadow view, metres: casters closer to the light are clamped
/// to it (depth clamping) or clipped.
pub const SPOT_NEAR: f32 = 0.05;

/// One spot light's shadow view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotShadowView {
    /// The light.
    pub light: Entity,
    /// Its view, relative to the render origin.
    pub view: SpotView,
    /// The light's emitter radius, metres (soft-shadow size).
    pub radius: f32,
}

/// The shadow views of this frame's spot lights and their culled casters: `groups[i]` holds
/// the draws of `views[i]`, indexing `indices`.
#[derive(Resource, Debug, Default)]
pub struct LightShadowViews {
    /// One view per shadowed spot light, largest on screen first.
    pub views: Vec<SpotShadowView>,
    /// The casters of each view, as instanced draws.
    pub groups: Vec<DrawGroup>,
    /// Instance indices of every group, concatenated.
    pub indices: Vec<u32>,
}

/// Reused buffers of [`update_spot_shadow_views`].
#[derive(Default)]
pub struct SpotScratch {
    candidates: Vec<LightCandidate>,
    lights: Vec<(Entity, SpotLight, SpotInput)>,
    visible: Vec<u32>,
    chunk_scratch: Vec<u32>,
    rank: RankScratch,
    choice: BudgetChoice,
}

/// Ranks the spot lights under the budget, builds the views of those kept and culls their
/// casters.
#[allow(clippy::too_many_arguments)]
pub fn update_spot_shadow_views(
    spots: Query<(Entity, &SpotLight, &GlobalTransform)>,
    view: Res<ActiveView>,
    origin: Res<RenderOrigin>,
    budget: Res<ShadowLightBudget>,
    instances: Res<RenderInstances>,
    mut out: ResMut<LightShadowViews>,
    mut diagnostics: ResMut<ShadowDiagnostics>,
    mut scratch: Local<SpotScratch>,
) {
    let out = &mut *out;
    out.views.clear();
    out.indices.clear();
    let scratch = &mut *scratch;
    scratch.candidates.clear();
    scratch.lights.clear();
    for (entity, light, transform) in &spots {
        if !light.shadows_enabled {
            continue;
        }
        let Some((rotation, position)) = world_pose(transform) else {
            continue;
        };
        let input = SpotInput {
            position: position - origin.0,
            direction: rotation * glam::Vec3::NEG_Z,
            outer_angle: light.outer_angle,
            range: light.range,
            near: SPOT_NEAR,
            resolution: budget.spot_resolution,
        };
        scratch.candidates.push(LightCandidate {
            id: scratch.lights.len(),
            kind: LightKind::Spot,
            bounds: Some((input.position, light.range)),
        });
        scratch.lights.push((entity, *light, input));
    }
    let ranking = match &view.camera {
        Some((camera, _)) => RankingView {
            position: camera.position(),
            tan_half_fov_y: (camera.fov_y * 0.5).tan(),
        },
        None => RankingView {
            position: glam::Vec3::ZERO,
            tan_half_fov_y: 1.0,
        },
    };
    choose_shadowed_lights_into(
        &scratch.candidates,
        &budget.lights,
        &ranking,
        &mut scratch.rank,
        &mut scratch.choice,
    );
    let choice = &scratch.choice;
    for (_, id) in &choice.dropped {
        let (entity, ..) = scratch.lights[*id];
        diagnostics.warn(format!(
            "spot light {entity} gets no shadow: only {} shadowed spot lights fit the budget, and it is smaller on screen",
            budget.lights.spot
        ));
    }
    if out.groups.len() < choice.shadowed.len() {
        out.groups.resize_with(choice.shadowed.len(), DrawGroup::default);
    }
    out.groups.iter_mut().for_each(DrawGroup::clear);
    for &id in &choice.shadowed {
        let (entity, light, input) = scratch.lights[id];
        let Some(view) = spot_view(&input) else {
            diagnostics.warn(format!(
                "spot light {entity} has range {}, outer angle {} rad: no shadow view can be made",
                light.range, light.outer_angle
            ));
            continue;
        };
        let group = &mut out.groups[out.views.len()];
        cull_spheres_frustum_chunked(
            &view.frustum,
            &instances.caster_centers,
            &instances.caster_radii,
            &instances.caster_chunks,
            &mut scratch.visible,
            &mut scratch.chunk_scratch,
        );
        for &k in &scratch.visible {
            let instance = instances.casters[k as usize];
            push_instance(group, &mut out.indices, instances.keys[instance as usize], instance);
        }
        out.views.push(SpotShadowView {
            light: entity,
            view,
            radius: light.radius,
        });
    }
    out.groups.truncate(out.views.len());
}
