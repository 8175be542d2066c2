//! The viewer without a window (`--offscreen`): the same frames, inspector included, drawn
//! into a texture made like a swapchain image, with their GPU times and wall time recorded;
//! and the options it refuses.

use std::path::Path;

use penumbra::viewer::{ViewerError, ViewerOptions, run};

/// Checks that an offscreen run of the default scene draws every frame asked for, records a
/// GPU time per frame and its wall time, and that its screenshot shows the inspector's dark
/// panel on the left and the scene, brighter, on the right.
#[test]
fn an_offscreen_viewer_draws_the_scene_and_the_inspector() {
    let screenshot = std::env::temp_dir().join(format!("penumbra-offscreen-{}.png", std::process::id()));
    let options = ViewerOptions {
        width: 480,
        height: 270,
        exit_after: Some(3),
        screenshot: Some(screenshot.clone()),
        offscreen: true,
        walk: Some(0.5),
        ..ViewerOptions::default()
    };
    let summary = run(Path::new("assets/scenes/default.ron"), options).unwrap_or_else(|e| {
        panic!("the offscreen viewer failed: {e}\nIt needs a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers).")
    });
    println!("{summary:?}");
    assert_eq!((summary.frames, summary.ticks), (3, 3), "{summary:?}");
    assert_eq!(summary.surface_recoveries, 0);
    assert_eq!(summary.gpu_ms.len(), 3, "one GPU time per frame: {:?}", summary.gpu_ms);
    assert!(
        summary.median_gpu_ms(0).is_some_and(|m| m > 0.0),
        "no frame's GPU time arrived: {:?}",
        summary.gpu_ms
    );
    assert!(summary.elapsed.as_secs_f64() > 0.0, "{summary:?}");
    let image = image::open(summary.screenshot.as_ref().expect("a screenshot"))
        .expect("the screenshot is a PNG")
        .to_rgb8();
    assert_eq!(image.dimensions(), (480, 270));
    let mean = |x0: u32, x1: u32| {
        let (mut sum, mut n) = (0.0, 0.0);
        for y in 0..image.height() {
            for x in x0..x1 {
                let p = image.get_pixel(x, y);
                sum += (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])) / 3.0;
                n += 1.0;
            }
        }
        sum / n
    };
    let (panel, scene) = (mean(0, 60), mean(360, 480));
    println!("panel mean {panel:.1}, scene mean {scene:.1}");
    assert!(panel < 60.0, "no inspector panel on the left (mean {panel})");
    assert!(
        scene > panel + 40.0,
        "no scene on the right (mean {scene}, panel {panel})"
    );
    let _ = std::fs::remove_file(&screenshot);
}

/// Checks that an offscreen run without a frame count is refused, before any device is
/// opened, with what it needs.
#[test]
fn an_offscreen_viewer_needs_a_frame_count() {
    let options = ViewerOptions {
        offscreen: true,
        ..ViewerOptions::default()
    };
    match run(Path::new("assets/scenes/default.ron"), options) {
        Err(e @ ViewerError::Options(_)) => assert_eq!(
            e.to_string(),
            "invalid viewer options: an offscreen viewer needs a frame count (`--exit-after N`)"
        ),
        other => panic!("expected an options error, got {other:?}"),
    }
}
