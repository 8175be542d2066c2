//! The lighting pass's fragment invocations are counted (a pipeline-statistics query), the
//! measure that shows the depth prepass shading each covered pixel once. Lavapipe counts
//! every rasterised fragment before its depth test (whole 2×2 quads included), so here the
//! count is checked for what it is: at least the covered pixels, never more with the prepass
//! than without; the one-shading-per-pixel figure is measured on a GPU (docs/benchmarks.md,
//! `penumbra render --count-fragments`).

use bevy_app::App;
use penumbra::app::{headless_app, spawn_scene};
use penumbra::render::{DepthPrepass, RenderOptions, Renderer};
use penumbra::scene::SceneDesc;

/// (fragment invocations of the lighting pass, covered pixels) for `scene` at 320×180.
fn count(scene: &str, prepass: DepthPrepass) -> (u64, u64) {
    let renderer = Renderer::headless_with_analysis(320, 180)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app: App = headless_app(renderer);
    app.insert_resource(RenderOptions {
        depth_prepass: prepass,
        ..RenderOptions::default()
    });
    let counting = app.world_mut().resource_mut::<Renderer>().count_forward_fragments(true);
    assert!(
        counting,
        "this test needs pipeline-statistics queries (lavapipe has them)"
    );
    let desc = SceneDesc::load(scene).expect("scene loads");
    spawn_scene(app.world_mut(), &desc).expect("scene spawns");
    app.update();
    let renderer = app.world().resource::<Renderer>();
    let fragments = renderer.last_report.forward_fragments.expect("counted");
    let analysis = renderer.read_analysis().expect("analysis targets");
    let covered = analysis.position.iter().filter(|p| p.x.is_finite()).count() as u64;
    (fragments, covered)
}

#[test]
fn fragment_invocations_are_counted_with_and_without_the_prepass() {
    for scene in [
        "assets/scenes/default.ron",
        "assets/bench/boxes.ron",
        "assets/scenes/garden.ron",
    ] {
        let (with, covered) = count(scene, DepthPrepass::On);
        let (without, covered_without) = count(scene, DepthPrepass::Off);
        assert_eq!(covered, covered_without, "{scene}");
        assert!(covered > 320 * 180 / 3, "{scene}: only {covered} pixels covered");
        assert!(
            with >= covered,
            "{scene}: {with} invocations for {covered} covered pixels"
        );
        assert!(
            with <= without,
            "{scene}: {with} invocations with the prepass, {without} without"
        );
    }
}
