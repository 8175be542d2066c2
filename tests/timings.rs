//! GPU timings arrive without the frame loop waiting for them: frames are numbered, each
//! frame's passes come back under its number (or the frame is counted as untimed when every
//! slot of the ring was busy), and a headless render, which waits for them frame by frame,
//! reports every frame.

use penumbra::app::{RenderRequest, headless_app, render_scene_with, spawn_scene};
use penumbra::render::{DepthPrepass, RenderOptions, Renderer};
use penumbra::scene::SceneDesc;

fn default_scene() -> SceneDesc {
    SceneDesc::load("assets/scenes/default.ron").expect("default scene loads")
}

#[test]
fn every_frame_is_timed_or_counted_and_numbered() {
    let renderer = Renderer::headless(64, 36)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    assert!(
        renderer.gpu.timestamps,
        "this test needs timestamp queries (lavapipe has them)"
    );
    let mut app = headless_app(renderer);
    // Every view and the prepass drawn every frame, so every frame has the same passes.
    app.insert_resource(RenderOptions {
        depth_prepass: DepthPrepass::On,
        shadow_cache: false,
        prepass_reuse: false,
        ..RenderOptions::default()
    });
    spawn_scene(app.world_mut(), &default_scene()).expect("default scene spawns");
    const FRAMES: u64 = 8;
    for _ in 0..FRAMES {
        app.update();
    }
    let mut renderer = app.world_mut().resource_mut::<Renderer>();
    assert_eq!(renderer.frames_rendered(), FRAMES);
    let mut timings = renderer.take_timings();
    timings.extend(renderer.wait_for_timings());
    let untimed = renderer.untimed_frames();
    assert_eq!(
        timings.len() as u64 + untimed,
        FRAMES,
        "timed {timings:?}, untimed {untimed}"
    );
    assert!(timings.len() >= 3, "only {} of {FRAMES} frames timed", timings.len());
    let frames: Vec<u64> = timings.iter().map(|t| t.frame).collect();
    assert!(frames.windows(2).all(|w| w[0] < w[1]), "out of order: {frames:?}");
    assert!(frames.iter().all(|&f| f < FRAMES));
    for t in &timings {
        let names: Vec<&str> = t.passes.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "shadow cascade 0",
                "shadow cascade 1",
                "shadow cascade 2",
                "shadow cascade 3",
                "depth prepass",
                "visibility resolve",
                "deferred lighting",
                "forward"
            ],
            "frame {}",
            t.frame
        );
        assert!(t.passes.iter().all(|p| p.ms.is_finite() && p.ms >= 0.0), "{t:?}");
    }
    // Nothing is left: a second wait returns nothing.
    assert!(renderer.wait_for_timings().is_empty());
    // The last report carries the newest timings that arrived, with their frame number.
    let report = &renderer.last_report;
    assert!(report.passes.is_empty() || report.timed_frame < FRAMES);
}

#[test]
fn a_headless_render_reports_the_timings_of_each_of_its_frames() {
    let request = RenderRequest {
        width: 64,
        height: 36,
        frames: 4,
        tweak: None,
        analysis: false,
        options: Default::default(),
        shadow_budget: None,
        count_fragments: false,
        camera_lod: None,
        camera_motion: Default::default(),
    };
    let result = render_scene_with(&default_scene(), &request).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(result.frames.len(), 4);
    let numbers: Vec<u64> = result.frames.iter().map(|f| f.timed_frame).collect();
    assert_eq!(numbers, [0, 1, 2, 3]);
    // A headless render waits for each frame's timings: every frame is timed.
    let timed = result.frames.iter().filter(|f| !f.passes.is_empty()).count();
    assert_eq!(timed, 4, "only {timed} of 4 frames came back with timings");
    assert_eq!(result.report, result.frames[3]);
}
