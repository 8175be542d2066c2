//! Property tests of the shadow math: splits, cascade fitting and snapping, robustness to
//! degenerate input and caster culling (Poisson-disk sets: `tests/poisson_props.rs`).

use glam::{DVec3, Mat4, Quat, Vec3, Vec4};
use penumbra::math::aabb::Aabb;
use penumbra::math::cascades::{CascadeInput, CascadeSet, compute_cascades};
use penumbra::math::chunks::{SphereChunks, cull_casters_chunked, cull_spheres_frustum_chunked};
use penumbra::math::culling::{cull_casters, cull_spheres_frustum};
use penumbra::math::frustum::{CameraView, Frustum, slice_corners};
use penumbra::math::splits::pssm_splits;
use penumbra::settings::{CascadeFit, MAX_CASCADES};
use proptest::prelude::{BoxedStrategy, Just, ProptestConfig, Strategy, any, prop};
use proptest::{prop_assert, prop_assert_eq, prop_assume, prop_oneof, proptest};

// ---------------------------------------------------------------------------------------
// Strategies
// ---------------------------------------------------------------------------------------

/// `10^e` for `e` uniform in the range: log-uniform magnitudes.
fn log_uniform(lo: f32, hi: f32) -> impl Strategy<Value = f32> {
    (lo..hi).prop_map(|e| 10f32.powf(e))
}

fn unit_quat() -> impl Strategy<Value = Quat> {
    prop::array::uniform4(-1.0f32..1.0).prop_filter_map("near-zero quaternion", |v| {
        let v = Vec4::from_array(v);
        (v.length() > 0.1).then(|| Quat::from_vec4(v.normalize()))
    })
}

fn unit_vec3() -> impl Strategy<Value = Vec3> {
    prop::array::uniform3(-1.0f32..1.0).prop_filter_map("near-zero vector", |v| {
        let v = Vec3::from_array(v);
        (v.length() > 0.1).then(|| v.normalize())
    })
}

/// Light directions, with the exactly vertical and nearly vertical cases over-represented.
fn light_direction() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        Just(Vec3::NEG_Y),
        Just(Vec3::Y),
        Just(Vec3::new(0.0, -1.0, 1e-6)),
        Just(Vec3::new(0.14, -0.99, 0.0)),
        unit_vec3(),
        unit_vec3(),
        unit_vec3(),
    ]
}

fn position() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        3 => prop::array::uniform3(-1.0e3f32..1.0e3).prop_map(Vec3::from_array),
        1 => prop::array::uniform3(-1.0e6f32..1.0e6).prop_map(Vec3::from_array),
    ]
}

/// Cameras with fields of view from 0.06° to 180°, aspect 1e-2..1e2, near 1e-3..10 and
/// far/near up to 1e8.
fn camera() -> BoxedStrategy<CameraView> {
    (
        unit_quat(),
        position(),
        prop_oneof![0.01f32..3.1, Just(1e-3), Just(std::f32::consts::PI)],
        log_uniform(-2.0, 2.0),
        log_uniform(-3.0, 1.0),
        log_uniform(0.01, 8.0),
    )
        .prop_map(|(q, p, fov_y, aspect, near, ratio)| CameraView {
            world_from_view: Mat4::from_rotation_translation(q, p),
            fov_y,
            aspect,
            near,
            far: near * ratio,
        })
        .boxed()
}

/// Cameras near the origin with ordinary projections, whose frustum planes an f32 clip
/// matrix represents well.
fn ordinary_camera() -> BoxedStrategy<CameraView> {
    (
        unit_quat(),
        prop::array::uniform3(-1.0e3f32..1.0e3).prop_map(Vec3::from_array),
        0.05f32..3.0,
        log_uniform(-1.0, 1.0),
        log_uniform(-2.0, 1.0),
        log_uniform(0.5, 5.0),
    )
        .prop_map(|(q, p, fov_y, aspect, near, ratio)| CameraView {
            world_from_view: Mat4::from_rotation_translation(q, p),
            fov_y,
            aspect,
            near,
            far: near * ratio,
        })
        .boxed()
}

