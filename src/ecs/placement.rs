//! Reading where an entity is from its [`GlobalTransform`] without trusting it: code (physics,
//! animation, a user's system) can write NaN, infinite or zero-scale transforms, and one such
//! entity must be skipped with a warning, never poison a frame. `bevy_transform`'s own axis
//! helpers (`forward()`, `rotation()`) assume a valid, normalized transform (they panic on a
//! degenerate one in debug builds), so the systems here go through these functions instead.

use bevy_transform::components::GlobalTransform;
use glam::{Quat, Vec3};

/// True when the world transform is finite and invertible (no scale axis is zero). A zero
/// quaternion is not caught here: `bevy_transform` turns it into the identity rotation.
pub fn is_valid_placement(transform: &GlobalTransform) -> bool {
    let affine = transform.affine();
    let m = affine.matrix3;
    let finite = m.x_axis.is_finite() && m.y_axis.is_finite() && m.z_axis.is_finite() && affine.translation.is_finite();
    // NOTE: the determinant is zero when any axis is (a zero scale anywhere in the hierarchy).
    finite && m.determinant() != 0.0
}

/// The unit world direction of the local -Z axis (where a light shines, where a camera looks),
/// or `None` when the transform is not a valid placement.
pub fn world_forward(transform: &GlobalTransform) -> Option<Vec3> {
    if !is_valid_placement(transform) {
        return None;
    }
    let forward = Vec3::from(-transform.affine().matrix3.z_axis).normalize_or_zero();
    (forward.is_finite() && forward != Vec3::ZERO).then_some(forward)
}

/// World position and rotation with the scale removed (a camera's pose), or `None` when the
/// transform is not a valid placement.
pub fn world_pose(transform: &GlobalTransform) -> Option<(Quat, Vec3)> {
    if !is_valid_placement(transform) {
        return None;
    }
    let (_, rotation, translation) = transform.to_scale_rotation_translation();
    let rotation = rotation.normalize();
    rotation.is_finite().then_some((rotation, translation))
}

#[cfg(test)]
mod tests {
    use bevy_transform::components::Transform;

    use super::*;

    fn global(t: Transform) -> GlobalTransform {
        GlobalTransform::from(t)
    }

    #[test]
    fn invalid_placements_are_detected() {
        assert!(is_valid_placement(&GlobalTransform::IDENTITY));
        let zero_axis = Transform::from_scale(Vec3::new(1.0, 0.0, 1.0));
        assert!(!is_valid_placement(&global(zero_axis)));
        let nan = Transform::from_translation(Vec3::new(f32::NAN, 0.0, 0.0));
        assert!(!is_valid_placement(&global(nan)));
        let infinite = Transform::from_scale(Vec3::splat(f32::INFINITY));
        assert!(!is_valid_placement(&global(infinite)));
        // NOTE: `bevy_transform` turns a zero quaternion into the identity rotation (glam's
        // `Mat3::from_quat` assumes a unit quaternion), so the world transform is finite and
        // the entity is placed, unrotated, rather than skipped.
        let zero_rotation = global(Transform::from_rotation(Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)));
        assert_eq!(zero_rotation, GlobalTransform::IDENTITY);
        assert!(is_valid_placement(&zero_rotation));
        assert_eq!(world_forward(&global(nan)), None);
        assert_eq!(world_pose(&global(zero_axis)), None);
    }

    #[test]
    fn forward_and_pose_ignore_scale() {
        let t = Transform::from_xyz(1.0, 2.0, 3.0)
            .looking_at(Vec3::new(4.0, 2.0, 3.0), Vec3::Y)
            .with_scale(Vec3::new(2.0, 0.5, 3.0));
        let g = global(t);
        assert!(world_forward(&g).unwrap().abs_diff_eq(Vec3::X, 1e-6));
        let (rotation, translation) = world_pose(&g).unwrap();
        assert!(rotation.abs_diff_eq(t.rotation, 1e-6) || rotation.abs_diff_eq(-t.rotation, 1e-6));
        assert_eq!(translation, Vec3::new(1.0, 2.0, 3.0));
        // Straight down with +Y up still gives a valid, normalized rotation.
        let down = global(Transform::default().looking_at(Vec3::new(0.0, -5.0, 0.0), Vec3::Y));
        assert!(world_forward(&down).unwrap().abs_diff_eq(Vec3::NEG_Y, 1e-6));
        assert!(world_pose(&down).unwrap().0.is_normalized());
    }
}
