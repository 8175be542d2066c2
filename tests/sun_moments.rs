//! A sun's moment shadows (EVSM2 in 16 and 32 bits, EVSM4, MSM in 16 and 32 bits) on a real
//! wgpu device (lavapipe in CI): the shadow lands where rays say, the umbra under two stacked
//! occluders (where moment techniques bleed light) stays within each technique's stated
//! limit, and a penumbra that is the same all along a line stays continuous where the line
//! crosses from one cascade into the next.

mod common;

use bevy_app::App;
use common::rays::{Aabb, evaluate_on, scene_with};
use common::still_scene;
use glam::Vec3;
use penumbra::math::splits::pssm_splits;
use penumbra::render::Renderer;
use penumbra::settings::{ShadowMode, ShadowSettings};

/// What the device may store moments in.
#[derive(Clone, Copy, PartialEq)]
enum Device {
    /// Whatever it has (lavapipe: 32-bit filtering and 16-bit unorm).
    Full,
    /// Neither 16-bit unorm textures nor 32-bit filtering: 16-bit MSM falls back to half
    /// floats.
    HalfFloatsOnly,
}

/// Every sun moment technique: name, settings, and the device it runs on.
const TECHNIQUES: [(&str, &str, Device); 6] = [
    ("evsm-fp16", "mode: Evsm, moment_precision: Fp16", Device::Full),
    ("evsm-fp32", "mode: Evsm, moment_precision: Fp32", Device::Full),
    ("evsm4", "mode: Evsm4", Device::Full),
    ("msm-unorm16", "mode: Msm, moment_precision: Fp16", Device::Full),
    ("msm-half", "mode: Msm, moment_precision: Fp16", Device::HalfFloatsOnly),
    ("msm-fp32", "mode: Msm, moment_precision: Fp32", Device::Full),
];

/// A ground slab that casts (its top at y = 0): moment techniques need receivers in the map.
const GROUND: Aabb = Aabb {
    min: Vec3::new(-40.0, -0.2, -100.0),
    max: Vec3::new(40.0, 0.0, 40.0),
};

/// A 2 m wall along z: under a sun from +x at 45° its shadow's edge runs along x = −2.1.
const WALL: Aabb = Aabb {
    min: Vec3::new(-0.1, 0.0, -80.0),
    max: Vec3::new(0.1, 2.0, 20.0),
};

/// The focus sun's visibility at `probes` for one technique.
fn visibility(boxes: &[Aabb], sun: &str, settings: &str, device: Device, probes: &[(Vec3, Vec3)]) -> Vec<f32> {
    let light = format!("Directional({sun}, shadows: ({settings}))");
    let desc = scene_with(boxes, &light);
    evaluate_on(&desc, probes, None, |gpu| {
        if device == Device::HalfFloatsOnly {
            gpu.unorm16_moments = false;
            gpu.moments_format = wgpu::TextureFormat::Rgba16Float;
        }
    })
}

