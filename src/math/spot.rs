//! Spot-light shadow views: the perspective reverse-Z view of a light cone, its cull volume,
//! the size of a shadow-map texel at a distance (which scales the normal offset and slope
//! bias of a perspective map), linear distance from stored depth, and the perspective PCSS
//! penumbra estimate of the blog seed, `w = (d_receiver − d_blocker) · w_light / d_blocker`.

use glam::{Mat4, Vec3};

use crate::math::frustum::Frustum;
use crate::math::light_space::{light_from_world, light_rotation};
use crate::math::projection::perspective_reverse_z;

/// Widest cone half-angle a spot shadow view covers (just under 90°: a perspective view
/// cannot cover a hemisphere).
pub const MAX_SPOT_HALF_ANGLE: f32 = 89.0 * std::f32::consts::PI / 180.0;

/// What a spot light's shadow view is fitted to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotInput {
    /// Position of the light, world space.
    pub position: Vec3,
    /// Direction the light shines along (need not be unit length).
    pub direction: Vec3,
    /// Half-angle of the outer cone, radians; clamped to [`MAX_SPOT_HALF_ANGLE`].
    pub outer_angle: f32,
    /// Distance past which the light has no effect (the view's far plane), metres.
    pub range: f32,
    /// Near plane distance, metres: casters closer to the light are clipped (or clamped
    /// where depth clamping is on).
    pub near: f32,
    /// Shadow-map side in texels.
    pub resolution: u32,
}

/// A spot light's shadow view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotView {
    /// Light view space from world: the light at the origin, looking down −Z.
    pub view_from_world: Mat4,
    /// Reverse-Z clip space from world (near plane at depth 1, range at depth 0).
    pub clip_from_world: Mat4,
    /// The cull volume: casters outside it cannot shadow anything the light reaches.
    pub frustum: Frustum,
    /// Near plane distance, metres.
    pub near: f32,
    /// Far plane distance (the range), metres.
    pub far: f32,
    /// World size of one texel per metre of distance along the view axis: a texel at
    /// distance `d` is `d · texel_per_metre` wide.
    pub texel_per_metre: f32,
}

impl SpotView {
    /// World size of a shadow-map texel at `distance` metres along the light's axis.
    pub fn texel_size_at(&self, distance: f32) -> f32 {
        distance.max(0.0) * self.texel_per_metre
    }

    /// Distance along the light's axis of a stored reverse-Z depth (`1` at the near plane,
    /// `0` at the far plane).
    pub fn distance_from_depth(&self, depth: f32) -> f32 {
        linear_distance(depth, self.near, self.far)
    }
}

/// The shadow view of a spot light, or None when the input cannot make one: a zero or
/// non-finite direction or position, an angle that is not positive, `near` not in
/// `(0, range)`, or a resolution of 0.
pub fn spot_view(input: &SpotInput) -> Option<SpotView> {
    let SpotInput {
        position,
        direction,
        outer_angle,
        range,
        near,
        resolution,
    } = *input;
    let valid = position.is_finite()
        && direction.is_finite()
        && direction.length_squared() > 0.0
        && outer_angle.is_finite()
        && outer_angle > 0.0
        && near.is_finite()
        && range.is_finite()
        && near > 0.0
        && near < range
        && resolution > 0;
    if !valid {
        return None;
    }
    let half = outer_angle.min(MAX_SPOT_HALF_ANGLE);
    // NOTE: the square map's inscribed circle is the cone, so the view's field of view is the
    // cone's full angle on both axes.
    let view_from_world = light_from_world(light_rotation(direction), position);
    let clip_from_view = perspective_reverse_z(2.0 * half, 1.0, near, range);
    let clip_from_world = clip_from_view * view_from_world;
    Some(SpotView {
        view_from_world,
        clip_from_world,
        frustum: Frustum::from_clip_from_world(clip_from_world),
        near,
        far: range,
        texel_per_metre: 2.0 * half.tan() / resolution as f32,
    })
}

