//! The glTF loader on broken files: every kind gives an error that names the file and the
//! problem, without panicking (missing or truncated files, malformed JSON, broken rules,
//! data outside its storage, bad indices, positions and images (and images without a
//! source), node cycles, damaged GLB
//! containers, and mutated bytes).

use std::fs;

use gltf::json;
use gltf::json::validation::{Checked, USize64};
use penumbra::gltf::sample::{SAMPLE_BIN, SAMPLE_PNG};
use penumbra::gltf::{GltfError, load};

mod gltf_common;

use gltf_common::{Scratch, files, load_err, node_index, sample_glb, sample_root};

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
fn image_without_a_source() {
    let scratch = Scratch::new("no-image-source");
    let path = scratch.write_edited(|root| root.images[0].uri = None);
    load_err(&path, &["image 0: has neither a `uri` nor a `bufferView`"]);
    let path = scratch.write_edited(|root| {
        root.images[0].uri = None;
        root.images[0].buffer_view = Some(json::Index::new(0));
    });
    load_err(&path, &["image 0: is in a `bufferView` but has no `mimeType`"]);
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
