//! Placement through `bevy_transform`: entities spawned without a transform are placed at the
//! identity (never silently ignored), parented entities are drawn where their world transform
//! puts them, and casting is the default with `NotShadowCaster` as the opt-out.

use bevy_app::App;
use bevy_ecs::entity::Entity;
use bevy_ecs::hierarchy::ChildOf;
use bevy_ecs::world::World;
use glam::{Quat, Vec3};
use penumbra::ecs::{
    ActiveView, Camera3d, DirectionalLight, FrameLights, GlobalTransform, Material, MaterialHandle, Materials, Mesh3d,
    MeshHandle, MeshMaterial3d, Meshes, NotShadowCaster, RenderInstances, ShadowPlugin, Transform,
};
use penumbra::mesh::cuboid;

/// An app with the shadow plugin, a unit cube mesh and one material.
fn app() -> (App, MeshHandle, MaterialHandle) {
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    let world = app.world_mut();
    let mesh = world.resource_mut::<Meshes>().add(cuboid(Vec3::ONE));
    let material = world.resource_mut::<Materials>().add(Material::default());
    (app, mesh, material)
}

/// A camera at (0, 2, 10) looking at the origin.
fn spawn_camera(world: &mut World) {
    world.spawn((
        Camera3d::default(),
        Transform::from_xyz(0.0, 2.0, 10.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
}

/// World-space centre (the render origin added back) of the only instance drawn.
fn only_center(world: &World) -> Vec3 {
    let instances = world.resource::<RenderInstances>();
    assert_eq!(instances.centers.len(), 1, "one instance is drawn");
    instances.centers[0] + instances.origin
}

#[test]
fn a_light_spawned_without_a_transform_still_casts_cascades() {
    let (mut app, mesh, material) = app();
    let world = app.world_mut();
    spawn_camera(world);
    let light = world.spawn(DirectionalLight::default()).id();
    world.spawn((Mesh3d(mesh), MeshMaterial3d(material)));
    app.update();
    let world = app.world();
    assert_eq!(world.get::<Transform>(light), Some(&Transform::IDENTITY));
    let sun = *world.resource::<FrameLights>().sun().expect("the light is used");
    // The identity shines along -Z.
    assert!(sun.direction.abs_diff_eq(Vec3::NEG_Z, 1e-6), "{}", sun.direction);
    assert_eq!(sun.cascades.count, 4);
    assert!(sun.cascades.active().iter().all(|c| c.clip_from_world.is_finite()));
}

#[test]
fn a_camera_spawned_without_a_transform_is_used() {
    let (mut app, _, _) = app();
    let camera = app.world_mut().spawn(Camera3d::default()).id();
    app.update();
    let world = app.world();
    assert!(world.get::<GlobalTransform>(camera).is_some());
    let (view, _) = world.resource::<ActiveView>().camera.expect("the camera is used");
    assert_eq!(view.world_from_view, glam::Mat4::IDENTITY);
}

#[test]
fn a_mesh_spawned_without_a_transform_is_drawn_and_casts() {
    let (mut app, mesh, material) = app();
    app.world_mut().spawn((Mesh3d(mesh), MeshMaterial3d(material)));
    app.update();
    let world = app.world();
    let instances = world.resource::<RenderInstances>();
    assert_eq!(
        (instances.gpu.len(), instances.casters.len(), instances.skipped),
        (1, 1, 0)
    );
    assert!(only_center(world).abs_diff_eq(Vec3::ZERO, 1e-6));
}

#[test]
fn not_shadow_caster_opts_out_and_removing_it_opts_back_in() {
    let (mut app, mesh, material) = app();
    let entity = app
        .world_mut()
        .spawn((
            Transform::default(),
            Mesh3d(mesh),
            MeshMaterial3d(material),
            NotShadowCaster,
        ))
        .id();
    app.update();
    let instances = app.world().resource::<RenderInstances>();
    assert_eq!((instances.gpu.len(), instances.casters.len()), (1, 0));
    app.world_mut().entity_mut(entity).remove::<NotShadowCaster>();
    app.update();
    assert_eq!(app.world().resource::<RenderInstances>().casters.len(), 1);
}

#[test]
fn a_child_mesh_is_drawn_at_its_world_placement_and_follows_its_parent() {
    let (mut app, mesh, material) = app();
    let world = app.world_mut();
    let parent = world
        .spawn(Transform::from_xyz(10.0, 0.0, 0.0).with_rotation(Quat::from_rotation_y(90_f32.to_radians())))
        .id();
    world.spawn((
        Transform::from_xyz(0.0, 0.0, -2.0),
        Mesh3d(mesh),
        MeshMaterial3d(material),
        ChildOf(parent),
    ));
    app.update();
    // Local -Z turned 90° about +Y is world -X.
    let center = only_center(app.world());
    assert!(center.abs_diff_eq(Vec3::new(8.0, 0.0, 0.0), 1e-5), "{center}");
    let generation = app.world().resource::<RenderInstances>().generation;

    move_entity(app.world_mut(), parent, Vec3::new(0.0, 5.0, 0.0));
    app.update();
    let world = app.world();
    assert_eq!(world.resource::<RenderInstances>().generation, generation + 1);
    let center = only_center(world);
    assert!(center.abs_diff_eq(Vec3::new(8.0, 5.0, 0.0), 1e-5), "{center}");
}

#[test]
fn a_light_takes_its_direction_from_its_parent() {
    let (mut app, _, _) = app();
    let world = app.world_mut();
    spawn_camera(world);
    let rig = world
        .spawn(Transform::from_rotation(Quat::from_rotation_x(-90_f32.to_radians())))
        .id();
    world.spawn((DirectionalLight::default(), Transform::default(), ChildOf(rig)));
    app.update();
    let sun = *app.world().resource::<FrameLights>().sun().expect("the light is used");
    // The rig turns -Z down to -Y.
    assert!(sun.direction.abs_diff_eq(Vec3::NEG_Y, 1e-6), "{}", sun.direction);
}

/// Adds `by` to `entity`'s local translation.
fn move_entity(world: &mut World, entity: Entity, by: Vec3) {
    world.get_mut::<Transform>(entity).unwrap().translation += by;
}
