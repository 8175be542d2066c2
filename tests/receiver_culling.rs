//! Casters whose shadow cannot reach a visible receiver are not drawn: with receiver-bounded
//! culling the cascades draw fewer casters on scenes looking at the horizon, and every image
//! is identical to the one drawn with every caster of the cascade boxes.

mod common;

use bevy_app::App;
use common::still_scene;
use image::RgbaImage;
use penumbra::ecs::ShadowStats;
use penumbra::ecs::receiver_culling::ShadowCulling;
use penumbra::render::Renderer;

/// Renders `scene` at 240×135; returns the image and the casters drawn per shadow view.
fn render(scene: &str, receivers: bool) -> (RgbaImage, Vec<u32>) {
    let renderer = Renderer::headless(240, 135)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app: App = still_scene(renderer, scene);
    app.insert_resource(ShadowCulling {
        receivers,
        ..Default::default()
    });
    app.update();
    let casters = app.world().resource::<ShadowStats>().casters_per_view.clone();
    (app.world().resource::<Renderer>().read_image(), casters)
}

#[test]
fn culling_to_the_receivers_changes_no_pixel_and_draws_fewer_casters() {
    let mut saved = 0;
    for scene in [
        "assets/scenes/default.ron",
        "assets/bench/boxes.ron",
        "assets/bench/field.ron",
        "assets/scenes/lights.ron",
        "assets/scenes/thin.ron",
    ] {
        let (culled, few) = render(scene, true);
        let (full, all) = render(scene, false);
        let differing = culled.pixels().zip(full.pixels()).filter(|(a, b)| a != b).count();
        assert_eq!(
            differing, 0,
            "{scene}: {differing} pixels differ; casters {few:?} against {all:?}"
        );
        assert_eq!(few.len(), all.len(), "{scene}");
        assert!(
            few.iter().zip(&all).all(|(f, a)| f <= a),
            "{scene}: {few:?} against {all:?}"
        );
        saved += all.iter().sum::<u32>() - few.iter().sum::<u32>();
    }
    // Looking along the ground, the far cascades' boxes reach high over the horizon where
    // nothing receives: some casters there are left out.
    assert!(saved > 0, "no caster was left out in any scene");
}
