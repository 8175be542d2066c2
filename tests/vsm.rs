//! Variance shadow maps of spot and point lights on a real wgpu device (lavapipe in CI): a
//! spot light's VSM shadow lands where rays say, and light bleeding — the classic VSM artefact
//! where a receiver under two stacked occluders is lit through the filtered mix of both — is
//! there without light-bleed reduction and gone with it; a spot or point light asked for a
//! sun's moment technique shadows as with VSM.

mod common;

use common::rays::{Aabb, evaluate, scene_with};
use glam::Vec3;

/// Two occluders at different heights that meet, seen from a light at (0, 6, 0): a plate
/// 2 m under the light over x < 0 and one 4.5 m under it over x > 0 (they overlap by 2 cm).
/// The ground from x = −1 to 1 is in the umbra of one or both, and a filter around x = 0
/// mixes both depths: where VSM bleeds.
fn stacked() -> [Aabb; 2] {
    [
        Aabb {
            min: Vec3::new(-3.0, 3.95, -1.5),
            max: Vec3::new(0.02, 4.05, 1.5),
        },
        Aabb {
            min: Vec3::new(-0.02, 1.45, -1.5),
            max: Vec3::new(3.0, 1.55, 1.5),
        },
    ]
}

/// The most light a ground probe from x = −1 to 1 (all in an umbra) gets from `light`.
fn brightest_in_umbra(light: &str) -> f32 {
    let desc = scene_with(&stacked(), light);
    let probes: Vec<(Vec3, Vec3)> = (0..=200)
        .map(|k| (Vec3::new(-1.0 + 0.01 * k as f32, 0.0, 0.1), Vec3::Y))
        .collect();
    let values = evaluate(&desc, &probes);
    values.into_iter().fold(0.0, f32::max)
}

#[test]
fn light_bleed_reduction_keeps_the_umbra_under_stacked_occluders_dark() {
    for (kind, light) in [
        (
            "spot",
            "Spot(position: (0, 6, 0), direction: (0, -1, 0), outer_angle: 60, intensity: 40, range: 20,",
        ),
        ("point", "Point(position: (0, 6, 0), intensity: 40, range: 20,"),
    ] {
        let with = |bleed: f32| {
            brightest_in_umbra(&format!(
                "{light} shadows: (mode: Vsm, vsm_blur: 8, vsm_bleed_reduction: {bleed}, resolution: 1024))"
            ))
        };
        let (raw, reduced) = (with(0.0), with(0.3));
        // NOTE: the bound there is about 0.2 (mean between the plates, variance of both).
        assert!(
            raw > 0.1,
            "{kind}: no bleeding without the reduction ({raw}): the case tests nothing"
        );
        assert!(
            reduced <= 0.01,
            "{kind}: {reduced} of the light bleeds through with a reduction of 0.3"
        );
    }
}

#[test]
fn a_spot_vsm_shadow_lands_where_a_ray_to_the_light_is_blocked() {
    let boxes = [
        Aabb::cube(Vec3::new(0.0, 0.5, 0.0), 1.0),
        Aabb::cube(Vec3::new(-1.5, 1.0, 1.0), 0.4),
        Aabb::cube(Vec3::new(1.2, 2.0, -1.0), 0.6),
    ];
    let light = Vec3::new(1.5, 5.0, 1.0);
    let desc = scene_with(
        &boxes,
        "Spot(position: (1.5, 5, 1), direction: (-0.2, -1, -0.1), intensity: 40, range: 15,
            inner_angle: 40, outer_angle: 50, shadows: (mode: Vsm, vsm_blur: 2, resolution: 1024))",
    );
    // Ground probes every 4 cm within 3 m of the point under the light (inside the cone).
    let probes: Vec<(Vec3, Vec3)> = (-75..=75)
        .flat_map(|i| (-75..=75).map(move |j| (Vec3::new(0.5 + i as f32 * 0.04, 0.0, 0.5 + j as f32 * 0.04), Vec3::Y)))
        .collect();
    let values = evaluate(&desc, &probes);
    let (mut judged, mut shadowed, mut wrong, mut error) = (0, 0, 0, 0.0);
    for (&(p, n), &v) in probes.iter().zip(&values) {
        let blocked_at = |q: Vec3| boxes.iter().any(|b| b.blocks(q + n * 1e-3, light));
        let here = blocked_at(p);
        if [Vec3::X, -Vec3::X, Vec3::Z, -Vec3::Z]
            .iter()
            .any(|&o| blocked_at(p + o * 0.03) != here)
        {
            continue;
        }
        judged += 1;
        shadowed += usize::from(here);
        wrong += usize::from((v < 0.5) != here);
        error += f64::from((v - if here { 0.0 } else { 1.0 }).abs());
    }
    assert!(judged >= 15_000, "only {judged} probes judged");
    assert!(shadowed >= 1_000, "only {shadowed} shadowed probes judged");
    assert!(
        wrong * 200 <= judged,
        "{wrong} of {judged} probes disagree with the rays"
    );
    let mean = error / judged as f64;
    assert!(mean <= 0.01, "mean error {mean:.4} against the rays");
}

#[test]
fn evsm_and_msm_asked_of_spot_and_point_lights_shadow_as_vsm() {
    // Across the stacked plates' shadow and the lit ground past them.
    let probes: Vec<(Vec3, Vec3)> = (0..=160)
        .map(|k| (Vec3::new(-6.0 + 0.1 * k as f32, 0.0, 0.1), Vec3::Y))
        .collect();
    for light in [
        "Spot(position: (0, 6, 0), direction: (0, -1, 0), outer_angle: 70, intensity: 40, range: 20,",
        "Point(position: (0, 6, 0), intensity: 40, range: 20,",
    ] {
        let values = |mode: &str| {
            let desc = scene_with(
                &stacked(),
                &format!("{light} shadows: (mode: {mode}, resolution: 512))"),
            );
            evaluate(&desc, &probes)
        };
        let vsm = values("Vsm");
        let (dark, lit) = (
            vsm.iter().filter(|v| **v < 0.1).count(),
            vsm.iter().filter(|v| **v > 0.9).count(),
        );
        assert!(
            dark >= 20 && lit >= 20,
            "{light}: {dark} dark and {lit} lit probes judged"
        );
        for mode in ["Evsm", "Evsm4", "Msm"] {
            assert_eq!(values(mode), vsm, "{light} with {mode}");
        }
    }
}