fn scene_bounds() -> impl Strategy<Value = Aabb> {
    prop_oneof![
        Just(Aabb::EMPTY),
        (
            prop::array::uniform3(-500.0f32..500.0),
            prop::array::uniform3(0.0f32..500.0)
        )
            .prop_map(|(c, h)| {
                let (c, h) = (Vec3::from_array(c), Vec3::from_array(h));
                Aabb::new(c - h, c + h)
            }),
    ]
}

fn fit() -> impl Strategy<Value = CascadeFit> {
    prop_oneof![Just(CascadeFit::Tight), Just(CascadeFit::Stable)]
}

fn input() -> BoxedStrategy<CascadeInput> {
    (
        camera(),
        light_direction(),
        scene_bounds(),
        1usize..=MAX_CASCADES,
        0.0f32..=1.0,
        log_uniform(-2.0, 4.0),
        prop_oneof![Just(512u32), Just(1024), Just(2048), Just(4096)],
        fit(),
        0.0f32..0.1,
        prop_oneof![Just(0u32), Just(8), Just(16), Just(64)],
    )
        .prop_map(
            |(camera, light_direction, scene_bounds, count, lambda, dist, resolution, fit, ad, snap_cells)| {
                CascadeInput {
                    camera,
                    light_direction,
                    scene_bounds,
                    receiver_bounds: Aabb::EMPTY,
                    count,
                    split_lambda: lambda,
                    // Shadow distance from just past the near plane to far beyond it.
                    max_distance: camera.near * (1.0 + dist),
                    resolution,
                    fit,
                    angular_diameter: ad,
                    blend_width: 0.1,
                    snap_cells,
                    scroll: false,
                    seen: None,
                }
            },
        )
        .boxed()
}

/// Any finite f32, with the troublesome values over-represented.
fn finite_f32() -> BoxedStrategy<f32> {
    prop_oneof![
        Just(0.0f32),
        Just(-0.0),
        Just(f32::MAX),
        Just(-f32::MAX),
        Just(f32::MIN_POSITIVE),
        Just(1e-45),
        -10.0f32..10.0,
        any::<f32>().prop_filter("finite", |v| v.is_finite()),
    ]
    .boxed()
}

fn finite_vec3() -> BoxedStrategy<Vec3> {
    prop::array::uniform3(finite_f32()).prop_map(Vec3::from_array).boxed()
}

/// Fully arbitrary finite inputs: rigid or arbitrary camera matrices, zero directions, fov 0
/// or π, zero or huge aspect, inverted near/far, extreme scene bounds, any resolution.
fn degenerate_input() -> BoxedStrategy<CascadeInput> {
    let matrix = prop_oneof![
        (unit_quat(), finite_vec3()).prop_map(|(q, p)| Mat4::from_rotation_translation(q, p)),
        prop::collection::vec(finite_f32(), 16).prop_map(|a| Mat4::from_cols_slice(&a)),
    ]
    .boxed();
    let fov = prop_oneof![Just(0.0f32), Just(std::f32::consts::PI), finite_f32()].boxed();
    let direction = prop_oneof![Just(Vec3::ZERO), Just(Vec3::NEG_Y), finite_vec3()].boxed();
    let bounds = prop_oneof![
        Just(Aabb::EMPTY),
        Just(Aabb::new(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX))),
        (finite_vec3(), finite_vec3()).prop_map(|(a, b)| Aabb::new(a, b)),
    ]
    .boxed();
    let camera = (matrix, fov, finite_f32(), finite_f32(), finite_f32())
        .prop_map(|(m, fov_y, aspect, near, far)| CameraView {
            world_from_view: m,
            fov_y,
            aspect,
            near,
            far,
        })
        .boxed();
    (
        camera,
        direction,
        bounds,
        0usize..=6,
        (finite_f32(), finite_f32()),
        prop_oneof![Just(0u32), Just(1), Just(u32::MAX), any::<u32>()],
        fit(),
        finite_f32(),
        prop_oneof![Just(0u32), Just(16), Just(u32::MAX), any::<u32>()],
    )
        .prop_map(
            |(camera, dir, bounds, count, (lambda, dist), res, fit, ad, snap_cells)| CascadeInput {
                camera,
                light_direction: dir,
                scene_bounds: bounds,
                receiver_bounds: bounds,
                count,
                split_lambda: lambda,
                max_distance: dist,
                resolution: res,
                fit,
                angular_diameter: ad,
                blend_width: 0.1,
                snap_cells,
                scroll: false,
                seen: None,
            },
        )
        .boxed()
}

