//! Positional lights — [`SpotLight`] and [`PointLight`] — and the report of the lights the
//! renderer does not draw yet. (The sun is [`DirectionalLight`].)
//!
//! These components carry everything their shadows will need (position and direction from
//! the transform, cone angles, range, emitter radius); rendering them comes with the light /
//! shadow-view model. Until then [`report_unrendered_lights`] says every frame, in
//! [`ShadowDiagnostics`], which lights are not drawn: no light is dropped silently.

use bevy_ecs::component::Component;
use bevy_ecs::query::With;
use bevy_ecs::system::{Query, ResMut};
use bevy_transform::components::Transform;
use glam::Vec3;

use crate::ecs::components::DirectionalLight;
use crate::ecs::stats::ShadowDiagnostics;

/// A cone of light from its [`GlobalTransform`]'s position along its forward (−Z) axis.
///
/// [`GlobalTransform`]: bevy_transform::components::GlobalTransform
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[require(Transform)]
pub struct SpotLight {
    /// Linear RGB colour.
    pub color: Vec3,
    /// Intensity multiplier: 1 lights a white surface facing the light at 1 m to white.
    pub intensity: f32,
    /// Distance past which the light has no effect (and casts no shadow), metres.
    pub range: f32,
    /// Half-angle of the fully lit inner cone, radians; at most `outer_angle`.
    pub inner_angle: f32,
    /// Half-angle of the outer cone, where the light fades to nothing, radians.
    pub outer_angle: f32,
    /// Radius of the emitter, metres: sets the width of soft (PCSS) penumbrae; 0 is a point.
    pub radius: f32,
    /// Whether this light casts shadows.
    pub shadows_enabled: bool,
}

impl Default for SpotLight {
    fn default() -> Self {
        Self {
            color: Vec3::ONE,
            intensity: 1.0,
            range: 20.0,
            inner_angle: 0.0,
            outer_angle: std::f32::consts::FRAC_PI_4,
            radius: 0.0,
            shadows_enabled: true,
        }
    }
}

/// Light in every direction from its [`GlobalTransform`]'s position.
///
/// [`GlobalTransform`]: bevy_transform::components::GlobalTransform
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[require(Transform)]
pub struct PointLight {
    /// Linear RGB colour.
    pub color: Vec3,
    /// Intensity multiplier: 1 lights a white surface facing the light at 1 m to white.
    pub intensity: f32,
    /// Distance past which the light has no effect (and casts no shadow), metres.
    pub range: f32,
    /// Radius of the emitter, metres: sets the width of soft (PCSS) penumbrae; 0 is a point.
    pub radius: f32,
    /// Whether this light casts shadows.
    pub shadows_enabled: bool,
}

impl Default for PointLight {
    fn default() -> Self {
        Self {
            color: Vec3::ONE,
            intensity: 1.0,
            range: 20.0,
            radius: 0.0,
            shadows_enabled: true,
        }
    }
}

/// Warns, every frame, about lights the renderer does not draw yet: directional lights after
/// the first, and every spot and point light.
pub fn report_unrendered_lights(
    suns: Query<(), With<DirectionalLight>>,
    spots: Query<(), With<SpotLight>>,
    points: Query<(), With<PointLight>>,
    mut diagnostics: ResMut<ShadowDiagnostics>,
) {
    let extra_suns = suns.iter().count().saturating_sub(1);
    if extra_suns > 0 {
        diagnostics.warn(format!(
            "{extra_suns} directional light(s) after the first are not drawn yet: only the first lights the scene and casts shadows"
        ));
    }
    let (spots, points) = (spots.iter().count(), points.iter().count());
    if spots + points > 0 {
        diagnostics.warn(format!(
            "{spots} spot light(s) and {points} point light(s) are not drawn yet: positional lights have no renderer"
        ));
    }
}
