//! Diffuse transmission (lavapipe): a thin double-sided surface with `transmission` shows on
//! its shaded side the light its lit side receives, shadowed as the lit side is, through
//! every path its shadow can take (the compute resolve after the prepass, the lighting pass's
//! own filters without it, alpha-to-coverage under MSAA); without transmission the shaded side
//! keeps the ambient light alone. Out-of-range values are scene errors.

use glam::Vec3;
use image::RgbaImage;
use penumbra::render::{DepthPrepass, Msaa, RenderOptions};
use penumbra::scene::SceneDesc;

mod common;

use common::{plane_colour, still_frame as render};

/// Three 1.5 m planes seen from below with a low sun above them (n·l = 0.36): an opaque one and an
/// alpha-masked one passing half the light through, and one passing none. A small slab 0.3 m
/// above each casts a 0.4 m square of shadow onto the middle of its plane's lit side. There
/// is no depth bias, so only a shadow lookup offset along the normal of the lit side (the
/// shaded side's turned over) misses the plane itself.
const LEAVES: &str = r#"Scene(
    camera: (position: (0, -5, 0), target: (0, 0, 0), up: (0, 0, -1), fov: 70, near: 0.1, far: 100),
    sun: (direction: (0.9, -0.35, 0.2), illuminance: 3.0),
    ambient: (0.05, 0.05, 0.05),
    shadows: (mode: Pcf, cascade_count: 1, resolution: 4096, max_distance: 12, slope_bias: 0, bias_clamp: 0, normal_offset: 5),
    materials: {
        "thin": (base_color: (0.8, 0.8, 0.8, 1), double_sided: true, transmission: 0.5),
        "leaf": (base_color: (0.8, 0.8, 0.8, 1), alpha: Mask(0.5), transmission: 0.5),
        "solid": (base_color: (0.8, 0.8, 0.8, 1), double_sided: true),
        "slab": (base_color: (0.8, 0.8, 0.8, 1)),
    },
    objects: [
        (shape: Plane(size: (1.5, 1.5)), material: "thin", translation: (-2, 0, 0)),
        (shape: Plane(size: (1.5, 1.5)), material: "leaf", translation: (0, 0, 0)),
        (shape: Plane(size: (1.5, 1.5)), material: "solid", translation: (2, 0, 0)),
        (shape: Cuboid(size: (0.4, 0.02, 0.4)), material: "slab", translation: (-2.77, 0.3, -0.17)),
        (shape: Cuboid(size: (0.4, 0.02, 0.4)), material: "slab", translation: (-0.77, 0.3, -0.17)),
        (shape: Cuboid(size: (0.4, 0.02, 0.4)), material: "slab", translation: (1.23, 0.3, -0.17)),
    ],
)"#;

/// Mean sRGB level (of the three channels) of the pixels of one region of the plane at `x`,
/// and their count.
fn level(image: &RgbaImage, positions: &[Vec3], x: f32, shadowed: bool) -> (f32, usize) {
    let (colour, n) = plane_colour(image, positions, x, shadowed);
    (colour.iter().sum::<f32>() / 3.0, n)
}

#[test]
fn a_thin_surface_shows_the_light_and_shadow_of_its_other_side() {
    let desc = SceneDesc::from_str(LEAVES, "leaves.ron").unwrap_or_else(|e| panic!("{e}"));
    let size = (640, 320);
    let positions = render(&desc, size, RenderOptions::default(), true)
        .analysis
        .expect("analysis targets")
        .position;
    for (msaa, depth_prepass) in [
        (Msaa::Off, DepthPrepass::On),
        (Msaa::Off, DepthPrepass::Off),
        (Msaa::Sample4, DepthPrepass::On),
    ] {
        let options = RenderOptions {
            msaa,
            depth_prepass,
            ..RenderOptions::default()
        };
        let image = render(&desc, size, options, false).image;
        let what = format!("MSAA {msaa:?}, prepass {depth_prepass:?}");
        let (solid_sun, n) = level(&image, &positions, 2.0, false);
        let (solid_shadow, m) = level(&image, &positions, 2.0, true);
        assert!(n > 1000 && m > 50, "{what}: {n} and {m} pixels of the solid plane");
        // Without transmission the underside has the ambient light alone, sun or not.
        assert!(
            (solid_sun - solid_shadow).abs() <= 2.0,
            "{what}: solid underside {solid_sun} in the sun, {solid_shadow} under the slab"
        );
        for (x, name) in [(-2.0, "thin"), (0.0, "masked leaf")] {
            let (sun, n) = level(&image, &positions, x, false);
            let (shadow, m) = level(&image, &positions, x, true);
            eprintln!(
                "{what} {name}: {sun:.1} in the sun ({n} px), {shadow:.1} under the slab ({m} px), solid {solid_sun:.1}"
            );
            assert!(n > 1000 && m > 50, "{what} {name}: {n} and {m} pixels");
            assert!(
                sun > solid_sun + 60.0,
                "{what} {name}: the underside in the sun ({sun}) is not lit through (solid: {solid_sun})"
            );
            assert!(
                (shadow - solid_shadow).abs() <= 3.0,
                "{what} {name}: under the slab ({shadow}) it should have the ambient light alone ({solid_shadow})"
            );
        }
    }
}

#[test]
fn transmission_out_of_range_is_a_scene_error() {
    let text = LEAVES.replace(
        "transmission: 0.5),\n        \"leaf\"",
        "transmission: 1.5),\n        \"leaf\"",
    );
    let err = SceneDesc::from_str(&text, "leaves.ron").unwrap_err().to_string();
    assert!(
        err.starts_with("leaves.ron:7:84:")
            && err.contains(
                "expected a diffuse transmission from 0 to 1 for `materials[\"thin\"].transmission`, found 1.5"
            ),
        "{err}"
    );
}
