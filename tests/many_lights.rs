//! Scenes with thousands of lights, on a real wgpu device (lavapipe in CI): 3,000 spot and
//! point lights render (the light list grows with the scene, and GPU timing spreads its
//! queries over sets within wgpu's limit); the last light in the list lights the image; the
//! lights past the shadow budget are reported in one warning per kind.
//!
//! NOTE: lavapipe stops a shader's loops after 65,535 iterations in all (llvmpipe's loop
//! limiter), which the per-pixel light loops reach past about 4,000 lights; GPUs have no such
//! limit (10,000 lights: docs/benchmarks.md).

mod common;

use common::INSTALL;
use penumbra::app::{RenderRequest, render_scene_with};
use penumbra::render::RenderOptions;
use penumbra::scene::SceneDesc;

/// 2,999 dim lights over the far half of a 400 m ground, then one strong red point light over
/// its middle.
fn scene() -> SceneDesc {
    let mut lights = Vec::new();
    for i in 0..2_999 {
        let x = -195.0 + (i % 100) as f32 * 3.9;
        let z = -195.0 + (i / 100) as f32 * 3.9;
        lights.push(if i % 2 == 0 {
            format!("Spot(position: ({x}, 3, {z}), direction: (0, -1, 0), intensity: 0.5, range: 4, outer_angle: 40)")
        } else {
            format!("Point(position: ({x}, 2, {z}), intensity: 0.5, range: 3)")
        });
    }
    lights.push("Point(position: (0, 2, 0), color: (1, 0, 0), intensity: 200, range: 10)".to_string());
    let text = format!(
        r#"Scene(
            camera: (position: (0, 30, 0.1), target: (0, 0, 0), fov: 40, near: 0.1, far: 100),
            ambient: (0.01, 0.01, 0.01),
            lights: [{}],
            materials: {{ "m": (base_color: (0.8, 0.8, 0.8, 1)) }},
            objects: [
                (shape: Plane(size: (400, 400)), material: "m"),
                (shape: Cuboid(size: (1, 1, 1)), material: "m", translation: (60, 0.5, 60)),
            ],
        )"#,
        lights.join(",\n")
    );
    SceneDesc::from_str(&text, "many_lights.ron").unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn three_thousand_lights_render_and_the_last_one_lights_the_image() {
    let desc = scene();
    let frame = render_scene_with(
        &desc,
        &RenderRequest {
            width: 32,
            height: 18,
            frames: 1,
            tweak: None,
            analysis: false,
            options: RenderOptions::default(),
            shadow_budget: None,
            count_fragments: false,
            camera_lod: None,
            camera_motion: Default::default(),
        },
    )
    .unwrap_or_else(|e| panic!("{e} ({INSTALL} if no adapter was found)"));
    let centre = frame.image.get_pixel(16, 9).0;
    assert!(
        centre[0] > 100 && u32::from(centre[0]) > 4 * u32::from(centre[1].max(1)),
        "the image's middle is not lit red by the 3,000th light: {centre:?}"
    );
    // Two warnings name the lights past the budget, one per kind, whatever their number.
    let budget: Vec<&String> = frame.warnings.iter().filter(|w| w.contains("gets no shadow")).collect();
    assert_eq!(budget.len(), 2, "{budget:?}");
    for (kind, more) in [("spot light", 1_500 - 8 - 1), ("point light", 1_500 - 4 - 1)] {
        let line = budget.iter().find(|w| w.starts_with(kind)).expect(kind);
        assert!(
            line.contains(&format!("(the same for {more} more: ")) && line.len() < 400,
            "{line}"
        );
    }
}
