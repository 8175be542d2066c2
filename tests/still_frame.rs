//! A still frame of static casters costs nothing per entity: the instance sync's change scans
//! go through moving entities only (counted by `InstanceSync::scanned`; that it allocates
//! nothing is `steady_state.rs`'), entities that move are rewritten in place (same data as a
//! fresh build), and the `Static` marker's semantics (moving a static entity does nothing
//! until it is marked again or unmarked).

use bevy_app::App;
use bevy_ecs::entity::Entity;
use glam::{Vec3, Vec4};
use penumbra::ecs::{
    Camera3d, DirectionalLight, InstanceSync, Material, Materials, Mesh3d, MeshMaterial3d, Meshes, NotShadowCaster,
    RenderInstances, ShadowPlugin, Static, Transform,
};
use penumbra::math::chunks::SphereChunks;
use penumbra::mesh::{cuboid, plane};

/// An app of `statics` static boxes on a ground (static too) and `moving` boxes without the
/// marker; returns it and the moving boxes.
fn app(statics: usize, moving: usize) -> (App, Vec<Entity>) {
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    let world = app.world_mut();
    let cube = world.resource_mut::<Meshes>().add(cuboid(Vec3::ONE));
    let ground = world.resource_mut::<Meshes>().add(plane(glam::Vec2::splat(400.0)));
    let material = world.resource_mut::<Materials>().add(Material {
        base_color: Vec4::ONE,
        ..Default::default()
    });
    world.spawn((
        Camera3d::default(),
        Transform::from_xyz(0.0, 3.0, 10.0).looking_at(Vec3::new(0.0, 0.0, -20.0), Vec3::Y),
    ));
    world.spawn((
        DirectionalLight::default(),
        Transform::default().looking_at(Vec3::new(0.3, -1.0, 0.2), Vec3::Y),
    ));
    world.spawn((
        Transform::default(),
        Mesh3d(ground),
        MeshMaterial3d(material),
        NotShadowCaster,
        Static,
    ));
    let side = (statics as f32).sqrt().ceil() as usize;
    world.spawn_batch((0..statics).map(move |i| {
        let at = Vec3::new((i % side) as f32 * 2.0 - 150.0, 0.5, (i / side) as f32 * -2.0);
        (
            Transform::from_translation(at),
            Mesh3d(cube),
            MeshMaterial3d(material),
            Static,
        )
    }));
    let moving = (0..moving)
        .map(|i| {
            let at = Vec3::new(i as f32 * 3.0, 0.5, 5.0);
            world
                .spawn((Transform::from_translation(at), Mesh3d(cube), MeshMaterial3d(material)))
                .id()
        })
        .collect();
    app.update();
    (app, moving)
}

fn sync(app: &App) -> InstanceSync {
    *app.world().resource::<InstanceSync>()
}

#[test]
fn still_frames_scan_only_the_moving_entities() {
    let (mut app, _) = app(10_000, 10);
    let instances = app.world().resource::<RenderInstances>();
    assert_eq!(instances.gpu.len(), 10_011, "every box and the ground are drawn");
    let generation = instances.generation;
    for _ in 0..3 {
        app.update();
    }
    let s = sync(&app);
    // Three change scans (transform, mesh, material; the shadow-flag scan matches only
    // entities with a flag) over the 10 moving boxes; none over the 10 001 static entities.
    assert_eq!(s.scanned, 30, "entities scanned by a still frame: {}", s.scanned);
    assert_eq!((s.dirty, s.rebuilds, s.updates), (0, 1, 0), "{s:?}");
    assert_eq!(app.world().resource::<RenderInstances>().generation, generation);
}

#[test]
fn a_moved_entity_is_rewritten_in_place_as_a_fresh_build_would_write_it() {
    let (mut app, moving) = app(2_000, 3);
    let (layout, generation) = {
        let i = app.world().resource::<RenderInstances>();
        (i.layout, i.generation)
    };
    let to = Vec3::new(-40.0, 2.0, -30.0);
    app.world_mut().get_mut::<Transform>(moving[1]).unwrap().translation = to;
    app.update();
    let i = app.world().resource::<RenderInstances>();
    let slot = i.slot(moving[1]).expect("drawn");
    assert_eq!(
        (i.layout, i.generation),
        (layout, generation + 1),
        "in place, not rebuilt"
    );
    assert_eq!(i.updated, [slot]);
    assert_eq!(sync(&app).updates, 1);
    // The same entity placed there from the start.
    let (mut fresh, fresh_moving) = app_at(to);
    fresh.update();
    let f = fresh.world().resource::<RenderInstances>();
    let fresh_slot = f.slot(fresh_moving).unwrap() as usize;
    let slot = slot as usize;
    assert_eq!(i.gpu[slot], f.gpu[fresh_slot]);
    assert_eq!(
        (i.centers[slot], i.radii[slot]),
        (f.centers[fresh_slot], f.radii[fresh_slot])
    );
    let c = i.caster_index[slot] as usize;
    assert_eq!(i.caster_boxes[c], f.caster_boxes[f.caster_index[fresh_slot] as usize]);
    // The chunks were refitted as a build would fit them.
    assert_eq!(i.chunks, SphereChunks::build(&i.centers, &i.radii));
    assert_eq!(i.caster_chunks, SphereChunks::build(&i.caster_centers, &i.caster_radii));
    assert!(i.caster_bounds.with_point(to) == i.caster_bounds && i.receiver_bounds.with_point(to) == i.receiver_bounds);
}

