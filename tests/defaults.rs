//! A scene file and code agree on every default: an object, material and sun written with
//! only their required fields spawn exactly the components a user gets from `Default` (and,
//! for casting and receiving, from leaving the opt-out markers off).

use bevy_app::App;
use bevy_ecs::query::{Has, With};
use glam::Vec3;
use penumbra::app::spawn_scene;
use penumbra::ecs::{
    AmbientLight, Camera3d, DirectionalLight, Material, Materials, Mesh3d, NotShadowCaster, NotShadowReceiver,
    ShadowPlugin, Transform,
};
use penumbra::scene::SceneDesc;
use penumbra::settings::ShadowSettings;

const MINIMAL: &str = r#"Scene(
    camera: (position: (0, 2, 5), target: (0, 0, 0), fov: 60, near: 0.1, far: 1000),
    sun: (direction: (0, -1, 0)),
    materials: { "m": () },
    objects: [ (shape: Cuboid(size: (1, 1, 1)), material: "m") ],
)"#;

#[test]
fn a_minimal_scene_spawns_the_code_defaults() {
    let desc = SceneDesc::from_str(MINIMAL, "minimal.ron").unwrap_or_else(|e| panic!("{e}"));
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    spawn_scene(app.world_mut(), &desc).unwrap();
    let world = app.world_mut();

    let (light, settings) = world
        .query::<(&DirectionalLight, &ShadowSettings)>()
        .single(world)
        .unwrap();
    assert_eq!(*light, DirectionalLight::default());
    assert_eq!(*settings, ShadowSettings::default());
    assert_eq!(*world.resource::<AmbientLight>(), AmbientLight::default());

    let camera = *world.query::<&Camera3d>().single(world).unwrap();
    let code = Camera3d::default();
    assert_eq!(
        (camera.fov_y, camera.near, camera.far, camera.exposure),
        (code.fov_y, code.near, code.far, code.exposure)
    );

    assert_eq!(world.resource::<Materials>().as_slice(), [Material::default()]);

    let (transform, no_cast, no_receive) = world
        .query_filtered::<(&Transform, Has<NotShadowCaster>, Has<NotShadowReceiver>), With<Mesh3d>>()
        .single(world)
        .unwrap();
    assert_eq!(*transform, Transform::from_scale(Vec3::ONE));
    assert!(
        !no_cast && !no_receive,
        "objects cast and receive by default, as meshes spawned in code"
    );
}
