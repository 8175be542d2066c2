//! Components a user puts on entities: the sun, the camera, meshes, materials and the shadow
//! flags. Placement is `bevy_transform`'s [`Transform`] (local, with parent/child hierarchy)
//! and [`GlobalTransform`] (world, written by transform propagation); every component that is
//! placed in the world requires a [`Transform`], so an entity spawned without one gets the
//! identity instead of being silently ignored.
//!
//! [`GlobalTransform`]: bevy_transform::components::GlobalTransform

use bevy_ecs::component::Component;
use bevy_ecs::resource::Resource;
use bevy_transform::components::Transform;
use glam::Vec3;

use crate::ecs::assets::{MaterialHandle, MeshHandle};

/// A sun-like light infinitely far away. It shines along its [`GlobalTransform`]'s forward
/// (-Z) axis.
///
/// [`GlobalTransform`]: bevy_transform::components::GlobalTransform
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[require(Transform)]
pub struct DirectionalLight {
    /// Linear RGB colour.
    pub color: Vec3,
    /// Intensity multiplier: 1 lights a white surface facing the sun to white.
    pub illuminance: f32,
    /// Apparent diameter of the light's disc, in radians (the sun is about 0.0093, 0.53°).
    /// Sets the PCSS penumbra width.
    pub angular_diameter: f32,
    /// Whether this light casts shadows.
    pub shadows_enabled: bool,
}

impl Default for DirectionalLight {
    fn default() -> Self {
        Self {
            color: Vec3::ONE,
            illuminance: 1.0,
            angular_diameter: 0.53_f32.to_radians(),
            shadows_enabled: true,
        }
    }
}

/// A perspective camera; it looks along its [`GlobalTransform`]'s forward (-Z) axis (its
/// scale is ignored).
///
/// [`GlobalTransform`]: bevy_transform::components::GlobalTransform
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[require(Transform)]
pub struct Camera3d {
    /// Vertical field of view in radians.
    pub fov_y: f32,
    /// Near clip distance (metres).
    pub near: f32,
    /// Far clip distance (metres).
    pub far: f32,
    /// Linear exposure multiplier applied before tone mapping.
    pub exposure: f32,
}

impl Default for Camera3d {
    fn default() -> Self {
        Self {
            fov_y: 60_f32.to_radians(),
            near: 0.1,
            far: 1000.0,
            exposure: 1.0,
        }
    }
}

/// The mesh an entity draws, placed by its [`GlobalTransform`]. Mesh entities cast shadows
/// unless they have [`NotShadowCaster`].
///
/// [`GlobalTransform`]: bevy_transform::components::GlobalTransform
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[require(Transform)]
pub struct Mesh3d(pub MeshHandle);

/// The material an entity's mesh is drawn with.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshMaterial3d(pub MaterialHandle);

/// Opts a mesh entity out of casting shadows (it is not drawn into the shadow maps). Meshes
/// without it cast, as in Bevy.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NotShadowCaster;

/// Opts a mesh entity out of receiving shadows (it is always fully lit by the sun).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NotShadowReceiver;

/// Flat ambient light added to every surface. Default black, as a scene file's `ambient`.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct AmbientLight {
    /// Linear RGB colour and intensity.
    pub color: Vec3,
}

/// Size in pixels of the image the camera renders to; sets the aspect ratio used for the
/// cascades. The render plugin keeps it in sync with its target.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ViewportSize {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl Default for ViewportSize {
    fn default() -> Self {
        Self {
            width: 1280,
            height: 720,
        }
    }
}

impl ViewportSize {
    /// Width over height, never zero or NaN.
    pub fn aspect(&self) -> f32 {
        self.width.max(1) as f32 / self.height.max(1) as f32
    }
}
