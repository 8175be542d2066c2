//! Components a user puts on entities: transforms, the sun, the camera, meshes, materials and
//! the shadow flags.

use bevy_ecs::component::Component;
use bevy_ecs::resource::Resource;
use glam::{Mat3, Mat4, Quat, Vec3};

use crate::ecs::assets::{MaterialHandle, MeshHandle};

/// Position, orientation and scale of an entity in world space (there is no hierarchy: this
/// is the world transform).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Position.
    pub translation: Vec3,
    /// Orientation.
    pub rotation: Quat,
    /// Scale per local axis.
    pub scale: Vec3,
}

impl Default for Transform {
    fn default() -> Self {
        Self {
            translation: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
        }
    }
}

impl Transform {
    /// A transform at `translation` with no rotation or scale.
    pub fn from_translation(translation: Vec3) -> Self {
        Self {
            translation,
            ..Self::default()
        }
    }

    /// Turns the transform so its local -Z axis points at `target`, with local +Y as close to
    /// `up` as possible. Leaves the rotation unchanged when the direction is degenerate.
    pub fn looking_at(mut self, target: Vec3, up: Vec3) -> Self {
        let forward = (target - self.translation).normalize_or_zero();
        if forward == Vec3::ZERO {
            return self;
        }
        let up = if forward.cross(up).length_squared() < 1e-8 {
            forward.any_orthonormal_vector()
        } else {
            up
        };
        let right = forward.cross(up).normalize();
        let true_up = right.cross(forward);
        self.rotation = Quat::from_mat3(&Mat3::from_cols(right, true_up, -forward));
        self
    }

    /// World from local matrix.
    pub fn world_from_local(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }

    /// The local -Z axis in world space (where a camera looks, where a light shines).
    pub fn forward(&self) -> Vec3 {
        self.rotation * Vec3::NEG_Z
    }

    /// True when every component is finite and no scale axis is zero.
    pub fn is_valid(&self) -> bool {
        self.translation.is_finite()
            && self.rotation.is_finite()
            && self.scale.is_finite()
            && self.scale.abs().min_element() > 0.0
            && self.rotation.length_squared() > 1e-12
    }
}

/// A sun-like light infinitely far away. It shines along its transform's forward (-Z) axis.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
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

/// A perspective camera; it looks along its transform's forward (-Z) axis.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
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

/// The mesh an entity draws.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Mesh3d(pub MeshHandle);

/// The material an entity's mesh is drawn with.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshMaterial3d(pub MaterialHandle);

/// Marks a mesh entity as a shadow caster. Meshes without it cast no shadow.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CastShadows;

/// Opts a mesh entity out of receiving shadows (it is always fully lit by the sun).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NotShadowReceiver;

/// Flat ambient light added to every surface.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct AmbientLight {
    /// Linear RGB colour and intensity.
    pub color: Vec3,
}

impl Default for AmbientLight {
    fn default() -> Self {
        Self {
            color: Vec3::splat(0.15),
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn looking_at_points_forward_at_the_target() {
        let t = Transform::from_translation(Vec3::new(1.0, 2.0, 3.0)).looking_at(Vec3::new(4.0, 2.0, 3.0), Vec3::Y);
        assert!(t.forward().abs_diff_eq(Vec3::X, 1e-6));
        // Straight down with +Y up still gives a valid rotation.
        let down = Transform::default().looking_at(Vec3::new(0.0, -5.0, 0.0), Vec3::Y);
        assert!(down.forward().abs_diff_eq(Vec3::NEG_Y, 1e-6));
        assert!(down.rotation.is_normalized());
    }

    #[test]
    fn invalid_transforms_are_detected() {
        assert!(Transform::default().is_valid());
        assert!(
            !Transform {
                scale: Vec3::new(1.0, 0.0, 1.0),
                ..Default::default()
            }
            .is_valid()
        );
        assert!(!Transform::from_translation(Vec3::new(f32::NAN, 0.0, 0.0)).is_valid());
        assert!(
            !Transform {
                scale: Vec3::splat(f32::INFINITY),
                ..Default::default()
            }
            .is_valid()
        );
    }
}
