//! The depth prepass kept from the frame before (lavapipe): a still frame draws no prepass,
//! and its image equals, pixel for pixel, the image of a renderer that draws the prepass every
//! frame (`prepass_reuse` off); so do the frames after a box moves and after the camera moves,
//! which draw it again. In the 100k field (occlusion culling in two phases) the kept frames
//! draw only the early phase's list and still equal the redrawn ones; animated skinned
//! meshes, posed every frame, never keep it.

mod common;

use bevy_app::App;
use bevy_ecs::entity::Entity;
use bevy_ecs::query::With;
use common::{INSTALL, spawn_box, still_scene};
use glam::{Vec3, Vec4};
use penumbra::ecs::{AnimationPlayer, Camera3d, Transform};
use penumbra::render::{DepthPrepass, RenderOptions, Renderer};

/// `scene` at `width × height` with the prepass on (and kept from frame to frame when
/// `reuse`), before its first frame.
fn app(scene: &str, (width, height): (u32, u32), reuse: bool) -> App {
    let mut app = still_scene(Renderer::headless(width, height).expect(INSTALL), scene);
    app.insert_resource(RenderOptions {
        depth_prepass: DepthPrepass::On,
        prepass_reuse: reuse,
        ..RenderOptions::default()
    });
    app
}

fn renderer(app: &App) -> &Renderer {
    app.world().resource::<Renderer>()
}

/// Renders a frame of both apps; returns whether the first kept its prepass, after checking
/// the second (reuse off) did not and that their images are equal pixel for pixel.
fn frame(kept: &mut App, drawn: &mut App, what: &str) -> bool {
    kept.update();
    drawn.update();
    assert!(
        !renderer(drawn).last_report.prepass_kept,
        "{what}: reuse off kept the prepass"
    );
    let (a, b) = (renderer(kept).read_image(), renderer(drawn).read_image());
    let differ = a.pixels().zip(b.pixels()).filter(|(x, y)| x != y).count();
    assert_eq!(differ, 0, "{what}: {differ} pixels differ from the prepass drawn again");
    renderer(kept).last_report.prepass_kept
}

/// Applies `f` to the camera's transform in both apps.
fn move_cameras(apps: [&mut App; 2], f: impl Fn(&mut Transform)) {
    for app in apps {
        let world = app.world_mut();
        let mut cameras = world.query_filtered::<&mut Transform, With<Camera3d>>();
        for mut t in cameras.iter_mut(world) {
            f(&mut t);
        }
    }
}

/// Moves both apps' cameras by `step` and renders two frames: the first draws the prepass
/// again, the second keeps it (both checked against the app that redraws it).
fn step_then_stand([kept, drawn]: [&mut App; 2], step: Vec3) {
    move_cameras([kept, drawn], |t| t.translation += step);
    assert!(!frame(kept, drawn, "camera moved"), "a moved camera draws the prepass");
    assert!(frame(kept, drawn, "still after the camera"), "kept again once still");
}

/// The default scene with a movable box in both apps; returns the boxes.
fn with_box(apps: [&mut App; 2]) -> [Entity; 2] {
    apps.map(|app| {
        spawn_box(
            app.world_mut(),
            Vec3::new(1.0, 2.0, 1.0),
            Vec4::new(0.9, 0.5, 0.2, 1.0),
            Vec3::new(0.5, 1.0, -2.0),
        )
    })
}

#[test]
fn still_frames_keep_the_prepass_and_draw_the_same_image() {
    let scene = "assets/scenes/default.ron";
    let (mut kept, mut drawn) = (app(scene, (320, 180), true), app(scene, (320, 180), false));
    let boxes = with_box([&mut kept, &mut drawn]);
    let still: Vec<bool> = (0..3).map(|_| frame(&mut kept, &mut drawn, "still")).collect();
    assert_eq!(still, [false, true, true], "kept per still frame");
    let report = &renderer(&kept).last_report;
    assert!(report.deferred_lighting, "the kept normals and ids lit the frame");
    let before = renderer(&kept).read_image();

    for (app, e) in [(&mut kept, boxes[0]), (&mut drawn, boxes[1])] {
        app.world_mut().get_mut::<Transform>(e).expect("the box").translation = Vec3::new(-0.5, 1.0, -6.0);
    }
    assert!(
        !frame(&mut kept, &mut drawn, "box moved"),
        "a moved box draws the prepass"
    );
    let moved = renderer(&kept).read_image();
    let changed = before.pixels().zip(moved.pixels()).filter(|(x, y)| x != y).count();
    eprintln!("{changed} pixels changed by the move");
    // Measured: 1 133 (as in the instance patch test's move).
    assert!(
        changed > 370,
        "the move changed only {changed} pixels: nothing was judged"
    );
    assert!(
        frame(&mut kept, &mut drawn, "still after the move"),
        "kept again once still"
    );

    step_then_stand([&mut kept, &mut drawn], Vec3::new(0.2, 0.0, -0.3));
}

#[test]
fn the_field_keeps_its_occluded_prepass() {
    let scene = "assets/scenes/field.ron";
    let (mut kept, mut drawn) = (app(scene, (160, 90), true), app(scene, (160, 90), false));
    let still: Vec<bool> = (0..3).map(|_| frame(&mut kept, &mut drawn, "field still")).collect();
    assert_eq!(still, [false, true, true], "kept per still frame");
    let (early, late) = renderer(&kept).read_occlusion_drawn().expect("occlusion culling ran");
    let redrawn = renderer(&drawn).read_occlusion_drawn().expect("occlusion culling ran");
    eprintln!("kept frame: {early} + {late} instances listed; redrawn: {redrawn:?}");
    assert_eq!(late, 0, "a kept frame runs no late phase");
    assert_eq!(early, redrawn.0 + redrawn.1, "the early list holds every instance seen");
    // Measured: 67 285 instances listed at 160×90.
    assert!(early > 22_000, "only {early} instances were listed: little was judged");

    step_then_stand([&mut kept, &mut drawn], Vec3::new(0.0, 0.0, -0.37));
}

#[test]
fn posed_skinned_meshes_never_keep_the_prepass() {
    let mut app = app("assets/scenes/walkers.ron", (160, 90), true);
    let mut posed = 0;
    for _ in 0..4 {
        app.update();
        let report = &renderer(&app).last_report;
        posed += report.skinned_meshes_posed;
        if report.skinned_meshes_posed > 0 {
            assert!(
                !report.prepass_kept,
                "a frame that posed skinned meshes kept the prepass"
            );
        }
    }
    eprintln!("{posed} skinned meshes posed over four frames");
    // Measured: 48 (12 meshes a frame).
    assert!(
        posed >= 16,
        "only {posed} meshes were posed over four frames: nothing was judged"
    );

    let world = app.world_mut();
    let mut players = world.query::<&mut AnimationPlayer>();
    for mut p in players.iter_mut(world) {
        p.paused = true;
    }
    let kept: Vec<bool> = (0..3)
        .map(|_| {
            app.update();
            renderer(&app).last_report.prepass_kept
        })
        .collect();
    assert_eq!(kept[1..], [true, true], "paused walkers keep the prepass: {kept:?}");
}
