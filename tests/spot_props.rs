//! Property tests of spot-light shadow views: for any light placement, cone and range, every
//! point inside the cone and range projects inside the map with a depth in `[0, 1]` that maps
//! back to its distance, and the cull volume keeps it.

use glam::{Quat, Vec3, Vec4Swizzles};
use penumbra::math::spot::{SpotInput, spot_view};
use proptest::prelude::{ProptestConfig, Strategy, prop};
use proptest::{prop_assert, proptest};

fn unit_vec3() -> impl Strategy<Value = Vec3> {
    prop::array::uniform3(-1.0f32..1.0).prop_filter_map("near-zero vector", |v| {
        let v = Vec3::from_array(v);
        (v.length() > 0.1).then(|| v.normalize())
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn points_in_the_cone_land_in_the_map(
        position in prop::array::uniform3(-1.0e4f32..1.0e4),
        direction in unit_vec3(),
        half_degrees in 1.0f32..85.0,
        range in 1.0f32..500.0,
        // Where the point is: fraction of the range, of the cone's angle, and turn about the axis.
        depth in 0.01f32..0.99,
        off_axis in 0.0f32..0.99,
        turn in 0.0f32..std::f32::consts::TAU,
    ) {
        let position = Vec3::from_array(position);
        let input = SpotInput {
            position,
            direction,
            outer_angle: half_degrees.to_radians(),
            range,
            near: 0.01,
            resolution: 2048,
        };
        let view = spot_view(&input).expect("a valid light makes a view");
        prop_assert!(view.clip_from_world.is_finite());
        let (side, _) = direction.any_orthonormal_pair();
        let tilt = Quat::from_axis_angle(Quat::from_axis_angle(direction, turn) * side, off_axis * input.outer_angle);
        let ray = tilt * direction;
        // Along the ray, to the requested fraction of the range measured along the axis.
        let along_axis = 0.01 + depth * (range - 0.01);
        let p = position + ray * (along_axis / ray.dot(direction));
        let clip = view.clip_from_world * p.extend(1.0);
        let ndc = clip.xyz() / clip.w;
        prop_assert!(ndc.x.abs() <= 1.0 + 1e-3 && ndc.y.abs() <= 1.0 + 1e-3, "{ndc}");
        prop_assert!((-1e-4..=1.0 + 1e-4).contains(&ndc.z), "{ndc}");
        let back = view.distance_from_depth(ndc.z);
        prop_assert!((back - along_axis).abs() <= 2e-3 * along_axis.max(1.0), "{along_axis} → {back}");
        prop_assert!(view.frustum.intersects_sphere(p, 1e-3 * (1.0 + position.abs().max_element())));
    }
}
