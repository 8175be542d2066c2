//! The glTF loader: the shipped sample loads with the expected content and matches its
//! generator byte for byte, a GLB and a data-URI copy load the same, and every kind of
//! broken file gives an error that names the file and the problem, without panicking.

use std::fs;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use base64::Engine;
use base64::engine::general_purpose::STANDARD as BASE64;
use glam::{Mat4, Vec3};
use gltf::binary::{Glb, Header};
use gltf::json;
use gltf::json::validation::{Checked, USize64};
use penumbra::ecs::AlphaMode;
use penumbra::gltf::sample::{self, SAMPLE_BIN, SAMPLE_DIR, SAMPLE_GLTF, SAMPLE_PNG, SampleFiles};
use penumbra::gltf::{GltfError, GltfModel, load};

/// `sample::build()`, built once (PNG encoding is slow in debug builds).
fn files() -> &'static SampleFiles {
    static FILES: OnceLock<SampleFiles> = OnceLock::new();
    FILES.get_or_init(sample::build)
}

fn sample_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(SAMPLE_DIR).join(SAMPLE_GLTF)
}

/// A fresh directory under the system temp dir, removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("penumbra-gltf-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }

    fn path(&self, file: &str) -> PathBuf {
        self.0.join(file)
    }

    /// Writes the three sample files (each replaceable) and returns the .gltf path.
    fn write(&self, gltf: Option<&str>, bin: Option<&[u8]>, png: Option<&[u8]>) -> PathBuf {
        let files = files();
        fs::write(self.path(SAMPLE_GLTF), gltf.unwrap_or(&files.gltf)).unwrap();
        if let Some(bin) = bin.or(Some(files.bin.as_slice())).filter(|b| !b.is_empty()) {
            fs::write(self.path(SAMPLE_BIN), bin).unwrap();
        }
        if let Some(png) = png.or(Some(files.png.as_slice())).filter(|p| !p.is_empty()) {
            fs::write(self.path(SAMPLE_PNG), png).unwrap();
        }
        self.path(SAMPLE_GLTF)
    }

    /// Writes the sample with its JSON edited by `edit`.
    fn write_edited(&self, edit: impl FnOnce(&mut json::Root)) -> PathBuf {
        let mut root = sample_root();
        edit(&mut root);
        self.write(Some(&json::serialize::to_string_pretty(&root).unwrap()), None, None)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

fn sample_root() -> json::Root {
    json::deserialize::from_str(&files().gltf).unwrap()
}

fn node_index(root: &json::Root, name: &str) -> usize {
    root.nodes.iter().position(|n| n.name.as_deref() == Some(name)).unwrap()
}

/// Loads `path` expecting an error whose text contains the path and every part.
fn load_err(path: &Path, parts: &[&str]) -> GltfError {
    let err = match load(path) {
        Ok(_) => panic!("{} loaded, expected an error containing {parts:?}", path.display()),
        Err(err) => err,
    };
    let text = err.to_string();
    assert!(
        text.starts_with(&format!("{}: ", path.display())),
        "error does not start with the file: {text}"
    );
    for part in parts {
        assert!(text.contains(part), "error lacks {part:?}: {text}");
    }
    err
}

fn instance<'m>(model: &'m GltfModel, name: &str) -> &'m penumbra::gltf::GltfNodeInstance {
    model
        .nodes
        .iter()
        .find(|n| n.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no node {name}"))
}

fn assert_close(actual: Vec3, expected: Vec3) {
    assert!(actual.abs_diff_eq(expected, 1e-5), "{actual} != {expected}");
}

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