#[test]
fn a_sun_moment_shadow_lands_where_a_ray_to_the_sun_is_blocked() {
    let boxes = [
        Aabb::cube(Vec3::new(0.0, 1.0, 0.0), 1.0),
        Aabb::cube(Vec3::new(-1.5, 1.5, 1.0), 0.4),
        Aabb::cube(Vec3::new(1.2, 2.5, -1.0), 0.6),
        GROUND,
    ];
    let towards_sun = Vec3::new(0.3, 1.0, 0.2).normalize();
    let sun = "direction: (-0.3, -1, -0.2), angular_diameter: 0";
    // Ground probes every 4 cm within 3 m of the origin.
    let probes: Vec<(Vec3, Vec3)> = (-75..=75)
        .flat_map(|i| (-75..=75).map(move |j| (Vec3::new(i as f32 * 0.04, 0.0, j as f32 * 0.04), Vec3::Y)))
        .collect();
    for (name, settings, device) in TECHNIQUES {
        let values = visibility(&boxes, sun, &format!("{settings}, moment_blur: 0.02"), device, &probes);
        let (mut judged, mut shadowed, mut wrong, mut error) = (0, 0, 0, 0.0);
        for (&(p, n), &v) in probes.iter().zip(&values) {
            let blocked_at = |q: Vec3| boxes.iter().any(|b| b.blocks(q + n * 1e-3, q + towards_sun * 50.0));
            let here = blocked_at(p);
            // NOTE: the 2 cm blur softens the edge over a few centimetres; those are not judged.
            if [Vec3::X, -Vec3::X, Vec3::Z, -Vec3::Z]
                .iter()
                .any(|&o| blocked_at(p + o * 0.06) != here)
            {
                continue;
            }
            judged += 1;
            shadowed += usize::from(here);
            wrong += usize::from((v < 0.5) != here);
            error += f64::from((v - if here { 0.0 } else { 1.0 }).abs());
        }
        let mean = error / judged as f64;
        println!("{name}: {wrong} of {judged} wrong ({shadowed} shadowed), mean error {mean:.4}");
        assert!(judged >= 15_000, "{name}: only {judged} probes judged");
        assert!(shadowed >= 1_000, "{name}: only {shadowed} shadowed probes judged");
        assert!(
            wrong * 200 <= judged,
            "{name}: {wrong} of {judged} probes disagree with the rays"
        );
        // Measured: 16-bit EVSM2 0.4 % wrong, mean error 0.0065 (contact leaks); the others
        // at most 0.0004.
        assert!(mean <= 0.01, "{name}: mean error {mean:.4} against the rays");
    }
}

#[test]
fn over_a_receiver_that_casts_nothing_only_evsm2_moves_the_shadow_edge() {
    // The wall's shadow edge across the ground, which is not in the map: empty texels hold
    // the box's far depth, whose positive warp outweighs an occluder's in any footprint
    // that reaches them, so EVSM2 lights the umbra's rim as far as its blur and bilinear
    // footprint reach. The negative warp (EVSM4) and MSM's reconstruction do not.
    let sun = "direction: (-1, -1, 0), angular_diameter: 0";
    let probes: Vec<(Vec3, Vec3)> = (0..=60)
        .map(|k| (Vec3::new(-2.6 + 0.01 * k as f32, 0.0, -10.0), Vec3::Y))
        .collect();
    // The truth: the edge at x = −2.1 (the wall's top corner at x = −0.1, 2 m up).
    for (name, settings, device) in [("pcf", "mode: Pcf", Device::Full)].into_iter().chain(TECHNIQUES) {
        let values = visibility(&[WALL], sun, settings, device, &probes);
        let edge = probes
            .iter()
            .zip(&values)
            .find(|(_, v)| **v < 0.5)
            .map_or(f32::NAN, |((p, _), _)| p.x);
        println!("{name}: the shadow starts at x = {edge:.2}");
        // Measured: PCF and MSM at −2.09 to −2.10, EVSM4 at −2.03, EVSM2 at −2.00 to −2.01.
        let limit = match name {
            "evsm-fp16" | "evsm-fp32" => 0.15,
            "evsm4" => 0.1,
            _ => 0.03,
        };
        assert!(
            (edge + 2.1).abs() <= limit,
            "{name}: the edge at {edge}, limit {limit} from −2.1"
        );
    }
}

/// Two plates at different heights that meet under a sun straight above: one 2 m over the
/// ground over x < 0, one 4.5 m over it over x > 0 (overlapping by 2 cm). The ground from
/// x = −1 to 1 is in the umbra of one or both, and a blur around x = 0 mixes both depths.
fn stacked() -> [Aabb; 3] {
    [
        Aabb {
            min: Vec3::new(-3.0, 4.45, -1.5),
            max: Vec3::new(0.02, 4.55, 1.5),
        },
        Aabb {
            min: Vec3::new(-0.02, 1.95, -1.5),
            max: Vec3::new(3.0, 2.05, 1.5),
        },
        GROUND,
    ]
}