/// [`app`] of 2 000 static boxes whose second moving box starts at `at`.
fn app_at(at: Vec3) -> (App, Entity) {
    let (mut app, moving) = app(2_000, 3);
    app.world_mut().get_mut::<Transform>(moving[1]).unwrap().translation = at;
    (app, moving[1])
}

#[test]
fn a_static_entity_moves_only_when_marked_again_or_unmarked() {
    let (mut app, _) = app(100, 0);
    let world = app.world_mut();
    let entity = world
        .query_filtered::<Entity, (bevy_ecs::query::With<Static>, bevy_ecs::query::Without<NotShadowCaster>)>()
        .iter(world)
        .next()
        .unwrap();
    let center = |app: &App| {
        let i = app.world().resource::<RenderInstances>();
        i.centers[i.slot(entity).unwrap() as usize]
    };
    let start = center(&app);
    app.world_mut().get_mut::<Transform>(entity).unwrap().translation.y += 5.0;
    app.update();
    assert_eq!(center(&app), start, "a static entity is not looked at");
    // Marked again: synced once, in place.
    app.world_mut().entity_mut(entity).insert(Static);
    app.update();
    assert_eq!(center(&app), start + Vec3::Y * 5.0);
    assert_eq!((sync(&app).updates, sync(&app).rebuilds), (1, 1));
    // Moved while static, then unmarked: placed where its transform says.
    app.world_mut().get_mut::<Transform>(entity).unwrap().translation.y += 1.0;
    app.update();
    assert_eq!(center(&app), start + Vec3::Y * 5.0, "still static");
    app.world_mut().entity_mut(entity).remove::<Static>();
    app.update();
    assert_eq!(center(&app), start + Vec3::Y * 6.0, "unmarked");
    // Scanned like any moving entity from then on.
    app.world_mut().get_mut::<Transform>(entity).unwrap().translation.y += 1.0;
    app.update();
    assert_eq!(center(&app), start + Vec3::Y * 7.0);
    assert_eq!(sync(&app).scanned, 3, "the one entity without the marker is scanned");
}

#[test]
fn spawning_appends_and_despawning_leaves_a_tombstone_without_renumbering() {
    let (mut app, moving) = app(1_000, 2);
    let (layout, len) = {
        let i = app.world().resource::<RenderInstances>();
        (i.layout, i.gpu.len())
    };
    let kept = app.world().resource::<RenderInstances>().slot(moving[1]);
    let material = *app.world().get::<MeshMaterial3d>(moving[0]).unwrap();
    let mesh = *app.world().get::<Mesh3d>(moving[0]).unwrap();
    app.world_mut().despawn(moving[0]);
    let added = app
        .world_mut()
        .spawn((Transform::from_xyz(7.0, 0.5, 9.0), mesh, material))
        .id();
    app.update();
    let i = app.world().resource::<RenderInstances>();
    assert_eq!(
        (i.layout, i.gpu.len(), i.tombstones, i.appended),
        (layout, len + 1, 1, 1),
        "in place"
    );
    assert_eq!((i.slot(moving[0]), i.slot(moving[1])), (None, kept), "none renumbered");
    let slot = i.slot(added).expect("appended") as usize;
    assert_eq!(slot, len);
    assert_eq!(
        i.updated.len(),
        2,
        "the tombstone and the new instance: {:?}",
        i.updated
    );
    assert_eq!(sync(&app).updates, 1);
    // The new instance as a fresh build writes it; the chunks and runs as a build makes them.
    let (center, radius) = (i.centers[slot], i.radii[slot]);
    assert!(center.abs_diff_eq(Vec3::new(7.0, 0.5, 9.0), 1e-6) && radius > 0.8);
    assert_eq!(i.chunks, SphereChunks::build(&i.centers, &i.radii));
    assert_eq!(i.caster_chunks, SphereChunks::build(&i.caster_centers, &i.caster_radii));
    let runs: u32 = (0..i.chunks.len())
        .map(|k| i.runs_of_chunk(k).map(|(a, b)| b - a).sum::<u32>())
        .sum();
    assert_eq!(runs as usize, i.gpu.len(), "every instance in one run");
    // Many changes at once (more than an eighth of the list) rebuild and drop the tombstone.
    let world = app.world_mut();
    for k in 0..200 {
        world.spawn((Transform::from_xyz(k as f32, 0.5, 20.0), mesh, material));
    }
    app.update();
    let i = app.world().resource::<RenderInstances>();
    assert!(i.layout > layout && i.tombstones == 0 && i.appended == 0, "rebuilt");
    assert_eq!(i.gpu.len(), len + 200, "{} instances", i.gpu.len());
    assert_eq!(sync(&app).rebuilds, 2);
}

#[test]
fn a_child_that_loses_its_parent_is_placed_by_its_own_transform() {
    let (mut app, moving) = app(10, 1);
    let world = app.world_mut();
    let parent = world.spawn(Transform::from_xyz(0.0, 10.0, 0.0)).id();
    world.entity_mut(moving[0]).insert(bevy_ecs::hierarchy::ChildOf(parent));
    app.update();
    let y = |app: &App| {
        let i = app.world().resource::<RenderInstances>();
        i.centers[i.slot(moving[0]).unwrap() as usize].y
    };
    assert_eq!(y(&app), 10.5, "placed under its parent");
    app.world_mut()
        .entity_mut(moving[0])
        .remove::<bevy_ecs::hierarchy::ChildOf>();
    app.update();
    assert_eq!(y(&app), 0.5, "placed by its own transform");
}
