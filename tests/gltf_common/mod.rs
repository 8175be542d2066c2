//! What the glTF tests share: the sample model built once, scratch folders holding edited
//! copies of it, and error and node lookups.

// NOTE: each test binary uses part of this module.
#![allow(dead_code)]

use std::fs;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use glam::Vec3;
use gltf::binary::{Glb, Header};
use gltf::json;
use gltf::json::validation::USize64;
use penumbra::gltf::sample::{self, SAMPLE_BIN, SAMPLE_DIR, SAMPLE_GLTF, SAMPLE_PNG, SampleFiles};
use penumbra::gltf::{GltfError, GltfModel, load};

/// `sample::build()`, built once (PNG encoding is slow in debug builds).
pub fn files() -> &'static SampleFiles {
    static FILES: OnceLock<SampleFiles> = OnceLock::new();
    FILES.get_or_init(sample::build)
}

pub fn sample_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(SAMPLE_DIR).join(SAMPLE_GLTF)
}

/// A fresh directory under the system temp dir, removed when dropped.
pub struct Scratch(pub PathBuf);

impl Scratch {
    pub fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("penumbra-gltf-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }

    pub fn path(&self, file: &str) -> PathBuf {
        self.0.join(file)
    }

    /// Writes the three sample files (each replaceable) and returns the .gltf path.
    pub fn write(&self, gltf: Option<&str>, bin: Option<&[u8]>, png: Option<&[u8]>) -> PathBuf {
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
    pub fn write_edited(&self, edit: impl FnOnce(&mut json::Root)) -> PathBuf {
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

pub fn sample_root() -> json::Root {
    json::deserialize::from_str(&files().gltf).unwrap()
}

pub fn node_index(root: &json::Root, name: &str) -> usize {
    root.nodes.iter().position(|n| n.name.as_deref() == Some(name)).unwrap()
}

/// Loads `path` expecting an error whose text contains the path and every part.
pub fn load_err(path: &Path, parts: &[&str]) -> GltfError {
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

pub fn instance<'m>(model: &'m GltfModel, name: &str) -> &'m penumbra::gltf::GltfNodeInstance {
    model
        .nodes
        .iter()
        .find(|n| n.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no node {name}"))
}

pub fn assert_close(actual: Vec3, expected: Vec3) {
    assert!(actual.abs_diff_eq(expected, 1e-5), "{actual} != {expected}");
}

/// The sample as one GLB: the buffer becomes the BIN chunk, the PNG a buffer view in it.
pub fn sample_glb() -> Vec<u8> {
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
