//! A sun's moment shadows with contact hardening (the default) on a real wgpu device
//! (lavapipe in CI), for every moment technique: casters standing on the ground shadow their
//! feet, over a ground that casts and over one that casts nothing, and a penumbra's width
//! follows the sun's angular diameter and the caster's height as the ray-cast truth's does.

mod common;

use common::rays::Aabb;
use common::suns::{
    GROUND, STANDING, TECHNIQUES, TRAVEL, disc_visibility, penumbra_width, probes_near_the_feet, visibility,
};
use glam::Vec3;

/// The largest leak and acne rates at the feet over a ground that casts, per technique:
/// three times what lavapipe measured (0.0155 and 0.0020 for each).
const FEET_LIMITS_GROUND: [(&str, f64, f64); 6] = [
    ("evsm-fp16", 0.046, 0.006),
    ("evsm-fp32", 0.046, 0.006),
    ("evsm4", 0.046, 0.006),
    ("msm-unorm16", 0.046, 0.006),
    ("msm-half", 0.046, 0.006),
    ("msm-fp32", 0.046, 0.006),
];

/// The same over a ground that casts nothing: three times what lavapipe measured (leak
/// 0.0018 for EVSM, 0.0015 for MSM; acne 0.0011 for each).
const FEET_LIMITS_BARE: [(&str, f64, f64); 6] = [
    ("evsm-fp16", 0.0054, 0.0033),
    ("evsm-fp32", 0.0054, 0.0033),
    ("evsm4", 0.0054, 0.0033),
    ("msm-unorm16", 0.0045, 0.0033),
    ("msm-half", 0.0045, 0.0033),
    ("msm-fp32", 0.0045, 0.0033),
];

/// Judges every technique at the feet of [`STANDING`] under a 0.5° sun, with the ground in
/// `boxes` or not: the share of the feet's umbra lit above 0.1 and of their lit ground
/// darkened below 0.9, against `limits` (per technique: leak, acne).
fn judge_feet(boxes: &[Aabb], limits: [(&str, f64, f64); 6]) {
    let probes = probes_near_the_feet();
    let sun = "direction: (-0.6, -0.7, -0.4), angular_diameter: 0.5";
    let truth: Vec<f32> = probes
        .iter()
        .map(|&(p, _)| disc_visibility(&STANDING, TRAVEL, 0.5, p))
        .collect();
    for ((name, settings, device), (limited, leak_limit, acne_limit)) in TECHNIQUES.into_iter().zip(limits) {
        assert_eq!(name, limited);
        let values = visibility(boxes, sun, settings, device, &probes);
        let (mut umbra, mut lit, mut leaks, mut acne) = (0u32, 0u32, 0u32, 0u32);
        for (&t, &v) in truth.iter().zip(&values) {
            if t <= 0.02 {
                umbra += 1;
                leaks += u32::from(v > 0.1);
            } else if t >= 0.98 {
                lit += 1;
                acne += u32::from(v < 0.9);
            }
        }
        let leak = f64::from(leaks) / f64::from(umbra);
        let acne_rate = f64::from(acne) / f64::from(lit);
        println!("{name}: leak {leak:.4} of {umbra} umbra probes, acne {acne_rate:.4} of {lit} lit");
        assert!(
            umbra >= 4_000 && lit >= 4_000,
            "{name}: {umbra} umbra, {lit} lit probes judged"
        );
        assert!(
            leak <= leak_limit,
            "{name}: {leak:.4} of the feet's umbra is lit (limit {leak_limit})"
        );
        assert!(
            acne_rate <= acne_limit,
            "{name}: {acne_rate:.4} of the lit ground is darkened (limit {acne_limit})"
        );
    }
}

#[test]
fn casters_standing_on_a_ground_that_casts_shadow_their_feet() {
    let mut boxes = STANDING.to_vec();
    boxes.push(GROUND);
    judge_feet(&boxes, FEET_LIMITS_GROUND);
}

#[test]
fn casters_standing_on_a_ground_that_casts_nothing_shadow_their_feet() {
    judge_feet(&STANDING, FEET_LIMITS_BARE);
}

#[test]
fn the_penumbra_widens_with_the_suns_diameter_and_the_casters_height() {
    // A 1 m plate 1.5 m and one 3 m over a casting ground, under a sun straight above of 2°
    // and of 3°: probes across the plate's edge at x = 0.5.
    let probes: Vec<(Vec3, Vec3)> = (0..=300)
        .map(|k| (Vec3::new(0.2 + 0.002 * k as f32, 0.0, 0.0), Vec3::Y))
        .collect();
    let travel = Vec3::new(0.0, -1.0, 0.001);
    let cases: Vec<(f32, f32)> = [2.0f32, 3.0].iter().flat_map(|&d| [(d, 1.5f32), (d, 3.0)]).collect();
    let plate = |h: f32| Aabb {
        min: Vec3::new(-0.5, h, -0.5),
        max: Vec3::new(0.5, h + 0.05, 0.5),
    };
    let truth: Vec<f32> = cases
        .iter()
        .map(|&(d, h)| {
            let values: Vec<f32> = probes
                .iter()
                .map(|&(p, _)| disc_visibility(&[plate(h)], travel, d, p))
                .collect();
            penumbra_width(&probes, &values)
        })
        .collect();
    println!("truth: widths {truth:?} (sun, height: {cases:?})");
    // Largest relative error of a width: three times what lavapipe measured (0.211 for each:
    // every width some 20 % narrower than the truth's). MSM in half floats is left out: its
    // quantised moments are too coarse for a receiver lying on a caster, and the ground under
    // the lower plate shadows itself (the device fallback where neither 16-bit unorm nor
    // 32-bit filtering exists).
    let limits = [
        ("evsm-fp16", 0.63),
        ("evsm-fp32", 0.63),
        ("evsm4", 0.63),
        ("msm-unorm16", 0.63),
        ("msm-half", f32::NAN),
        ("msm-fp32", 0.63),
    ];
    for ((name, settings, device), (limited, limit)) in TECHNIQUES.into_iter().zip(limits) {
        assert_eq!(name, limited);
        if limit.is_nan() {
            continue;
        }
        let widths: Vec<f32> = cases
            .iter()
            .map(|&(d, h)| {
                let sun = format!("direction: (0, -1, 0.001), angular_diameter: {d}");
                let values = visibility(&[plate(h), GROUND], &sun, settings, device, &probes);
                penumbra_width(&probes, &values)
            })
            .collect();
        let worst = widths
            .iter()
            .zip(&truth)
            .map(|(w, t)| (w / t - 1.0).abs())
            .fold(0.0f32, f32::max);
        println!("{name}: widths {widths:?}, worst relative error {worst:.3}");
        assert!(
            worst <= limit,
            "{name}: widths {widths:?} against {truth:?} (worst {worst:.3}, limit {limit})"
        );
    }
}
