//! Point-light shadows on a real wgpu device (lavapipe in CI), judged against rays cast on the
//! CPU: a shadow lands where a ray to the light is blocked in every face direction (±X, ±Y,
//! ±Z) and across face edges, with PCF and with VSM (blurred or not, 32- or 16-bit moments),
//! a point light's PCSS penumbra widens with the gap between caster and receiver as the
//! perspective estimate says, and `penumbra bench` scores the point-light scene against the
//! sphere-light reference.

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
    let values = evaluate_with(&desc, &probes, format, None);
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
    for format in [wgpu::TextureFormat::Rgba32Float, wgpu::TextureFormat::Rgba16Float] {
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
    assert_penumbra_widens("mode: Pcss, pcss_quality: High");
}

#[test]
fn a_point_vsm_penumbra_widens_with_the_gap_to_the_caster() {
    // VSM's contact hardening (on by default) sizes the penumbra from the light's radius.
    assert_penumbra_widens("mode: Vsm");
}

/// Walks the ground out of the shadows of two boxes under a point light filtered with
/// `filter` and checks each penumbra's width against the perspective estimate.
fn assert_penumbra_widens(filter: &str) {
    // A light 6 m up with a 0.15 m radius over two boxes: one 0.1 m above the ground, one
    // 2.5 m. Their outer shadow edges on the ground are at x = −3.06 and x = 6.0.
    let boxes = [
        Aabb::cube(Vec3::new(-2.0, 0.6, 0.0), 1.0),
        Aabb::cube(Vec3::new(2.0, 3.0, 0.0), 1.0),
    ];
    let desc = scene_with(
        &boxes,
        &format!(
            "Point(position: (0, 6, 0), intensity: 40, range: 20, radius: 0.15,
            shadows: ({filter}, temporal_rotation: false, resolution: 2048))"
        ),
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
        "{filter}: penumbra {far} m behind the high box, {near} m behind the low one"
    );
    assert!(
        (0.25..=0.65).contains(&far),
        "{filter}: penumbra {far} m, the estimate is 0.42 m"
    );
    assert!(near <= 0.15, "{filter}: penumbra {near} m, the estimate is 0.07 m");
}

#[test]
fn the_bench_scores_the_point_scene_against_the_sphere_light() {
    use penumbra::analysis::ScoredLight;
    use penumbra::bench::run_bench;

    let wanted = ["hard", "pcss-high", "vsm", "vsm-blur4"];
    let config = common::small_bench("scenes/point.ron", &wanted);
    let report = run_bench(&config).unwrap_or_else(|e| panic!("{e}"));
    let names: Vec<&str> = report.presets.iter().map(|p| p.preset.as_str()).collect();
    assert_eq!(names, wanted);
    let notes = report.notes.join("\n");
    assert!(notes.contains("point light 0, radius 0.20 m"), "{notes}");
    let mut penumbra_mae = Vec::new();
    for p in &report.presets {
        let [s] = p.scenes.as_slice() else {
            panic!("{}: {} scenes", p.preset, p.scenes.len())
        };
        assert_eq!(s.light, ScoredLight::Point { index: 0, radius: 0.2 });
        let e = &s.errors;
        // The ground and both walls, within the light's range, on every face it sees.
        assert!(e.pixels >= 4000, "{}: only {} points judged", p.preset, e.pixels);
        assert!(
            e.penumbra_pixels >= 100,
            "{}: only {} penumbra points",
            p.preset,
            e.penumbra_pixels
        );
        assert!(e.lit_pixels >= 2000 && e.shadowed_pixels >= 200, "{}: {e:?}", p.preset);
        assert_eq!(
            s.per_cascade[0].pixels, e.pixels,
            "{}: the faces count as one view",
            p.preset
        );
        assert!(e.acne_rate <= 0.005, "{}: acne {:.2} %", p.preset, e.acne_rate * 100.0);
        penumbra_mae.push(e.penumbra_mae);
    }
    // Contact hardening matters here: PCSS follows the sphere light's penumbrae, one hardware
    // comparison cannot.
    let (hard, pcss) = (penumbra_mae[0], penumbra_mae[1]);
    assert!(pcss < 0.5 * hard, "penumbra MAE: PCSS High {pcss:.4}, hard {hard:.4}");
}