#[test]
fn the_umbra_under_stacked_occluders_stays_dark_within_each_techniques_limit() {
    let sun = "direction: (0, -1, 0.001), angular_diameter: 0";
    let probes: Vec<(Vec3, Vec3)> = (0..=200)
        .map(|k| (Vec3::new(-1.0 + 0.01 * k as f32, 0.0, 0.1), Vec3::Y))
        .collect();
    for (name, settings, device) in TECHNIQUES {
        let with = |bleed: f32| {
            let s = format!("{settings}, moment_blur: 0.2, moment_bleed_reduction: {bleed}");
            let values = visibility(&stacked(), sun, &s, device, &probes);
            values.into_iter().fold(0.0, f32::max)
        };
        let (raw, reduced) = (with(0.0), with(0.15));
        println!("{name}: brightest in the umbra {raw:.4} without bleed reduction, {reduced:.4} with 0.15");
        // Measured on lavapipe: EVSM2 in 16 bits 0.16 (its warp, 5.2 over the deepest
        // cascade, is weak); 32-bit EVSM2 and EVSM4 0.04; MSM 0.002 (32 bits) to 0.06 (half
        // floats); with the default reduction of 0.15, at most 0.013.
        let limit = if name == "evsm-fp16" { 0.2 } else { 0.08 };
        assert!(
            raw <= limit,
            "{name}: {raw} of the light bleeds through the umbra (limit {limit})"
        );
        assert!(
            reduced <= 0.02,
            "{name}: {reduced} bleeds through with the default reduction"
        );
        if name == "evsm-fp16" {
            assert!(
                raw > 0.1,
                "{name}: no bleeding without the reduction ({raw}): the case tests nothing"
            );
        }
    }
}

#[test]
fn a_constant_penumbra_stays_continuous_across_cascade_splits() {
    // A long wall along the view (z) casts a shadow whose soft edge runs away from the
    // camera; probes on the ground along the middle of the shadow edge, where the penumbra is
    // the same at every distance, from 3 m to 60 m in front of the camera.
    let wall = [WALL, GROUND];
    let sun = "direction: (-1, -1, 0), angular_diameter: 2";
    // The camera is at (0, 9, 9) looking down the scene; probes along −z.
    let probes: Vec<(Vec3, Vec3)> = (0..=570)
        .map(|k| (Vec3::new(-2.1, 0.0, 6.0 - 0.1 * k as f32), Vec3::Y))
        .collect();
    // The line runs from before the first split to past the third (view depths of the
    // camera at (0, 9, 9) looking at (0, 2, 0)).
    let forward = (Vec3::new(0.0, 2.0, 0.0) - Vec3::new(0.0, 9.0, 9.0)).normalize();
    let depth = |p: Vec3| (p - Vec3::new(0.0, 9.0, 9.0)).dot(forward);
    let splits = pssm_splits(0.1, 100.0, 4, 0.6);
    let (first, last) = (depth(probes[0].0), depth(probes[probes.len() - 1].0));
    assert!(
        first < splits[1] && last > splits[3],
        "{first}..{last} against {splits:?}"
    );
    for (name, settings, device) in TECHNIQUES {
        // NOTE: with `moment_contact_hardening` (off here, as by default) MSM misjudges this
        // penumbra in the last cascade (measured 0.98 where the truth is 0.5): the wide
        // blocker search over a receiver sloping away from the light.
        // NOTE: MSM in half floats is left out: its quantised moments are too coarse for a
        // receiver lying on a caster, and the ground of cascade 2 shadows itself (measured:
        // visibility 0 from view depth 22 to 39 m). That is why 16-bit MSM takes unorm, or
        // 32 bits, wherever the device has either.
        if device == Device::HalfFloatsOnly {
            continue;
        }
        let values = visibility(&wall, sun, settings, device, &probes);
        let jump = values.windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f32::max);
        let (lo, hi) = values.iter().fold((1.0f32, 0.0f32), |(a, b), &v| (a.min(v), b.max(v)));
        println!("{name}: largest step {jump:.4}, values {lo:.3}..{hi:.3}");
        // Measured: steps of at most 0.006 between probes 10 cm apart, and values within
        // 0.41..0.67 (the true penumbra is the same all along the line).
        assert!(jump <= 0.03, "{name}: a step of {jump} along a constant penumbra");
        assert!(
            lo >= 0.3 && hi <= 0.75,
            "{name}: {lo}..{hi} along a penumbra centred on 0.5"
        );
    }
}