/// Distance along a perspective view's axis of a reverse-Z depth: the inverse of
/// `depth = a·(far − d) / d` with `a = near / (far − near)`. Depths outside `[0, 1]` are
/// clamped to it.
pub fn linear_distance(depth: f32, near: f32, far: f32) -> f32 {
    let (n, f) = (f64::from(near), f64::from(far));
    let a = n / (f - n);
    let depth = f64::from(depth.clamp(0.0, 1.0));
    (a * f / (depth + a)) as f32
}

/// The width of a perspective penumbra at a receiver: `(d_receiver − d_blocker) · w_light /
/// d_blocker`, distances from the light and `light_size` the emitter's diameter, in metres.
/// Zero where the blocker is not in front of the receiver or any input is not finite or not
/// positive.
pub fn perspective_penumbra(receiver_distance: f32, blocker_distance: f32, light_size: f32) -> f32 {
    let valid = receiver_distance.is_finite() && blocker_distance.is_finite() && light_size.is_finite();
    if !valid || blocker_distance <= 0.0 || light_size <= 0.0 || receiver_distance <= blocker_distance {
        return 0.0;
    }
    (receiver_distance - blocker_distance) * light_size / blocker_distance
}

/// The blocker-search radius of perspective PCSS on the map's near plane, in metres: the
/// light's size projected through the receiver onto the near plane,
/// `light_size · (d_receiver − near) / d_receiver`. Zero for invalid input.
pub fn blocker_search_width(receiver_distance: f32, near: f32, light_size: f32) -> f32 {
    let valid = receiver_distance.is_finite() && near.is_finite() && light_size.is_finite();
    if !valid || receiver_distance <= near || near <= 0.0 || light_size <= 0.0 {
        return 0.0;
    }
    light_size * (receiver_distance - near) / receiver_distance
}

#[cfg(test)]
mod tests {
    use glam::Vec4Swizzles;

    use super::*;

    fn input() -> SpotInput {
        SpotInput {
            position: Vec3::new(1.0, 5.0, -2.0),
            direction: Vec3::new(0.2, -1.0, 0.1),
            outer_angle: 30f32.to_radians(),
            range: 40.0,
            near: 0.05,
            resolution: 1024,
        }
    }

    fn project(view: &SpotView, p: Vec3) -> Vec3 {
        let clip = view.clip_from_world * p.extend(1.0);
        clip.xyz() / clip.w
    }

    #[test]
    fn the_axis_projects_to_the_centre_with_reverse_z() {
        let i = input();
        let view = spot_view(&i).unwrap();
        let axis = i.direction.normalize();
        let mut last = f32::INFINITY;
        for d in [0.05f32, 0.5, 2.0, 10.0, 39.9] {
            let ndc = project(&view, i.position + axis * d);
            assert!(ndc.x.abs() < 1e-4 && ndc.y.abs() < 1e-4, "{d}: {ndc}");
            assert!(ndc.z < last, "depth falls with distance");
            last = ndc.z;
            let back = view.distance_from_depth(ndc.z);
            assert!((back - d).abs() < 1e-3 * d.max(1.0), "{d} → {back}");
        }
        assert!((project(&view, i.position + axis * i.near).z - 1.0).abs() < 1e-5);
        assert!(project(&view, i.position + axis * i.range).z.abs() < 1e-5);
    }

    #[test]
    fn the_cone_is_the_maps_inscribed_circle() {
        let i = input();
        let view = spot_view(&i).unwrap();
        let axis = i.direction.normalize();
        let (side, _) = axis.any_orthonormal_pair();
        for d in [1.0f32, 7.0, 30.0] {
            for turn in 0..8 {
                let around = glam::Quat::from_axis_angle(axis, turn as f32 * 0.785);
                let edge = glam::Quat::from_axis_angle(around * side, i.outer_angle) * axis;
                let ndc = project(&view, i.position + edge * d);
                let r = ndc.truncate().length();
                assert!((r - 1.0).abs() < 1e-3, "distance {d}, turn {turn}: radius {r}");
            }
        }
    }