/// The cube-face seam on `assets/scenes/point.ron`: the shadow of the box at x = 2.2 falls on
/// the ground across the edge between the light's −Y and +X faces (x = 3 on the ground, 3 m
/// under the light). Along 161 paths across that edge (z from −0.8 to 0.8), probes 1 cm apart
/// at x = 2.985, 2.995, 3.005 and 3.015 give three steps; the seam of a path is how much the
/// step across the edge exceeds the larger of its neighbours (a filter's own slope is not a
/// seam). Returns the largest seam, the largest jump across the edge and the reference's
/// largest jump between the same points (4096 rays each), and asserts the paths cross
/// penumbrae (so the seam was measured where filtering matters).
fn seams(mode: &str) -> (f32, f32, f32) {
    use penumbra::bench::session::SceneSession;
    use penumbra::reference::{ReferencePoint, ReferenceSettings, SphereLight, sphere_light_visibility};
    use penumbra::scene::SceneDesc;

    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/point.ron");
    let text = std::fs::read_to_string(path).unwrap();
    let text = text.replace("mode: Pcss, pcss_quality: High, resolution: 1024", mode);
    let desc = SceneDesc::from_str(&text, path).unwrap_or_else(|e| panic!("{e}"));
    let paths: Vec<Vec3> = (0..=160)
        .flat_map(|k| {
            let z = -0.8 + 0.01 * k as f32;
            [2.985, 2.995, 3.005, 3.015].map(|x| Vec3::new(x, 0.0, z))
        })
        .collect();
    let probes: Vec<(Vec3, Vec3)> = paths.iter().map(|&p| (p, Vec3::Y)).collect();
    // NOTE: one rotation of the filter patterns for every probe, so their per-pixel noise
    // does not pass for a seam.
    let values = evaluate_with(&desc, &probes, None, Some((7, 7)));
    let session = SceneSession::new(&desc, 64, 36).unwrap_or_else(|e| panic!("{e}"));
    let points: Vec<ReferencePoint> = paths
        .iter()
        .map(|&position| ReferencePoint {
            position,
            normal: Vec3::Y,
        })
        .collect();
    let light = SphereLight {
        center: LIGHT_OF_POINT_SCENE,
        radius: 0.2,
    };
    let settings = ReferenceSettings {
        max_samples: 4096,
        min_samples: 4096,
        seed: 3,
    };
    let reference = sphere_light_visibility(&session.reference_scene(), &light, &points, &settings, &|_| {});
    let (mut penumbra_paths, mut seam, mut jump, mut reference_jump) = (0, 0.0f32, 0.0f32, 0.0f32);
    for (v, r) in values.chunks(4).zip(reference.chunks(4)) {
        penumbra_paths += usize::from((0.05..0.95).contains(&r[1].value));
        let step = |i: usize| (v[i + 1] - v[i]).abs();
        seam = seam.max(step(1) - step(0).max(step(2)));
        jump = jump.max(step(1));
        reference_jump = reference_jump.max((r[2].value - r[1].value).abs());
    }
    assert!(
        penumbra_paths >= 20,
        "{mode}: only {penumbra_paths} paths cross a penumbra"
    );
    (seam, jump, reference_jump)
}

/// The light of `assets/scenes/point.ron`.
const LIGHT_OF_POINT_SCENE: Vec3 = Vec3::new(0.0, 3.0, 0.0);

// NOTE: measured on lavapipe: PCF 5×5 0.035 at 1024² faces and 0 at 2048², PCSS High 0.008,
// VSM (blurred across faces) 0; the limit is set above the worst of them.
#[test]
fn cube_face_edges_leave_no_seam_in_the_shadow() {
    for mode in [
        "mode: Pcf, pcf_radius: 2, resolution: 1024",
        "mode: Pcf, pcf_radius: 2, resolution: 2048",
        "mode: Pcss, pcss_quality: High, resolution: 1024",
        "mode: Vsm, vsm_blur: 4, resolution: 1024",
    ] {
        let (seam, jump, reference) = seams(mode);
        eprintln!(
            "{mode}: seam {seam:.4}; largest step across the face edge {jump:.4}, the reference's {reference:.4}"
        );
        assert!(
            seam <= 0.05,
            "{mode}: the step across a face edge exceeds its neighbours by {seam:.4}"
        );
    }
}