#[test]
fn a_still_sun_bakes_its_moments_once_and_again_when_its_settings_change() {
    let renderer = Renderer::headless(64, 36)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    assert!(
        renderer.gpu.timestamps,
        "this test needs timestamp queries (lavapipe has them)"
    );
    let mut app = still_scene(renderer, "assets/scenes/default.ron");
    let world = app.world_mut();
    let mut settings = world.query::<&mut ShadowSettings>();
    for mut s in settings.iter_mut(world) {
        s.mode = ShadowMode::Evsm;
    }
    // Cascades baked in each of `frames` frames (each frame's timings waited for, so every
    // frame is timed).
    let bakes = |app: &mut App, frames: usize| -> Vec<usize> {
        (0..frames)
            .map(|_| {
                app.update();
                let mut renderer = app.world_mut().resource_mut::<Renderer>();
                let mut timings = renderer.take_timings();
                timings.extend(renderer.wait_for_timings());
                assert_eq!(timings.len(), 1, "one frame timed");
                let passes = &timings[0].passes;
                passes
                    .iter()
                    .filter(|p| p.name.starts_with("shadow moments sun"))
                    .count()
            })
            .collect()
    };
    assert_eq!(bakes(&mut app, 5), [4, 0, 0, 0, 0]);
    // A new blur radius changes what every cascade's moments are made from.
    let world = app.world_mut();
    let mut settings = world.query::<&mut ShadowSettings>();
    for mut s in settings.iter_mut(world) {
        s.moment_blur = 0.05;
    }
    assert_eq!(bakes(&mut app, 3), [4, 0, 0]);
    let mut renderer = app.world_mut().resource_mut::<Renderer>();
    assert_eq!(renderer.take_errors(), Vec::<String>::new());
}

/// The width (metres) over which visibility along `probes` (a line across a shadow edge)
/// rises from 0.1 to 0.9.
fn penumbra_width(probes: &[(Vec3, Vec3)], values: &[f32]) -> f32 {
    let at = |level: f32| {
        probes
            .iter()
            .zip(values)
            .find(|(_, v)| **v >= level)
            .map_or(f32::NAN, |((p, _), _)| p.x)
    };
    (at(0.9) - at(0.1)).abs()
}

#[test]
fn msm_contact_hardening_widens_the_penumbra_with_the_casters_height() {
    // A 1 m plate at 0.5 m and one at 3 m over a casting ground, under a 3° sun straight
    // above: their penumbrae on the ground are about 0.03 and 0.16 m wide.
    let sun = "direction: (0, -1, 0.001), angular_diameter: 3";
    let probes: Vec<(Vec3, Vec3)> = (0..=200)
        .map(|k| (Vec3::new(0.3 + 0.002 * k as f32, 0.0, 0.0), Vec3::Y))
        .collect();
    let widths = |settings: &str| -> Vec<f32> {
        [0.5f32, 3.0]
            .iter()
            .map(|&h| {
                let plate = Aabb {
                    min: Vec3::new(-0.5, h, -0.5),
                    max: Vec3::new(0.5, h + 0.05, 0.5),
                };
                let values = visibility(&[plate, GROUND], sun, settings, Device::Full, &probes);
                penumbra_width(&probes, &values)
            })
            .collect()
    };
    let fixed = widths("mode: Msm, moment_blur: 0.01");
    let hardening = widths("mode: Msm, moment_blur: 0.01, moment_contact_hardening: true");
    println!("penumbra widths (0.5 m, 3 m): fixed {fixed:?}, contact hardening {hardening:?}");
    // Measured on lavapipe: fixed 0.016 and 0.016 m; contact hardening 0.024 and 0.198 m
    // (the sun's geometry gives 0.026 and 0.157).
    assert!(
        fixed.iter().chain(&hardening).all(|w| w.is_finite()),
        "an edge was not found"
    );
    assert!(hardening[1] > 2.0 * hardening[0], "no contact hardening: {hardening:?}");
    assert!(
        hardening[1] > 1.5 * fixed[1],
        "the high plate's penumbra did not widen: {hardening:?} against {fixed:?}"
    );
}
