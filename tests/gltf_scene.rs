//! glTF models in scene files: the garden scene spawns one entity per node primitive with the
//! model's own materials (alpha-masked, double-sided leaves), a missing model is a located
//! scene error, and a damaged model is a spawn error naming the object, the file and the
//! problem, never a panic.

use bevy_app::App;
use penumbra::app::{PreparedScene, spawn_scene};
use penumbra::ecs::assets::{AlphaMode, Materials};
use penumbra::ecs::instances::RenderInstances;
use penumbra::ecs::plugin::ShadowPlugin;
use penumbra::gltf;
use penumbra::scene::{SceneDesc, SceneLimits};

#[test]
fn the_garden_spawns_every_node_primitive_with_the_models_materials() {
    let desc = SceneDesc::load("assets/scenes/garden.ron").unwrap_or_else(|e| panic!("{e}"));
    let model = gltf::load(std::path::Path::new("assets/models/fern.gltf")).unwrap();
    let per_fern: usize = model.nodes.iter().map(|n| model.meshes[n.mesh].primitives.len()).sum();
    let ferns = 4 * 2 + 1;
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    let spawned = spawn_scene(app.world_mut(), &desc).unwrap_or_else(|e| panic!("{e}"));
    // Plane, wall and bench, then every fern's primitives.
    assert_eq!(spawned, 3 + ferns * per_fern);
    app.update();
    let world = app.world();
    let leaves = world
        .resource::<Materials>()
        .as_slice()
        .iter()
        .find(|m| matches!(m.alpha_mode, AlphaMode::Mask(_)))
        .expect("the leaf material is masked");
    assert!(leaves.double_sided && leaves.base_color_texture.is_some());
    let instances = world.resource::<RenderInstances>();
    let masked = instances.casters.len() - instances.opaque_casters;
    assert!(masked >= ferns * 9, "only {masked} masked casters");
    assert_eq!(instances.skipped, 0);
}

/// A fresh directory with a copy of the sample model and a scene that uses it.
fn scene_with_model(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-gltf-scene-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for file in ["fern.gltf", "fern.bin", "fern_leaf.png"] {
        std::fs::copy(format!("assets/models/{file}"), dir.join(file)).unwrap();
    }
    let scene = r#"Scene(
    camera: (position: (0, 2, 5), target: (0, 0.5, 0), fov: 50, near: 0.1, far: 100),
    sun: (direction: (0.3, -1, -0.4)),
    materials: { "white": () },
    objects: [
        (shape: Plane(size: (10, 10)), material: "white"),
        (shape: Gltf(path: "fern.gltf"), material: "white"),
    ],
)"#;
    std::fs::write(dir.join("scene.ron"), scene).unwrap();
    dir
}

#[test]
fn a_missing_model_is_a_located_scene_error() {
    let dir = scene_with_model("missing");
    std::fs::remove_file(dir.join("fern.gltf")).unwrap();
    let err = SceneDesc::load(dir.join("scene.ron")).expect_err("a missing model loads");
    let text = err.to_string();
    assert!(text.contains("scene.ron:7:"), "{text}");
    assert!(
        text.contains("expected a .gltf or .glb file inside the asset folder")
            && text.contains("found \"fern.gltf\" (no file at `"),
        "{text}"
    );
}

#[test]
fn models_count_their_primitives_against_the_instance_budget() {
    let dir = scene_with_model("budget");
    let desc = SceneDesc::load(dir.join("scene.ron")).unwrap();
    let entities = PreparedScene::new(&desc).unwrap().entity_count() as u64;
    assert!(entities > desc.instance_count(), "the model has several primitives");
    let limits = SceneLimits {
        max_instances: entities - 1,
        ..SceneLimits::default()
    };
    let desc = SceneDesc::load_with(dir.join("scene.ron"), &limits).expect("within the scene's own count");
    let err = PreparedScene::new(&desc).map(|_| ()).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "the scene would spawn {entities} mesh entities (each glTF object counts its primitives), \
             more than the {} its instance budget allows",
            entities - 1
        )
    );
}

#[test]
fn a_damaged_model_is_a_spawn_error_naming_the_file() {
    let dir = scene_with_model("truncated");
    let bin = std::fs::read(dir.join("fern.bin")).unwrap();
    std::fs::write(dir.join("fern.bin"), &bin[..bin.len() / 2]).unwrap();
    let desc = SceneDesc::load(dir.join("scene.ron")).unwrap_or_else(|e| panic!("{e}"));
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    let err = spawn_scene(app.world_mut(), &desc).expect_err("a truncated model spawns");
    let text = err.to_string();
    assert!(text.starts_with("object 1: "), "{text}");
    assert!(text.contains("fern.gltf") && text.contains("truncated"), "{text}");

    std::fs::write(dir.join("fern.gltf"), "{ \"asset\": ").unwrap();
    let err = spawn_scene(app.world_mut(), &desc).expect_err("malformed JSON spawns");
    assert!(err.to_string().contains("not valid glTF"), "{err}");
}