/// The sample as one GLB: the buffer becomes the BIN chunk, the PNG a buffer view in it.
fn sample_glb() -> Vec<u8> {
    let files = files();
    let mut root = sample_root();
    let mut bin = files.bin.clone();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let png_view = root.push(json::buffer::View {
        buffer: json::Index::new(0),
        byte_length: USize64::from(files.png.len()),
        byte_offset: Some(USize64::from(bin.len())),
        byte_stride: None,
        name: None,
        target: None,
        extensions: None,
        extras: Default::default(),
    });
    bin.extend_from_slice(&files.png);
    root.images[0].uri = None;
    root.images[0].buffer_view = Some(png_view);
    root.images[0].mime_type = Some(json::image::MimeType("image/png".into()));
    root.buffers[0].uri = None;
    root.buffers[0].byte_length = USize64::from(bin.len());
    let json_text = json::serialize::to_vec(&root).unwrap();
    Glb {
        header: Header {
            magic: *b"glTF",
            version: 2,
            length: 0,
        },
        json: json_text.into(),
        bin: Some(bin.into()),
    }
    .to_vec()
    .unwrap()
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

#[test]
fn missing_gltf_file() {
    let scratch = Scratch::new("missing-gltf");
    let err = load_err(&scratch.path("absent.gltf"), &["absent.gltf: cannot read: "]);
    assert!(matches!(err, GltfError::Io { .. }));
}

#[test]
fn missing_bin_file() {
    let scratch = Scratch::new("missing-bin");
    let path = scratch.write(None, Some(&[]), None);
    let bin = scratch.path(SAMPLE_BIN).display().to_string();
    load_err(&path, &["buffer 0 (`fern.bin`): no file at ", &bin]);
}

#[test]
fn truncated_bin_file() {
    let scratch = Scratch::new("truncated-bin");
    let files = files();
    let path = scratch.write(None, Some(&files.bin[..600]), None);
    let declared = format!(
        "buffer 0 (`fern.bin`) is truncated: 600 bytes, {} declared",
        files.bin.len()
    );
    let err = load_err(&path, &[&declared]);
    assert!(matches!(err, GltfError::Truncated { actual: 600, .. }));
}

#[test]
fn malformed_json() {
    let scratch = Scratch::new("malformed");
    let files = files();
    let path = scratch.write(Some(&files.gltf[..files.gltf.len() / 2]), None, None);
    load_err(&path, &["not valid glTF: ", "EOF while parsing", "line "]);
}

#[test]
fn json_breaking_gltf_rules() {
    let scratch = Scratch::new("rules");
    let path = scratch.write_edited(|root| root.accessors[1].buffer_view = Some(json::Index::new(99)));
    load_err(
        &path,
        &["not valid glTF: ", "accessors[1].bufferView: Index out of bounds"],
    );
    // A POSITION accessor index out of range is caught before the crate's validation,
    // which would index with it.
    let path = scratch.write_edited(|root| {
        root.meshes[0].primitives[0]
            .attributes
            .insert(Checked::Valid(json::mesh::Semantic::Positions), json::Index::new(99));
    });
    load_err(&path, &["mesh 0 primitive 0: POSITION refers to accessor 99"]);
}

#[test]
fn accessor_outside_its_view() {
    let scratch = Scratch::new("accessor-range");
    let path = scratch.write_edited(|root| root.accessors[0].count = USize64(1000));
    load_err(
        &path,
        &[
            "mesh 0 primitive 0: POSITION (accessor 0): ",
            "past the end of buffer view 0",
        ],
    );
    let path = scratch.write_edited(|root| root.accessors[2].byte_offset = Some(USize64(8)));
    load_err(
        &path,
        &["mesh 0 primitive 0: TEXCOORD_0 (accessor 2): ", "buffer view 2"],
    );
}

#[test]
fn view_outside_its_buffer() {
    let scratch = Scratch::new("view-range");
    let path = scratch.write_edited(|root| root.buffer_views[5].byte_length = USize64(100_000));
    load_err(&path, &["buffer view 5: bytes ", "outside buffer 0 (1680 bytes)"]);
}

#[test]
fn index_out_of_range() {
    let scratch = Scratch::new("index-range");
    let root = sample_root();
    let indices = root.meshes[0].primitives[0].indices.unwrap();
    let view = root.accessors[indices.value()].buffer_view.unwrap();
    let offset = root.buffer_views[view.value()].byte_offset.unwrap().0 as usize;
    let mut bin = files().bin.clone();
    bin[offset + 4..offset + 6].copy_from_slice(&97u16.to_le_bytes());
    let path = scratch.write(None, Some(&bin), None);
    let err = load_err(&path, &["mesh 0 primitive 0: index 97 out of range (20 vertices)"]);
    assert!(matches!(err, GltfError::IndexOutOfRange { index: 97, .. }));
}

#[test]
fn missing_position() {
    let scratch = Scratch::new("no-position");
    let path = scratch.write_edited(|root| {
        root.meshes[2].primitives[0]
            .attributes
            .remove(&Checked::Valid(json::mesh::Semantic::Positions));
    });
    load_err(&path, &["mesh 2 primitive 0 has no POSITION attribute"]);
}

#[test]
fn non_finite_position() {
    let scratch = Scratch::new("nan-position");
    let mut bin = files().bin.clone();
    bin[4..8].copy_from_slice(&f32::NAN.to_le_bytes());
    let path = scratch.write(None, Some(&bin), None);
    load_err(&path, &["mesh 0 primitive 0: POSITION of vertex 0 is not finite"]);
}

#[test]
fn missing_image_file() {
    let scratch = Scratch::new("missing-png");
    let path = scratch.write(None, None, Some(&[]));
    let png = scratch.path(SAMPLE_PNG).display().to_string();
    load_err(&path, &["image 0 (`fern_leaf.png`): no file at ", &png]);
}

#[test]
fn undecodable_image() {
    let scratch = Scratch::new("bad-png");
    let path = scratch.write(None, None, Some(b"not a png at all"));
    let err = load_err(&path, &["image 0 (`fern_leaf.png`): cannot decode: "]);
    assert!(matches!(err, GltfError::Asset { .. }));
}

#[test]
fn node_cycle() {
    let scratch = Scratch::new("cycle");
    let path = scratch.write_edited(|root| {
        let (stem, crown) = (node_index(root, "stem"), node_index(root, "crown"));
        root.nodes[crown]
            .children
            .as_mut()
            .unwrap()
            .push(json::Index::new(stem as u32));
    });
    let err = load_err(
        &path,
        &["node 2 is its own ancestor: node 0 → node 2 → node 3 → node 2"],
    );
    assert!(matches!(err, GltfError::NodeCycle { node: 2, .. }));
}

#[test]
fn broken_glb_containers() {
    let scratch = Scratch::new("glb-broken");
    let glb = sample_glb();
    let path = scratch.path("broken.glb");
    for (bytes, part) in [
        (glb[..8].to_vec(), "GLB header is truncated"),
        (
            [&glb[..8], &4u32.to_le_bytes()[..], &glb[12..]].concat(),
            "GLB header declares 4 bytes",
        ),
        (glb[..glb.len() - 100].to_vec(), "GLB header declares"),
        (
            [&b"glTF"[..], &1u32.to_le_bytes()[..], &glb[8..]].concat(),
            "GLB version 1",
        ),
    ] {
        fs::write(&path, bytes).unwrap();
        load_err(&path, &["not valid glTF: ", part]);
    }
}

/// Damaged numbers in every accessor and buffer view, and damaged bytes all through a GLB,
/// give errors or (rarely) models, never panics.
#[test]
fn damaged_files_never_panic() {
    let scratch = Scratch::new("damage");
    let values = [0u64, 1, 3, 4, 7, 1679, 1680, 1 << 31, u32::MAX as u64, u64::MAX];
    let base = sample_root();
    // Without the texture, so that each load is quick; its bytes are damaged in the GLB below.
    let untextured = |root: &mut json::Root| {
        root.images.clear();
        root.textures.clear();
        root.materials[3].pbr_metallic_roughness.base_color_texture = None;
    };
    for i in 0..base.accessors.len() {
        for &v in &values {
            for field in 0..2 {
                let path = scratch.write_edited(|root| {
                    untextured(root);
                    match field {
                        0 => root.accessors[i].count = USize64(v),
                        _ => root.accessors[i].byte_offset = Some(USize64(v)),
                    }
                });
                let _ = load(&path);
            }
        }
    }
    for i in 0..base.buffer_views.len() {
        for &v in &values {
            for field in 0..3 {
                let path = scratch.write_edited(|root| {
                    untextured(root);
                    match field {
                        0 => root.buffer_views[i].byte_offset = Some(USize64(v)),
                        1 => root.buffer_views[i].byte_length = USize64(v),
                        _ => root.buffer_views[i].byte_stride = Some(json::buffer::Stride(v.min(1 << 20) as usize)),
                    }
                });
                let _ = load(&path);
            }
        }
    }
    let glb = sample_glb();
    let path = scratch.path("damaged.glb");
    for at in (0..glb.len()).step_by(53) {
        let mut bytes = glb.clone();
        bytes[at] ^= 0xA5;
        fs::write(&path, &bytes).unwrap();
        let _ = load(&path);
        fs::write(&path, &glb[..at]).unwrap();
        let _ = load(&path);
    }
}
