//! Instances that move, appear or go are changed in place and patched in the GPU's copy
//! (lavapipe): the image after moving a box in the default scene, or after despawning it and
//! spawning another, equals, pixel for pixel, the image of the same scene with the box spawned
//! where it ends.

mod common;

use bevy_app::App;
use bevy_ecs::entity::Entity;
use common::{INSTALL, spawn_box, still_scene};
use glam::{Vec3, Vec4};
use penumbra::ecs::{Mesh3d, MeshMaterial3d, RenderInstances, Transform};
use penumbra::render::Renderer;

/// The default scene with a box at `at` (not static: it may move), one frame rendered.
fn app(at: Vec3) -> (App, Entity) {
    let renderer = Renderer::headless(320, 180).expect(INSTALL);
    let mut app = still_scene(renderer, "assets/scenes/default.ron");
    let cube = spawn_box(
        app.world_mut(),
        Vec3::new(1.0, 2.0, 1.0),
        Vec4::new(0.9, 0.5, 0.2, 1.0),
        at,
    );
    app.update();
    (app, cube)
}

fn image(app: &App) -> image::RgbaImage {
    app.world().resource::<Renderer>().read_image()
}

/// Pixels that differ between `a` and `b`.
fn differing(a: &image::RgbaImage, b: &image::RgbaImage) -> usize {
    a.pixels().zip(b.pixels()).filter(|(x, y)| x != y).count()
}

#[test]
fn a_moved_box_draws_as_one_spawned_where_it_went() {
    // Both places inside the scene's other casters' bounds, so no bound grows with the move.
    let (from, to) = (Vec3::new(0.5, 1.0, -2.0), Vec3::new(-0.5, 1.0, -6.0));
    let (mut moved, cube) = app(from);
    let before = image(&moved);
    let layout = moved.world().resource::<RenderInstances>().layout;
    moved.world_mut().get_mut::<Transform>(cube).unwrap().translation = to;
    moved.update();
    let instances = moved.world().resource::<RenderInstances>();
    let slot = instances.slot(cube).expect("drawn");
    assert_eq!(
        (instances.layout, instances.updated.as_slice()),
        (layout, [slot].as_slice()),
        "the move was an in-place update"
    );
    let (mut placed, _) = app(to);
    placed.update();
    let (a, b) = (image(&moved), image(&placed));
    let changed = differing(&before, &a);
    let differ = differing(&a, &b);
    eprintln!("{changed} pixels changed by the move, {differ} differ from the box spawned there");
    // Measured: 1 133 pixels changed.
    assert!(changed > 400, "the move changed only {changed} pixels");
    assert_eq!(differ, 0, "{differ} pixels differ from the box spawned there");
}

#[test]
fn a_despawned_box_and_a_spawned_one_draw_as_a_scene_with_the_new_one_only() {
    let (from, to) = (Vec3::new(0.5, 1.0, -2.0), Vec3::new(-0.5, 1.0, -6.0));
    let (mut changed, cube) = app(from);
    let before = image(&changed);
    let layout = changed.world().resource::<RenderInstances>().layout;
    let world = changed.world_mut();
    // NOTE: the same mesh and material (a new asset would rebuild the list).
    let (mesh, material) = (
        *world.get::<Mesh3d>(cube).unwrap(),
        *world.get::<MeshMaterial3d>(cube).unwrap(),
    );
    world.despawn(cube);
    world.spawn((Transform::from_translation(to), mesh, material));
    changed.update();
    let instances = changed.world().resource::<RenderInstances>();
    assert_eq!(
        (instances.layout, instances.tombstones),
        (layout, 1),
        "a tombstone and an append, in place"
    );
    let (mut placed, _) = app(to);
    placed.update();
    let (a, b) = (image(&changed), image(&placed));
    let moved = differing(&before, &a);
    let differ = differing(&a, &b);
    eprintln!("{moved} pixels changed, {differ} differ from the scene with the new box only");
    // Measured: as many as the move above changes.
    assert!(moved > 400, "only {moved} pixels changed");
    assert_eq!(differ, 0, "{differ} pixels differ from the scene with the new box only");
}