// ---------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------

/// `m · (p, 1)` evaluated in f64 from the f32 values, with the sum of the absolute terms of
/// each row (the scale of the rounding error any f32 evaluation has).
fn project_f64(m: &Mat4, p: Vec3) -> ([f64; 3], [f64; 3]) {
    let p = [f64::from(p.x), f64::from(p.y), f64::from(p.z), 1.0];
    let mut value = [0.0; 3];
    let mut magnitude = [0.0; 3];
    for (row, (v, mag)) in value.iter_mut().zip(&mut magnitude).enumerate() {
        let r = m.row(row);
        for (k, pk) in p.iter().enumerate() {
            let term = f64::from(r[k]) * pk;
            *v += term;
            *mag += term.abs();
        }
    }
    (value, magnitude)
}

/// Texture u, v of world point `p` in f64 (`u = x/2 + 1/2`, `v = 1/2 − y/2`).
fn uv_f64(m: &Mat4, p: Vec3) -> (f64, f64) {
    let (c, _) = project_f64(m, p);
    (c[0] * 0.5 + 0.5, 0.5 - c[1] * 0.5)
}

fn all_finite(set: &CascadeSet) -> bool {
    set.splits.iter().all(|s| s.is_finite())
        && set.light_rotation.is_finite()
        && set.cascades.iter().all(|c| {
            c.clip_from_world.is_finite()
                && c.near.is_finite()
                && c.far.is_finite()
                && c.light_min.is_finite()
                && c.light_max.is_finite()
                && c.texel_world_size.is_finite()
                && c.depth_range.is_finite()
                && c.light_size_uv.is_finite()
                && c.pcss_scale.is_finite()
                && c.uv_scale_y.is_finite()
        })
}

/// Distance from `p` to the box `[min, max]` whose +z side is open, in f64.
fn distance_to_open_box(p: DVec3, min: DVec3, max: DVec3) -> f64 {
    let dx = (min.x - p.x).max(p.x - max.x).max(0.0);
    let dy = (min.y - p.y).max(p.y - max.y).max(0.0);
    let dz = (min.z - p.z).max(0.0);
    (dx * dx + dy * dy + dz * dz).sqrt()
}

