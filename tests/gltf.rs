//! The glTF loader on good files: the shipped sample loads with the expected content and
//! matches its generator byte for byte, a GLB and a data-URI copy load the same, and
//! approximations are warned. Broken files are in `tests/gltf_errors.rs`.

use std::fs;
use std::path::Path;

use base64::Engine;
use base64::engine::general_purpose::STANDARD as BASE64;
use glam::{Mat4, Vec3};
use gltf::json;
use gltf::json::validation::Checked;
use penumbra::ecs::AlphaMode;
use penumbra::gltf::load;
use penumbra::gltf::sample::{self, SAMPLE_BIN, SAMPLE_DIR, SAMPLE_GLTF, SAMPLE_PNG, SampleFiles};

mod gltf_common;

use gltf_common::{Scratch, assert_close, files, instance, sample_glb, sample_path, sample_root};

#[test]
fn shipped_sample_loads() {
    let model = load(&sample_path()).unwrap();
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);

    let names: Vec<_> = model.meshes.iter().map(|m| m.name.as_deref().unwrap()).collect();
    assert_eq!(names, ["pot", "stem", "frond"]);
    let primitive_counts: Vec<_> = model.meshes.iter().map(|m| m.primitives.len()).collect();
    assert_eq!(primitive_counts, [2, 1, 1]);
    let pot = &model.meshes[0];
    assert_eq!(pot.primitives[0].material, Some(0));
    assert_eq!(pot.primitives[1].material, Some(1));
    assert_eq!(pot.primitives[0].mesh.triangle_count(), 10);
    let frond = &model.meshes[2].primitives[0];
    assert_eq!(frond.mesh.vertices.len(), 4);
    assert_eq!(frond.mesh.indices, [0, 1, 2, 0, 2, 3]);
    assert!(frond.mesh.vertices.iter().all(|v| v.normal == [0.0, 0.0, 1.0]));
    assert_eq!(frond.mesh.vertices[2].position, [0.15, 0.7, 0.0]);
    assert_eq!(frond.mesh.vertices[2].uv, [1.0, 0.0]);

    assert_eq!(model.materials.len(), 4);
    let leaf = &model.materials[frond.material.unwrap()];
    assert_eq!(leaf.name.as_deref(), Some("frond"));
    assert_eq!(leaf.alpha_mode, AlphaMode::Mask(0.5));
    assert_eq!(leaf.base_color_texture, Some(0));
    assert!(leaf.double_sided);
    // KHR_materials_diffuse_transmission, read without a warning.
    assert_eq!(leaf.transmission, 0.4);
    for opaque in &model.materials[..3] {
        assert_eq!(opaque.alpha_mode, AlphaMode::Opaque);
        assert_eq!(opaque.base_color_texture, None);
        assert!(!opaque.double_sided);
        assert_eq!(opaque.transmission, 0.0);
    }
    assert_eq!(model.materials[0].base_color, glam::Vec4::new(0.60, 0.22, 0.10, 1.0));

    assert_eq!(model.images.len(), 1);
    let image = &model.images[0];
    assert_eq!((image.width, image.height), (64, 128));
    let alphas: Vec<u8> = image.rgba.chunks(4).map(|p| p[3]).collect();
    assert!(alphas.iter().all(|&a| a == 0 || a == 255));
    let opaque = alphas.iter().filter(|&&a| a == 255).count();
    assert!(opaque > 64 * 128 / 8 && opaque < 64 * 128 / 2, "{opaque} opaque texels");

    let names: Vec<_> = model.nodes.iter().map(|n| n.name.as_deref().unwrap()).collect();
    assert_eq!(
        names,
        [
            "pot",
            "stem",
            "frond_0",
            "frond_1",
            "frond_2",
            "frond_3",
            "frond_4",
            "frond_5",
            "top_frond_0",
            "top_frond_1",
            "top_frond_2"
        ]
    );
    let tip = Vec3::new(0.0, 0.7, 0.0);
    // frond_0 leans 60° towards +Z; the crown turns 30° about Y and sits 0.6 above the
    // stem, which sits 0.3 above the root; the root turns 90° about Y: (x, y, z) → (z, y, -x).
    let frond_0 = instance(&model, "frond_0");
    assert_eq!(frond_0.mesh, 2);
    let lean = 0.7 * 60f32.to_radians().sin(); // 0.606
    let expected = Vec3::new(lean * 30f32.to_radians().cos(), 1.25, -lean * 0.5);
    assert_close(frond_0.model_from_mesh.transform_point3(tip), expected);
    assert_close(
        frond_0.model_from_mesh.transform_point3(Vec3::ZERO),
        Vec3::new(0.0, 0.9, 0.0),
    );
    // top_frond_0 leans 30°, under crown_top (0.25 up, 30° turn, scale 0.8) under the crown.
    let top = instance(&model, "top_frond_0");
    let (y, z) = (0.8 * 0.7 * 30f32.to_radians().cos(), 0.8 * 0.7 * 0.5);
    let turned = Mat4::from_rotation_y(60f32.to_radians()).transform_point3(Vec3::new(0.0, y, z));
    let expected = Vec3::new(turned.z, 0.3 + 0.6 + 0.25 + y, -turned.x);
    assert_close(top.model_from_mesh.transform_point3(tip), expected);
    assert_close(
        top.model_from_mesh.transform_point3(Vec3::ZERO),
        Vec3::new(0.0, 1.15, 0.0),
    );

    // Stands on y = 0 and is between 1 and 2 m tall.
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for node in &model.nodes {
        for primitive in &model.meshes[node.mesh].primitives {
            for v in &primitive.mesh.vertices {
                let y = node.model_from_mesh.transform_point3(Vec3::from(v.position)).y;
                (lo, hi) = (lo.min(y), hi.max(y));
            }
        }
    }
    assert!(lo.abs() < 1e-6, "lowest point {lo}");
    assert!((1.0..2.0).contains(&hi), "height {hi}");
}

