//! Multi-draw (lavapipe): batches of different meshes that bind nothing between them are one
//! `multi_draw_indexed_indirect`, and the image equals the one drawn batch by batch, pixel for
//! pixel, with the same draws.

mod common;

use bevy_app::App;
use common::still_scene;
use penumbra::render::{RenderOptions, Renderer};

/// The scene drawn one frame with `multi_draw`; the image, the draw commands, the shadow draw
/// commands and the draws.
fn frame(scene: &str, multi_draw: bool) -> (image::RgbaImage, u32, u32, u32) {
    let renderer = Renderer::headless(320, 180)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app: App = still_scene(renderer, scene);
    // NOTE: without occlusion culling, whose phases always draw from GPU-written arguments.
    app.insert_resource(RenderOptions {
        multi_draw,
        shadow_cache: false,
        occlusion_culling: false,
        ..RenderOptions::default()
    });
    app.update();
    let renderer = app.world().resource::<Renderer>();
    let report = &renderer.last_report;
    (
        renderer.read_image(),
        report.draw_calls,
        report.shadow_draw_calls,
        report.draws,
    )
}

#[test]
fn one_multi_draw_per_run_draws_the_same_image() {
    // The boxes scene binds one material per pass (measured 8 commands for 47 draws); the
    // garden's ferns bind theirs between runs (16 for 30).
    for (scene, fewer) in [("assets/bench/boxes.ron", 5), ("assets/scenes/garden.ron", 1)] {
        let (multi, calls, shadow_calls, draws) = frame(scene, true);
        let (single, single_calls, single_shadow_calls, single_draws) = frame(scene, false);
        eprintln!(
            "{scene}: {calls} commands ({shadow_calls} shadow) for {draws} draws; one by one {single_calls} ({single_shadow_calls})"
        );
        assert_eq!(draws, single_draws, "{scene}: the same draws");
        assert_eq!(
            single_calls, single_draws,
            "{scene}: one command per draw without multi-draw"
        );
        assert!(draws >= 20, "{scene}: only {draws} draws compared");
        assert!(
            calls * fewer < single_calls,
            "{scene}: {calls} commands against {single_calls}"
        );
        assert!(
            shadow_calls < single_shadow_calls,
            "{scene}: shadow commands {shadow_calls} against {single_shadow_calls}"
        );
        let differing = multi.pixels().zip(single.pixels()).filter(|(a, b)| a != b).count();
        assert_eq!(differing, 0, "{scene}: {differing} pixels differ");
    }
}