// ---------------------------------------------------------------------------------------
// Properties
// ---------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 512,
        // Failures are reported with their minimal input; no regression files are written.
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn splits_increase_and_cover_the_range(
        near in log_uniform(-4.0, 3.0),
        ratio in log_uniform(0.001, 8.0),
        count in 1usize..=MAX_CASCADES,
        lambda in 0.0f32..=1.0,
    ) {
        let far = near * ratio;
        prop_assume!(far > near * 1.001);
        let s = pssm_splits(near, far, count, lambda);
        prop_assert_eq!(s[0], near);
        prop_assert_eq!(s[count], far);
        for w in s[..=count].windows(2) {
            prop_assert!(w[0] < w[1], "{:?}", s);
        }
        for v in &s[count..] {
            prop_assert_eq!(*v, far);
        }
    }

    #[test]
    fn splits_never_fail_on_bad_input(
        near in finite_f32(), far in finite_f32(), count in 0usize..10, lambda in finite_f32(),
    ) {
        let s = pssm_splits(near, far, count, lambda);
        let n = count.clamp(1, MAX_CASCADES);
        prop_assert!(s.iter().all(|v| v.is_finite() && *v > 0.0), "{:?}", s);
        for w in s[..=n].windows(2) {
            prop_assert!(w[0] < w[1], "{:?}", s);
        }
    }

    #[test]
    fn slice_corners_project_inside_their_cascade(inp in input()) {
        let set = compute_cascades(&inp);
        prop_assert_eq!(set.count, inp.count);
        for (i, c) in set.active().iter().enumerate() {
            prop_assert_eq!((c.near, c.far), (set.splits[i], set.splits[i + 1]));
            // The blend band at the end of the previous cascade must be covered too.
            let start = if i > 0 { c.near - inp.blend_width * (c.near - set.splits[i - 1]) } else { c.near };
            for p in slice_corners(&inp.camera, start, c.far) {
                let (q, mag) = project_f64(&c.clip_from_world, p);
                // NOTE: the only slack is the rounding any f32 evaluation of this matrix
                // has at this point (negligible near the origin, large far from it).
                let tol = mag.map(|m| 1e-5 + 16.0 * f64::from(f32::EPSILON) * m);
                prop_assert!(q[0].abs() <= 1.0 + tol[0], "cascade {i}: x {} ({:?})", q[0], tol);
                prop_assert!(q[1].abs() <= 1.0 + tol[1], "cascade {i}: y {} ({:?})", q[1], tol);
                prop_assert!(q[2] >= -tol[2] && q[2] <= 1.0 + tol[2], "cascade {i}: z {}", q[2]);
            }
            prop_assert!(c.texel_world_size > 0.0 && c.depth_range > 0.0);
            prop_assert!(c.light_max.cmpgt(c.light_min).all());
        }
    }

    #[test]
    fn sub_texel_translation_moves_by_whole_texels(
        inp in input(), dir in unit_vec3(), frac in 0.0f32..0.5, probe in position(),
    ) {
        let a = compute_cascades(&inp);
        let step = dir * frac * a.cascades[0].texel_world_size;
        let mut moved = inp;
        moved.camera.world_from_view.w_axis += step.extend(0.0);
        let b = compute_cascades(&moved);
        let res = f64::from(inp.resolution);
        for (i, (ca, cb)) in a.active().iter().zip(b.active()).enumerate() {
            // Same box size: identical projection scale.
            prop_assert_eq!(ca.texel_world_size, cb.texel_world_size);
            prop_assert_eq!(ca.uv_scale_y, cb.uv_scale_y);
            for p in [probe, inp.camera.position(), Vec3::ZERO] {
                let (ua, va) = uv_f64(&ca.clip_from_world, p);
                let (ub, vb) = uv_f64(&cb.clip_from_world, p);
                let (du, dv) = ((ub - ua) * res, (vb - va) * res);
                prop_assert!((du - du.round()).abs() < 1e-3, "cascade {i}: du = {du} texels");
                prop_assert!((dv - dv.round()).abs() < 1e-3, "cascade {i}: dv = {dv} texels");
            }
        }
    }

    #[test]
    fn receivers_in_a_slice_project_inside_their_cascade(
        inp in input(), receivers in scene_bounds(), samples in prop::collection::vec(prop::array::uniform3(0.0f64..=1.0), 64),
    ) {
        let inp = CascadeInput { receiver_bounds: receivers, ..inp };
        let set = compute_cascades(&inp);
        let (rmin, rmax) = (receivers.min.as_dvec3(), receivers.max.as_dvec3());
        for (i, c) in set.active().iter().enumerate() {
            let start = if i > 0 { c.near - inp.blend_width * (c.near - set.splits[i - 1]) } else { c.near };
            let k = slice_corners(&inp.camera, start, c.far).map(|p| p.as_dvec3());
            // Points of the slice (trilinear in its corners) that lie in the receivers' box.
            for [u, v, w] in &samples {
                let near = k[0] + (k[1] - k[0]) * *u + (k[3] - k[0]) * *v;
                let far = k[4] + (k[5] - k[4]) * *u + (k[7] - k[4]) * *v;
                let p = near + (far - near) * *w;
                if !(p.cmpge(rmin).all() && p.cmple(rmax).all()) {
                    continue;
                }
                let (q, mag) = project_f64(&c.clip_from_world, p.as_vec3());
                let tol = mag.map(|m| 1e-4 + 16.0 * f64::from(f32::EPSILON) * m);
                prop_assert!(q[0].abs() <= 1.0 + tol[0], "cascade {i}: x {} ({:?})", q[0], tol);
                prop_assert!(q[1].abs() <= 1.0 + tol[1], "cascade {i}: y {} ({:?})", q[1], tol);
                prop_assert!(q[2] >= -tol[2] && q[2] <= 1.0 + tol[2], "cascade {i}: z {}", q[2]);
            }
        }
    }

    #[test]
    fn stable_fit_ignores_camera_rotation_with_or_without_receivers(
        inp in input(), q in unit_quat(), receivers in scene_bounds(),
    ) {
        let inp = CascadeInput { fit: CascadeFit::Stable, receiver_bounds: receivers, ..inp };
        let inp = CascadeInput { fit: CascadeFit::Stable, ..inp };
        let a = compute_cascades(&inp);
        let mut turned = inp;
        let position = inp.camera.position();
        turned.camera.world_from_view = Mat4::from_rotation_translation(q, position);
        let b = compute_cascades(&turned);
        prop_assert_eq!(a, b);
    }

    #[test]
    fn outputs_are_finite_for_any_finite_input(inp in degenerate_input()) {
        let set = compute_cascades(&inp);
        prop_assert!((1..=MAX_CASCADES).contains(&set.count));
        prop_assert!(all_finite(&set), "{:?}", set);
        for c in set.active() {
            prop_assert!(c.texel_world_size > 0.0, "{:?}", c);
            prop_assert!(c.depth_range > 0.0, "{:?}", c);
            prop_assert!(c.uv_scale_y > 0.0, "{:?}", c);
            prop_assert!(c.light_max.cmpgt(c.light_min).all(), "{:?}", c);
        }
        for w in set.splits[..=set.count].windows(2) {
            prop_assert!(w[0] < w[1]);
        }
    }

    #[test]
    fn culling_matches_brute_force(
        inp in input(),
        spheres in prop::collection::vec(
            (prop::array::uniform3(-1.0f32..1.0), 0.0f32..1.0, 0.0f32..1.0), 1..64),
        specials in prop::collection::vec(0usize..64, 0..4),
    ) {
        let set = compute_cascades(&inp);
        let cam = inp.camera.position();
        let reach = set.splits[set.count];
        let mut centers: Vec<Vec3> = spheres
            .iter()
            .map(|(o, _, _)| cam + Vec3::from_array(*o) * reach * 1.5)
            .collect();
        let mut radii: Vec<f32> = spheres.iter().map(|(_, r, _)| r * r * reach * 0.3).collect();
        for (k, &s) in specials.iter().enumerate() {
            let i = s % centers.len();
            match k % 3 {
                0 => centers[i].x = f32::NAN,
                1 => radii[i] = f32::INFINITY,
                _ => centers[i].z = f32::NEG_INFINITY,
            }
        }
        let mut masks = vec![0xAAu8; centers.len()];
        cull_casters(&set, &centers, &radii, &mut masks);
        let rot = set.light_rotation.as_dmat3();
        for (i, (&c, &r)) in centers.iter().zip(&radii).enumerate() {
            if !(c.is_finite() && r.is_finite()) {
                prop_assert_eq!(masks[i], 0);
                continue;
            }
            let p = rot * c.as_dvec3();
            for k in 0..MAX_CASCADES {
                let bit = masks[i] >> k & 1 == 1;
                if k >= set.count {
                    prop_assert!(!bit);
                    continue;
                }
                let cascade = &set.cascades[k];
                let d = distance_to_open_box(
                    p, cascade.light_min.as_dvec3(), cascade.light_max.as_dvec3());
                // Skip spheres within rounding distance of touching the box.
                let tol = 1e-5 * (1.0 + p.abs().element_sum() + f64::from(r));
                if (d - f64::from(r)).abs() > tol {
                    prop_assert_eq!(bit, d <= f64::from(r), "caster {} cascade {}: d {} r {}", i, k, d, r);
                }
            }
        }
    }

    #[test]
    fn chunked_culling_agrees_with_the_exact_tests(
        inp in input(),
        spheres in prop::collection::vec(
            (prop::array::uniform3(-1.0f32..1.0), 0.0f32..1.0), 1..300),
        nan_at in prop::option::of(0usize..300),
    ) {
        let set = compute_cascades(&inp);
        let cam = inp.camera.position();
        let reach = set.splits[set.count];
        // A random walk keeps neighbours close, like a spatially sorted instance list.
        let mut p = Vec3::ZERO;
        let mut centers = Vec::new();
        for (o, _) in &spheres {
            p = (p + Vec3::from_array(*o) * 0.1).clamp(Vec3::splat(-1.5), Vec3::splat(1.5));
            centers.push(cam + p * reach);
        }
        let mut radii: Vec<f32> = spheres.iter().map(|(_, r)| r * r * reach * 0.05).collect();
        if let Some(i) = nan_at {
            let i = i % centers.len();
            radii[i] = f32::NAN;
        }
        let chunks = SphereChunks::build(&centers, &radii);
        let mut exact = vec![0u8; centers.len()];
        let mut chunked = vec![0u8; centers.len()];
        cull_casters(&set, &centers, &radii, &mut exact);
        cull_casters_chunked(&set, &centers, &radii, &chunks, &mut chunked);
        for (i, (e, c)) in exact.iter().zip(&chunked).enumerate() {
            prop_assert_eq!(e & !c, 0, "caster {}: chunked culling dropped an exact hit", i);
        }
        let frustum = Frustum::from_clip_from_world(inp.camera.clip_from_world());
        let (mut a, mut b, mut scratch) = (Vec::new(), Vec::new(), Vec::new());
        cull_spheres_frustum(&frustum, &centers, &radii, &mut a);
        cull_spheres_frustum_chunked(&frustum, &centers, &radii, &chunks, &mut b, &mut scratch);
        for i in &a {
            prop_assert!(b.contains(i), "sphere {} visible exactly but culled by its chunk", i);
        }
        prop_assert!(b.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn frustum_keeps_interior_and_drops_exterior(
        cam in ordinary_camera(), x in -0.95f32..0.95, y in -0.95f32..0.95, t in 0.01f32..0.99,
    ) {
        let frustum = Frustum::from_clip_from_world(cam.clip_from_world());
        // A point inside: interpolate within the frustum between the corners of a slice.
        let near = cam.near + (cam.far - cam.near) * t * 0.5;
        let c = slice_corners(&cam, near, near);
        let bottom = c[0].lerp(c[1], x * 0.5 + 0.5);
        let top = c[3].lerp(c[2], x * 0.5 + 0.5);
        let inside = bottom.lerp(top, y * 0.5 + 0.5);
        // NOTE: `inside` is built in f32 and carries the rounding of its coordinates (up to
        // ~6e-5 m at 1000 m from the origin), which can exceed 1e-3 · near for a narrow view
        // with a tiny near plane: the radius covers 8 ulps of the position as well.
        let rounding = 8.0 * f32::EPSILON * inside.abs().max_element();
        let radius = (1e-3 * near).max(rounding);
        prop_assert!(frustum.intersects_sphere(inside, radius));
        let outside = cam.position() - cam.forward() * (cam.near + 1.0) * 2.0;
        prop_assert!(!frustum.intersects_sphere(outside, cam.near));
        let mut out = Vec::new();
        cull_spheres_frustum(&frustum, &[outside, inside], &[cam.near, radius], &mut out);
        prop_assert_eq!(out, vec![1]);
    }
}
