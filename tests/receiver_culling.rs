//! Casters whose shadow cannot reach a visible receiver are not drawn: with receiver-bounded
//! culling the cascades draw fewer casters on scenes looking at the horizon, and every image
//! is identical to the one drawn with every caster of the cascade boxes, on a still camera
//! and on every frame of a walk (where the receivers' bounds are held over cells of the
//! camera's position); the held bounds cull with exactly the volumes of a fresh app at the
//! walk's end. Cascades are held, not scrolled (scrolling ones keep their whole boxes).

mod common;

use bevy_app::App;
use common::{camera_transform, move_camera, still_scene};
use glam::Vec3;
use image::RgbaImage;
use penumbra::app::PreparedScene;
use penumbra::ecs::ShadowStats;
use penumbra::ecs::components::ViewportSize;
use penumbra::ecs::receiver_culling::ShadowCulling;
use penumbra::ecs::view_list::{CullVolume, ShadowViews};
use penumbra::ecs::{ShadowPlugin, Transform};
use penumbra::render::Renderer;
use penumbra::scene::SceneDesc;

/// `scene` in a 240×135 headless app culling to the receivers or not, before its first frame.
fn scene_app(scene: &str, receivers: bool) -> App {
    let renderer = Renderer::headless(240, 135)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app: App = still_scene(renderer, scene);
    app.insert_resource(ShadowCulling {
        receivers,
        ..Default::default()
    });
    common::hold_cascades(&mut app);
    app
}

/// The image of `app`'s last frame and the casters drawn per shadow view.
fn drawn(app: &App) -> (RgbaImage, Vec<u32>) {
    let casters = app.world().resource::<ShadowStats>().casters_per_view.clone();
    (app.world().resource::<Renderer>().read_image(), casters)
}

/// Renders `scene` at 240×135; returns the image and the casters drawn per shadow view.
fn render(scene: &str, receivers: bool) -> (RgbaImage, Vec<u32>) {
    let mut app = scene_app(scene, receivers);
    app.update();
    drawn(&app)
}

/// One step of the walks: 0.37 m towards −z, drifting 0.05 m along x.
fn step(app: &mut App) {
    move_camera(app, |t| t.translation += Vec3::new(0.05, 0.0, -0.37));
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

#[test]
fn a_walk_culled_to_held_receiver_bounds_draws_what_every_caster_draws() {
    let scene = "assets/bench/field.ron";
    let (mut culled, mut full) = (scene_app(scene, true), scene_app(scene, false));
    let (mut saved, mut judged) = (0, 0);
    for frame in 0..30 {
        for app in [&mut culled, &mut full] {
            step(app);
            app.update();
        }
        let ((a, few), (b, all)) = (drawn(&culled), drawn(&full));
        let differing = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
        assert_eq!(differing, 0, "frame {frame}: {differing} pixels differ");
        saved += all.iter().sum::<u32>() - few.iter().sum::<u32>();
        judged += a.pixels().count();
    }
    println!("{judged} pixels judged, {saved} caster draws left out over the walk");
    assert!(saved > 0, "no caster was left out on the walk");
}

/// `scene` in an app of the shadow systems alone (no renderer) at 1920×1080, culling to the
/// receivers or not, its camera moved to `at` (where given), after its first frame.
fn systems_app(scene: &str, receivers: bool, at: Option<Transform>) -> App {
    let desc = SceneDesc::load(scene).expect("the scene loads");
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    app.insert_resource(ShadowCulling {
        receivers,
        ..Default::default()
    });
    app.insert_resource(ViewportSize {
        width: 1920,
        height: 1080,
    });
    PreparedScene::new(&desc)
        .expect("the scene spawns")
        .spawn(app.world_mut());
    common::hold_cascades(&mut app);
    if let Some(at) = at {
        move_camera(&mut app, |t| *t = at);
    }
    app.update();
    app
}

/// The cull volumes of `app`'s cascade views.
fn cascade_volumes(app: &App) -> Vec<CullVolume> {
    let views = &app.world().resource::<ShadowViews>().views;
    let boxes = views
        .iter()
        .map(|v| v.cull)
        .filter(|c| matches!(c, CullVolume::LightBox { .. }));
    boxes.collect()
}

#[test]
fn held_receiver_bounds_cull_as_a_fresh_app_at_the_same_pose() {
    let scene = "assets/scenes/default.ron";
    let mut walked = systems_app(scene, true, None);
    let mut shrunk = 0;
    for frame in 0..40 {
        step(&mut walked);
        walked.update();
        let at = camera_transform(&mut walked);
        let (fresh, whole) = (systems_app(scene, true, Some(at)), systems_app(scene, false, Some(at)));
        let (kept, made) = (cascade_volumes(&walked), cascade_volumes(&fresh));
        assert_eq!(kept.len(), 4, "the field's cascades");
        assert_eq!(
            kept, made,
            "frame {frame}: the walked app culls with other volumes than a fresh one"
        );
        shrunk += kept
            .iter()
            .zip(cascade_volumes(&whole))
            .filter(|(k, w)| *k != w)
            .count();
    }
    println!("{shrunk} of 160 cascade volumes shrunk to the receivers");
    assert!(shrunk > 0, "no volume shrunk: the walk judged nothing");
}
