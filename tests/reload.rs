//! Live reload of scene and settings files: a good edit is applied, a bad edit is rejected
//! with its error and the previous scene keeps running, and fixing it applies it.

use std::path::{Path, PathBuf};
use std::time::Duration;

use bevy_app::App;
use bevy_ecs::world::World;
use penumbra::app::spawn_scene;
use penumbra::ecs::assets::Meshes;
use penumbra::ecs::components::{DirectionalLight, Mesh3d};
use penumbra::ecs::plugin::ShadowPlugin;
use penumbra::scene::SceneDesc;
use penumbra::settings::{ShadowMode, ShadowSettings};
use penumbra::viewer::{LiveReload, ReloadOutcome};

const SCENE: &str = r#"Scene(
    camera: Camera(position: (0, 4, 10), target: (0, 0, 0), fov: 60, near: 0.1, far: 200),
    sun: Sun(direction: (-1, -2, -1)),
    materials: { "grey": Material(base_color: (0.6, 0.6, 0.6, 1)) },
    objects: [
        Object(shape: Plane(size: (20, 20)), material: "grey"),
        Object(shape: Cuboid(size: (1, 2, 1)), material: "grey", translation: (0, 1, 0)),
    ],
)"#;

/// A fresh directory for one test's files.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-reload-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn start(dir: &Path, settings: Option<&Path>) -> (App, LiveReload) {
    let path = dir.join("scene.ron");
    std::fs::write(&path, SCENE).unwrap();
    let desc = SceneDesc::load(&path).unwrap();
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    spawn_scene(app.world_mut(), &desc).unwrap();
    app.update();
    let reload = LiveReload::new(&path, desc, settings).with_interval(Duration::ZERO);
    (app, reload)
}

fn mesh_entities(world: &mut World) -> usize {
    world.query::<&Mesh3d>().iter(world).count()
}

fn sun_settings(world: &mut World) -> ShadowSettings {
    *world
        .query::<(&DirectionalLight, &ShadowSettings)>()
        .single(world)
        .unwrap()
        .1
}

#[test]
fn a_good_scene_edit_replaces_the_scene() {
    let dir = temp_dir("good");
    let (mut app, mut reload) = start(&dir, None);
    assert_eq!(reload.poll(app.world_mut()), ReloadOutcome::Unchanged);
    assert_eq!(mesh_entities(app.world_mut()), 2);

    let edited = SCENE.replace(
        "translation: (0, 1, 0)),",
        "translation: (0, 1, 0)),\n        Object(shape: Sphere(radius: 0.5), material: \"grey\", translation: (3, 0.5, 0)),",
    );
    std::fs::write(dir.join("scene.ron"), edited).unwrap();
    let outcome = reload.poll(app.world_mut());
    assert_eq!(
        outcome,
        ReloadOutcome::Applied {
            scene: true,
            camera_changed: false
        }
    );
    app.update();
    let world = app.world_mut();
    assert_eq!(mesh_entities(world), 3, "old entities were not replaced");
    // Three shapes, and the sphere's four coarser levels.
    assert_eq!(world.resource::<Meshes>().len(), 7, "old meshes were not dropped");
    assert_eq!(world.query::<&DirectionalLight>().iter(world).count(), 1);
    assert_eq!(reload.current().objects.len(), 3);

    // A moved camera is reported, so the viewer can reset its free camera.
    let moved = SCENE.replace("position: (0, 4, 10)", "position: (0, 5, 12)");
    std::fs::write(dir.join("scene.ron"), moved).unwrap();
    assert_eq!(
        reload.poll(app.world_mut()),
        ReloadOutcome::Applied {
            scene: true,
            camera_changed: true
        }
    );
}

#[test]
fn a_bad_scene_edit_is_rejected_and_the_last_good_scene_kept() {
    let dir = temp_dir("bad");
    let (mut app, mut reload) = start(&dir, None);
    let path = dir.join("scene.ron");

    // Broken syntax: rejected with a located error.
    std::fs::write(&path, SCENE.replace("fov: 60,", "fov: 60")).unwrap();
    let ReloadOutcome::Rejected(error) = reload.poll(app.world_mut()) else {
        panic!("a syntax error was applied");
    };
    assert!(error.contains("scene.ron:2:"), "{error}");
    assert_eq!(reload.error.as_deref(), Some(error.as_str()));
    app.update();
    assert_eq!(mesh_entities(app.world_mut()), 2);

    // Parses, but a texture is missing: rejected before the old scene is touched.
    let missing = SCENE.replace(
        "base_color: (0.6, 0.6, 0.6, 1)",
        "base_color: (0.6, 0.6, 0.6, 1), texture: \"nowhere.png\"",
    );
    std::fs::write(&path, missing).unwrap();
    let ReloadOutcome::Rejected(error) = reload.poll(app.world_mut()) else {
        panic!("a missing texture was applied");
    };
    assert!(error.contains("nowhere.png"), "{error}");
    app.update();
    assert_eq!(mesh_entities(app.world_mut()), 2);
    assert_eq!(app.world().resource::<Meshes>().len(), 2);

    // Fixing the file applies it and clears the error.
    std::fs::write(&path, SCENE.replace("size: (1, 2, 1)", "size: (1, 3, 1)")).unwrap();
    assert!(matches!(
        reload.poll(app.world_mut()),
        ReloadOutcome::Applied { scene: true, .. }
    ));
    assert!(reload.error.is_none());
}

#[test]
fn a_settings_file_edit_applies_without_respawning() {
    let dir = temp_dir("settings");
    let settings_path = dir.join("settings.ron");
    std::fs::write(&settings_path, "ShadowSettings(cascade_count: 3)").unwrap();
    let (mut app, mut reload) = start(&dir, Some(&settings_path));
    let before: Vec<_> = app.world_mut().query::<&Mesh3d>().iter(app.world()).copied().collect();

    std::fs::write(&settings_path, "ShadowSettings(mode: Pcss, cascade_count: 2)").unwrap();
    assert_eq!(
        reload.poll(app.world_mut()),
        ReloadOutcome::Applied {
            scene: false,
            camera_changed: false
        }
    );
    let s = sun_settings(app.world_mut());
    assert_eq!((s.filter.mode, s.map.cascades.count), (ShadowMode::Pcss, 2));
    let after: Vec<_> = app.world_mut().query::<&Mesh3d>().iter(app.world()).copied().collect();
    assert_eq!(before, after, "a settings edit respawned the scene");

    // Out of range: rejected with the file, line and field; the settings stay.
    std::fs::write(&settings_path, "ShadowSettings(\n    resolution: 8192,\n)").unwrap();
    let ReloadOutcome::Rejected(error) = reload.poll(app.world_mut()) else {
        panic!("an invalid resolution was applied");
    };
    assert!(
        error.contains("settings.ron:2:17") && error.contains("resolution"),
        "{error}"
    );
    assert_eq!(sun_settings(app.world_mut()).map.cascades.count, 2);
}
