//! Occlusion culling of the camera view (lavapipe): the depth pyramid's every level holds the
//! farthest depth of the level above it; the GPU's test finds hidden exactly the instances the
//! CPU mirror does; and over a camera path through the 100k field the image with occlusion
//! culling equals the image without it, pixel for pixel, while it draws fewer instances.

mod common;

use bevy_app::App;
use bevy_ecs::query::With;
use bevy_transform::components::Transform;
use common::still_scene;
use glam::{Quat, Vec3};
use penumbra::ecs::view::ActiveView;
use penumbra::ecs::{Camera3d, RenderInstances, ViewDrawGroups};
use penumbra::math::occlusion::{CullCamera, Pyramid, hidden};
use penumbra::render::{DepthPrepass, RenderOptions, Renderer};

const SCENE: &str = "assets/scenes/field.ron";

/// The field with the prepass on and occlusion culling `on`.
fn app(on: bool) -> App {
    let renderer = Renderer::headless(320, 180)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = still_scene(renderer, SCENE);
    app.insert_resource(RenderOptions {
        depth_prepass: DepthPrepass::On,
        occlusion_culling: on,
        ..RenderOptions::default()
    });
    app
}

fn renderer(app: &App) -> &Renderer {
    app.world().resource::<Renderer>()
}

#[test]
fn the_pyramid_levels_hold_the_farthest_depth_under_them() {
    let mut app = app(true);
    app.update();
    let gpu = renderer(&app).read_occlusion_pyramid();
    assert_eq!(gpu.len(), 9, "320×180 down to one texel");
    let (w, h, level0) = &gpu[0];
    assert!(level0.iter().any(|&d| d > 0.0), "the depth is empty");
    let cpu = Pyramid::build(level0, *w, *h);
    for (k, (g, c)) in gpu.iter().zip(&cpu.levels).enumerate() {
        assert_eq!((g.0, g.1), (c.0, c.1), "level {k} size");
        let wrong = g.2.iter().zip(&c.2).filter(|(a, b)| a != b).count();
        assert_eq!(wrong, 0, "level {k}: {wrong} texels differ from the CPU's");
    }
}

#[test]
fn the_gpu_hides_what_the_cpu_mirror_hides() {
    let mut app = app(true);
    app.update();
    let world = app.world();
    let r = renderer(&app);
    let instances = world.resource::<RenderInstances>();
    let seen = r.read_occlusion_seen(instances.centers.len());
    let pyramid = Pyramid {
        levels: r.read_occlusion_pyramid(),
    };
    let (camera, _) = world.resource::<ActiveView>().camera.expect("a camera");
    let camera = CullCamera {
        clip_from_view: camera.clip_from_view(),
        view_from_world: camera.view_from_world(),
        near: camera.near,
    };
    let entries = &world.resource::<ViewDrawGroups>().indices;
    let (mut hidden_count, mut disagree) = (0, 0);
    for &i in entries {
        let i = i as usize;
        let cpu = hidden(&pyramid, &camera, instances.centers[i], instances.radii[i]);
        hidden_count += cpu as usize;
        disagree += (cpu != (seen[i] == 0)) as usize;
    }
    eprintln!(
        "{hidden_count} of {} entries hidden, {disagree} disagree",
        entries.len()
    );
    assert!(
        hidden_count * 5 > entries.len(),
        "only {hidden_count} of {} hidden",
        entries.len()
    );
    assert_eq!(disagree, 0, "{disagree} entries judged otherwise on the GPU");
}

#[test]
fn culling_changes_no_pixel_along_a_camera_path() {
    let (mut culled, mut full) = (app(true), app(false));
    let mut drawn = (0, 0);
    for step in 0..6 {
        for app in [&mut culled, &mut full] {
            let world = app.world_mut();
            let mut q = world.query_filtered::<&mut Transform, With<Camera3d>>();
            for mut t in q.iter_mut(world) {
                // Forward 4 m and 3° left a frame, after the first.
                if step > 0 {
                    let forward = t.rotation * Vec3::new(0.0, 0.0, -4.0);
                    t.translation += forward;
                    t.rotation = Quat::from_rotation_y(3f32.to_radians()) * t.rotation;
                }
            }
            app.update();
        }
        let (a, b) = (renderer(&culled).read_image(), renderer(&full).read_image());
        let differing = a.pixels().zip(b.pixels()).filter(|(x, y)| x != y).count();
        assert_eq!(differing, 0, "step {step}: {differing} pixels differ");
        let (early, late) = renderer(&culled).read_occlusion_drawn().expect("the culling ran");
        let entries = culled.world().resource::<ViewDrawGroups>().indices.len() as u64;
        eprintln!("step {step}: {early} + {late} of {entries} instances drawn");
        // NOTE: the first frame draws everything (nothing was seen before it).
        if step > 0 {
            drawn.0 += early + late;
            drawn.1 += entries;
        }
    }
    // Measured: 305 459 of 380 868 (80 %) after the first frame.
    assert!(
        drawn.0 * 10 < drawn.1 * 9,
        "culling drew {} of {} instances",
        drawn.0,
        drawn.1
    );
}