#[test]
fn sample_generator_matches_shipped_files() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(SAMPLE_DIR);
    let built = sample::build();
    let shipped = SampleFiles {
        gltf: fs::read_to_string(dir.join(SAMPLE_GLTF)).unwrap(),
        bin: fs::read(dir.join(SAMPLE_BIN)).unwrap(),
        png: fs::read(dir.join(SAMPLE_PNG)).unwrap(),
    };
    let hint = "run `cargo run --example make_sample_gltf` and commit assets/models";
    assert!(
        built.gltf == shipped.gltf,
        "{SAMPLE_GLTF} differs from sample::build(): {hint}"
    );
    assert!(
        built.bin == shipped.bin,
        "{SAMPLE_BIN} differs from sample::build(): {hint}"
    );
    assert!(
        built.png == shipped.png,
        "{SAMPLE_PNG} differs from sample::build(): {hint}"
    );
    assert_eq!(sample::build(), built, "sample::build() is not deterministic");
}

#[test]
fn glb_round_trip_loads_the_same() {
    let scratch = Scratch::new("glb");
    let path = scratch.path("fern.glb");
    fs::write(&path, sample_glb()).unwrap();
    let glb = load(&path).unwrap();
    let gltf = load(&sample_path()).unwrap();
    assert_eq!(glb, gltf);
}

#[test]
fn data_uris_load_the_same() {
    let scratch = Scratch::new("data-uri");
    let files = files();
    let mut root = sample_root();
    root.buffers[0].uri = Some(format!(
        "data:application/octet-stream;base64,{}",
        BASE64.encode(&files.bin)
    ));
    root.images[0].uri = Some(format!("data:image/png;base64,{}", BASE64.encode(&files.png)));
    let path = scratch.path("embedded.gltf");
    fs::write(&path, json::serialize::to_string(&root).unwrap()).unwrap();
    assert_eq!(load(&path).unwrap(), load(&sample_path()).unwrap());
}

#[test]
fn percent_encoded_uris_resolve() {
    let scratch = Scratch::new("percent");
    let files = files();
    let mut root = sample_root();
    root.buffers[0].uri = Some("fern%20data.bin".into());
    fs::write(scratch.path("fern data.bin"), &files.bin).unwrap();
    fs::write(scratch.path(SAMPLE_PNG), &files.png).unwrap();
    let path = scratch.path(SAMPLE_GLTF);
    fs::write(&path, json::serialize::to_string(&root).unwrap()).unwrap();
    assert_eq!(load(&path).unwrap(), load(&sample_path()).unwrap());
}

#[test]
fn approximations_are_warned() {
    let scratch = Scratch::new("warnings");
    let path = scratch.write_edited(|root| {
        // No normals on the stem; the pot's soil as a fan, the stem as points; leaves blended.
        let stem = &mut root.meshes[1].primitives[0];
        stem.attributes.remove(&Checked::Valid(json::mesh::Semantic::Normals));
        root.meshes[0].primitives[1].mode = Checked::Valid(json::mesh::Mode::TriangleFan);
        root.meshes[2].primitives[0].mode = Checked::Valid(json::mesh::Mode::Points);
        root.materials[3].alpha_mode = Checked::Valid(json::material::AlphaMode::Blend);
        let transmission = root.materials[3].extensions.as_mut().expect("the frond's extension");
        transmission.others.insert(
            "KHR_materials_diffuse_transmission".to_owned(),
            json::Value::Object(
                [("diffuseTransmissionFactor".to_owned(), json::Value::from(2.0))]
                    .into_iter()
                    .collect(),
            ),
        );
    });
    let model = load(&path).unwrap();
    let warnings = model.warnings.join("\n");
    assert!(
        warnings.contains("material 3 (`frond`): diffuseTransmissionFactor 2 clamped to 0..=1"),
        "{warnings}"
    );
    assert_eq!(model.materials[3].transmission, 1.0);
    assert!(
        warnings.contains("mesh 1 primitive 0: no NORMAL attribute; flat normals computed"),
        "{warnings}"
    );
    assert!(
        warnings.contains("mesh 2 primitive 0: Points primitive skipped"),
        "{warnings}"
    );
    assert!(
        warnings.contains("material 3 (`frond`): alphaMode BLEND is not supported"),
        "{warnings}"
    );
    assert_eq!(model.materials[3].alpha_mode, AlphaMode::Mask(0.5));
    assert!(model.meshes[2].primitives.is_empty());
    // Un-welded: three vertices per triangle, each with its face's normal.
    let stem = &model.meshes[1].primitives[0].mesh;
    assert_eq!(stem.vertices.len(), stem.indices.len());
    assert!(Vec3::from(stem.vertices[0].normal).abs_diff_eq(Vec3::X, 1e-6));
    // The soil's indices 0 1 2 0 2 3 read as a fan around 0: (1 2 0) (2 0 0) (0 2 0) (2 3 0),
    // the middle two degenerate and dropped.
    assert_eq!(model.meshes[0].primitives[1].mesh.indices, [1, 2, 0, 2, 3, 0]);
}
