//! Point-light shadows on a real wgpu device (lavapipe in CI), judged against rays cast on the
//! CPU: a shadow lands where a ray to the light is blocked in every face direction (±X, ±Y,
//! ±Z) and across face edges, with PCF and with VSM (blurred or not, 32- or 16-bit moments),
//! and a point light's PCSS penumbra widens with the gap between caster and receiver as the
//! perspective estimate says.

mod common;

use common::rays::{Aabb, evaluate, evaluate_with, scene_with};
use glam::Vec3;

const LIGHT: Vec3 = Vec3::new(0.0, 4.0, 0.0);

/// A 0.8 m box 1.6 m from the light along each face axis, and one on the edge between +X and
/// +Z (its shadow falls on both faces).
fn casters() -> Vec<Aabb> {
    let mut boxes: Vec<Aabb> = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z]
        .iter()
        .map(|&axis| Aabb::cube(LIGHT + axis * 1.6 + axis.any_orthonormal_vector() * 0.3, 0.8))
        .collect();
    boxes.push(Aabb::cube(LIGHT + Vec3::new(1.2, 0.2, 1.2), 0.6));
    boxes
}

/// Evaluates `light` (a point light at `LIGHT`) on planes 4 m from it across each face axis,
/// facing it, out to 40° from the axis (near the face edges), every 5 cm, and asserts per
/// face that at most `max_wrong` of the probes a ray judges disagree with it (on which side
/// of 0.5 they fall) and that their mean error is at most 0.01; VSM moments are stored in
/// `format` where given.
fn assert_rays_on_every_face(light: &str, format: Option<wgpu::TextureFormat>, max_wrong: f64) {
    let boxes = casters();
    let desc = scene_with(&boxes, light);
    let mut probes = Vec::new();
    let mut faces = Vec::new();
    for (face, axis) in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z]
        .iter()
        .enumerate()
    {
        let (u, v) = axis.any_orthonormal_pair();
        for i in -66..=66 {
            for j in -66..=66 {
                let p = LIGHT + *axis * 4.0 + u * (i as f32 * 0.05) + v * (j as f32 * 0.05);
                probes.push((p, -*axis));
                faces.push(face);
            }
        }
    }
    let values = evaluate_with(&desc, &probes, format);
    let mut judged = [0usize; 6];
    let mut shadowed = [0usize; 6];
    let mut wrong = [0usize; 6];
    let mut error = [0.0f64; 6];
    for ((&(p, n), &v), &face) in probes.iter().zip(&values).zip(&faces) {
        let blocked_at = |q: Vec3| boxes.iter().any(|b| b.blocks(q + n * 1e-3, LIGHT));
        let here = blocked_at(p);
        let (u, w) = n.any_orthonormal_pair();
        // NOTE: a ray that grazes a box (blocked 3 cm to one side, not the other) is left out:
        // the filter blurs it by design.
        if [u, -u, w, -w].iter().any(|&o| blocked_at(p + o * 0.03) != here) {
            continue;
        }
        judged[face] += 1;
        shadowed[face] += usize::from(here);
        wrong[face] += usize::from((v < 0.5) != here);
        error[face] += f64::from((v - if here { 0.0 } else { 1.0 }).abs());
    }
    for face in 0..6 {
        assert!(
            judged[face] >= 10_000,
            "face {face}: only {} probes judged",
            judged[face]
        );
        assert!(
            shadowed[face] >= 500,
            "face {face}: only {} shadowed probes",
            shadowed[face]
        );
        let share = wrong[face] as f64 / judged[face] as f64;
        let mean_error = error[face] / judged[face] as f64;
        assert!(
            mean_error <= 0.01,
            "face {face}: mean error {mean_error:.4} against the rays"
        );
        assert!(
            share <= max_wrong,
            "face {face}: {:.2} % of probes disagree with the rays ({} of {})",
            share * 100.0,
            wrong[face],
            judged[face]
        );
    }
}

#[test]
fn a_point_shadow_lands_where_a_ray_to_the_light_is_blocked_on_every_face() {
    assert_rays_on_every_face(
        "Point(position: (0, 4, 0), intensity: 40, range: 12, shadows: (mode: Pcf, pcf_radius: 1, resolution: 1024))",
        None,
        0.005,
    );
}

#[test]
fn a_point_vsm_shadow_lands_where_a_ray_to_the_light_is_blocked_with_and_without_blur() {
    for format in [wgpu::TextureFormat::Rg32Float, wgpu::TextureFormat::Rgba16Float] {
        for blur in [0, 3] {
            assert_rays_on_every_face(
                &format!(
                    "Point(position: (0, 4, 0), intensity: 40, range: 12,
                        shadows: (mode: Vsm, vsm_blur: {blur}, resolution: 1024))"
                ),
                Some(format),
                0.005,
            );
        }
    }
}

/// Width of the shadow edge crossed by the probes: the distance between the last probe below
/// 0.1 and the first above 0.9, walking away from the umbra.
fn edge_width(values: &[f32], step: f32) -> f32 {
    let last_dark = values
        .iter()
        .rposition(|&v| v < 0.1)
        .expect("the walk starts in the umbra");
    let first_lit = values
        .iter()
        .position(|&v| v > 0.9)
        .expect("the walk ends in the light");
    assert!(first_lit > last_dark, "{values:?}");
    (first_lit - last_dark) as f32 * step
}

#[test]
fn a_point_pcss_penumbra_widens_with_the_gap_to_the_caster() {
    // A light 6 m up with a 0.15 m radius over two boxes: one 0.1 m above the ground, one
    // 2.5 m. Their outer shadow edges on the ground are at x = −3.06 and x = 6.0.
    let boxes = [
        Aabb::cube(Vec3::new(-2.0, 0.6, 0.0), 1.0),
        Aabb::cube(Vec3::new(2.0, 3.0, 0.0), 1.0),
    ];
    let desc = scene_with(
        &boxes,
        "Point(position: (0, 6, 0), intensity: 40, range: 20, radius: 0.15,
            shadows: (mode: Pcss, pcss_quality: High, temporal_rotation: false, resolution: 2048))",
    );
    let step = 0.01;
    let walk = |from: f32, to: f32| -> Vec<(Vec3, Vec3)> {
        let n = ((to - from).abs() / step) as usize;
        let dir = (to - from).signum();
        (0..=n)
            .map(|k| (Vec3::new(from + dir * step * k as f32, 0.0, 0.0), Vec3::Y))
            .collect()
    };
    let (near_walk, far_walk) = (walk(-2.6, -3.6), walk(5.2, 7.0));
    let all: Vec<(Vec3, Vec3)> = near_walk.iter().chain(&far_walk).copied().collect();
    let values = evaluate(&desc, &all);
    let near = edge_width(&values[..near_walk.len()], step);
    let far = edge_width(&values[near_walk.len()..], step);
    // The perspective estimate (d_receiver − d_blocker) · 2r / d_blocker: 0.07 m and 0.42 m.
    assert!(
        far > 3.0 * near,
        "penumbra {far} m behind the high box, {near} m behind the low one"
    );
    assert!((0.25..=0.65).contains(&far), "penumbra {far} m, the estimate is 0.42 m");
    assert!(near <= 0.15, "penumbra {near} m, the estimate is 0.07 m");
}
