//! Property tests of the depth-bounds (SDSM) cascade fit: fitted to what a camera saw (reduced
//! on the CPU as the GPU does), every seen point projects inside the cascade that shades it,
//! the splits still start at the near plane and increase, shadows end where the other fits
//! end them, and arbitrary reduction words never break the cascades.

use glam::{DVec3, Mat4, Quat, Vec3};
use penumbra::math::aabb::Aabb;
use penumbra::math::cascades::{CascadeInput, compute_cascades};
use penumbra::math::frustum::{CameraView, slice_corners};
use penumbra::math::seen_depths::{SEEN_WORDS, SeenDepths, band_of, initial_words, ordered_bits};
use penumbra::settings::{CascadeFit, MAX_CASCADES};
use proptest::prelude::{BoxedStrategy, ProptestConfig, Strategy, any, prop};
use proptest::{prop_assert, prop_assert_eq, prop_assume, proptest};

/// A camera near the origin looking anywhere, with a view of 0.2–2.5 rad and a far plane 10
/// to 10⁵ times its near plane.
fn camera() -> BoxedStrategy<CameraView> {
    (
        prop::array::uniform4(-1.0f32..1.0),
        prop::array::uniform3(-50.0f32..50.0),
        0.2f32..2.5,
        0.2f32..5.0,
        0.01f32..1.0,
        1.0f32..5.0,
    )
        .prop_map(|(q, p, fov_y, aspect, near, decades)| CameraView {
            world_from_view: Mat4::from_rotation_translation(unit_quat(q), Vec3::from_array(p)),
            fov_y,
            aspect,
            near,
            far: near * 10f32.powf(decades),
        })
        .boxed()
}

/// `q` normalised, or the identity where it is too short to normalise.
fn unit_quat(q: [f32; 4]) -> Quat {
    let q = Quat::from_array(q);
    if q.length() > 1e-3 {
        q.normalize()
    } else {
        Quat::IDENTITY
    }
}

/// View depth of world point `p` seen by `camera` (what the reduction shader computes).
fn view_depth(camera: &CameraView, p: DVec3) -> f64 {
    -(camera.world_from_view.as_dmat4().inverse() * p.extend(1.0)).z
}

/// The reduction of `points` by `camera`, as the GPU's words.
fn reduce(camera: &CameraView, points: &[DVec3]) -> Vec<u32> {
    let mut w = initial_words(camera.near, camera.far).to_vec();
    for p in points {
        let d = view_depth(camera, *p) as f32;
        w[2] = w[2].min(ordered_bits(d));
        w[3] = w[3].max(ordered_bits(d));
        let b = 4 + 6 * band_of(d, camera.near, camera.far);
        for (i, v) in p.as_vec3().to_array().into_iter().enumerate() {
            w[b + i] = w[b + i].min(ordered_bits(v));
            w[b + 3 + i] = w[b + 3 + i].max(ordered_bits(v));
        }
    }
    w
}

/// Points inside the camera's view between the fractions `a` and `b` of its depth range
/// (log-spaced), from unit-cube samples trilinear in that slice's corners.
fn seen_points(camera: &CameraView, (a, b): (f32, f32), samples: &[[f64; 3]]) -> Vec<DVec3> {
    let depth = |t: f32| camera.near * (camera.far / camera.near).powf(t);
    let (d0, d1) = (depth(a.min(b)), depth(a.max(b)));
    let k = slice_corners(camera, d0, d1.max(d0 * 1.01)).map(|p| p.as_dvec3());
    samples
        .iter()
        .map(|&[u, v, w]| {
            let near = k[0] + (k[1] - k[0]) * u + (k[3] - k[0]) * v;
            let far = k[4] + (k[5] - k[4]) * u + (k[7] - k[4]) * v;
            near + (far - near) * w
        })
        .collect()
}

fn input(camera: CameraView, count: usize, lambda: f32, max_distance: f32, seen: Option<SeenDepths>) -> CascadeInput {
    CascadeInput {
        camera,
        light_direction: Vec3::new(0.3, -0.8, 0.4),
        scene_bounds: Aabb::new(Vec3::splat(-500.0), Vec3::splat(500.0)),
        receiver_bounds: Aabb::EMPTY,
        count,
        split_lambda: lambda,
        max_distance,
        resolution: 2048,
        fit: CascadeFit::DepthBounds,
        angular_diameter: 0.01,
        blend_width: 0.1,
        snap_cells: 0,
        scroll: false,
        seen,
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 256,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn every_seen_point_projects_inside_the_cascade_that_shades_it(
        camera in camera(),
        range in (0.0f32..1.0, 0.0f32..1.0),
        samples in prop::collection::vec(prop::array::uniform3(0.0f64..=1.0), 64),
        count in 1usize..=MAX_CASCADES,
        lambda in 0.0f32..=1.0,
        max_distance in 1.0f32..1.0e5,
    ) {
        let points = seen_points(&camera, range, &samples);
        let seen = SeenDepths::from_words(&reduce(&camera, &points));
        prop_assume!(seen.is_some());
        let inp = input(camera, count, lambda, max_distance, seen);
        let set = compute_cascades(&inp);
        let tight = compute_cascades(&CascadeInput { fit: CascadeFit::Tight, ..inp });
        prop_assert_eq!(set.splits[0], tight.splits[0]);
        prop_assert_eq!(set.end, tight.end);
        for w in set.splits[..=count].windows(2) {
            prop_assert!(w[0] < w[1], "{:?}", set.splits);
        }
        let mut judged = 0;
        for p in &points {
            let d = view_depth(&camera, *p);
            let Some(i) = (0..count).find(|&i| d < f64::from(set.splits[i + 1])) else {
                // Past the last split: only where shadows end before it.
                prop_assert!(d >= f64::from(set.splits[count]) && set.splits[count] >= set.end * 0.999_999);
                continue;
            };
            judged += 1;
            let c = &set.cascades[i];
            let m = c.clip_from_world.as_dmat4();
            let q = m * p.extend(1.0);
            // NOTE: the slack is the f32 matrix's rounding at this point.
            let tol = 1e-4 + 1e-6 * p.abs().max_element();
            prop_assert!(q.x.abs() <= 1.0 + tol && q.y.abs() <= 1.0 + tol, "cascade {}: {:?}", i, q);
            prop_assert!(q.z >= -tol && q.z <= 1.0 + tol, "cascade {}: {:?}", i, q);
        }
        prop_assert!(judged > 0 || set.end <= seen.unwrap().near, "no point judged");
    }

    #[test]
    fn any_reduction_words_leave_the_cascades_finite(
        camera in camera(),
        words in prop::collection::vec(any::<u32>(), SEEN_WORDS),
        count in 1usize..=MAX_CASCADES,
    ) {
        let seen = SeenDepths::from_words(&words);
        let set = compute_cascades(&input(camera, count, 0.7, 200.0, seen));
        prop_assert_eq!(set.count, count);
        for w in set.splits[..=count].windows(2) {
            prop_assert!(w[0] < w[1], "{:?}", set.splits);
        }
        for c in set.active() {
            prop_assert!(c.clip_from_world.is_finite(), "{:?}", c);
            prop_assert!(c.texel_world_size > 0.0 && c.depth_range > 0.0, "{:?}", c);
            prop_assert!(c.light_max.cmpgt(c.light_min).all(), "{:?}", c);
        }
    }
}