    #[test]
    fn the_cull_volume_holds_the_cone_and_nothing_behind_or_past_the_range() {
        let i = input();
        let view = spot_view(&i).unwrap();
        let axis = i.direction.normalize();
        assert!(view.frustum.contains_point(i.position + axis * 5.0));
        assert!(
            !view.frustum.contains_point(i.position - axis * 1.0),
            "behind the light"
        );
        assert!(!view.frustum.contains_point(i.position + axis * 41.0), "past the range");
        assert!(view.frustum.intersects_sphere(i.position + axis * 41.0, 2.0));
    }

    #[test]
    fn texels_grow_linearly_with_distance() {
        let view = spot_view(&input()).unwrap();
        let expected = 2.0 * 30f32.to_radians().tan() / 1024.0;
        assert!((view.texel_size_at(1.0) - expected).abs() < 1e-7);
        assert!((view.texel_size_at(10.0) - 10.0 * expected).abs() < 1e-6);
        assert_eq!(view.texel_size_at(-1.0), 0.0);
    }

    #[test]
    fn degenerate_inputs_make_no_view() {
        let bad = [
            SpotInput {
                direction: Vec3::ZERO,
                ..input()
            },
            SpotInput {
                position: Vec3::NAN,
                ..input()
            },
            SpotInput {
                outer_angle: 0.0,
                ..input()
            },
            SpotInput { near: 0.0, ..input() },
            SpotInput { near: 50.0, ..input() },
            SpotInput {
                resolution: 0,
                ..input()
            },
        ];
        for b in bad {
            assert!(spot_view(&b).is_none(), "{b:?}");
        }
        // Straight down and a very wide cone still make a finite view.
        let down = SpotInput {
            direction: Vec3::NEG_Y,
            outer_angle: 3.0,
            ..input()
        };
        let view = spot_view(&down).unwrap();
        assert!(view.clip_from_world.is_finite());
    }

    #[test]
    fn perspective_penumbrae() {
        // Blocker halfway: the penumbra is as wide as the light.
        assert!((perspective_penumbra(10.0, 5.0, 0.2) - 0.2).abs() < 1e-6);
        // It widens with the caster-receiver gap and with the light's size.
        assert!(perspective_penumbra(10.0, 2.0, 0.2) > perspective_penumbra(10.0, 5.0, 0.2));
        assert!(perspective_penumbra(10.0, 5.0, 0.4) > perspective_penumbra(10.0, 5.0, 0.2));
        // Contact and invalid input give none.
        assert_eq!(perspective_penumbra(5.0, 5.0, 0.2), 0.0);
        assert_eq!(perspective_penumbra(4.0, 5.0, 0.2), 0.0);
        assert_eq!(perspective_penumbra(10.0, 0.0, 0.2), 0.0);
        assert_eq!(perspective_penumbra(f32::NAN, 5.0, 0.2), 0.0);
        // The search region on the near plane shrinks to nothing at the near plane.
        assert!((blocker_search_width(10.0, 0.1, 0.2) - 0.2 * 9.9 / 10.0).abs() < 1e-6);
        assert_eq!(blocker_search_width(0.1, 0.1, 0.2), 0.0);
    }

    #[test]
    fn linear_distance_inverts_the_projection_at_its_ends() {
        assert!((linear_distance(1.0, 0.1, 100.0) - 0.1).abs() < 1e-6);
        assert!((linear_distance(0.0, 0.1, 100.0) - 100.0).abs() < 1e-3);
        assert!((linear_distance(2.0, 0.1, 100.0) - 0.1).abs() < 1e-6, "clamped");
    }
}
