//! Positional lights: [`SpotLight`] and [`PointLight`] (the sun is
//! [`DirectionalLight`](crate::ecs::DirectionalLight)). Position and direction come from the
//! entity's transform. Both light and cast shadows (a spot light a perspective view, a point
//! light a cube of six faces), with the entity's
//! [`ShadowSettings`](crate::settings::ShadowSettings) if it has them.

use bevy_ecs::component::Component;
use bevy_transform::components::Transform;
use glam::Vec3;

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
