//! Reading the files user data names — scene textures and models, glTF buffers and images —
//! confined to one asset root, with bounded reads and bounded image decoding.
//!
//! A reference (a scene's `texture:` or `Gltf(path: …)`, a glTF URI after percent-decoding)
//! is a relative path resolved against the folder of the file that names it. It is refused,
//! with a message that says nothing about the target, when it is absolute, when `..` steps
//! out of the root (lexically or through a symbolic link), or when it names something other
//! than a regular file (a device, a pipe, a folder). Reads stop at a size cap (and at the size
//! a glTF buffer declares); images are decoded under [`image::Limits`]. Files are identified
//! by their canonical path, so one file reached by two spellings is one file.
//!
//! The root defaults to the nearest enclosing folder named `assets` (Bevy's convention),
//! else the folder of the scene or model being loaded; [`AssetIo::with_root`] sets it.

use std::fs::File;
use std::io::Read;
use std::path::{Component, Path, PathBuf};
use std::sync::Arc;

use thiserror::Error;

/// Default cap on one file read, in bytes (1 GiB).
pub const DEFAULT_MAX_FILE_BYTES: u64 = 1 << 30;
/// Default cap on one decoded image, in bytes of RGBA8 (256 MiB: 8192² pixels).
pub const DEFAULT_MAX_IMAGE_BYTES: u64 = 256 << 20;
/// Default budget of all a scene's decoded images together, in bytes of RGBA8 with their mip
/// chains (256 MiB: three 4096² images, or twelve 2048² ones). An 8192² image (341 MiB with
/// its mips) needs a larger one: building its mips on the CPU briefly takes 16 bytes a texel,
/// 1 GiB, which with the rest took a software-Vulkan render of two such images to 1.9 GiB.
pub const DEFAULT_MAX_TEXTURE_BYTES: u64 = 256 << 20;

/// Why an asset file could not be read. Messages leave out the reference itself: the
/// caller's message names it (like ``image 0 (`leaf.png`): no file at …``).
#[derive(Debug, Error, PartialEq, Eq)]
#[non_exhaustive]
pub enum AssetError {
    /// The reference is absolute, leaves the asset root, or is not a plain relative path.
    /// The message never says whether the target exists.
    #[error("outside the asset folder `{}` (only relative paths inside it are read)", root.display())]
    Outside {
        /// The reference as written (after percent-decoding).
        reference: String,
        /// The asset root.
        root: PathBuf,
    },
    /// Nothing readable at a path inside the root.
    #[error("no file at `{}`", path.display())]
    Missing {
        /// The reference as written.
        reference: String,
        /// Where it resolves to.
        path: PathBuf,
    },
    /// The path names a folder, a device, a pipe or another non-regular file.
    #[error("not a regular file")]
    NotAFile {
        /// The reference as written.
        reference: String,
    },
    /// The file is larger than the cap.
    #[error("{size} bytes, more than the {max} bytes allowed")]
    TooLarge {
        /// The reference as written.
        reference: String,
        /// Its size.
        size: u64,
        /// The cap.
        max: u64,
    },
    /// Reading failed.
    #[error("cannot read: {message}")]
    Read {
        /// The reference as written.
        reference: String,
        /// Why.
        message: String,
    },
    /// The bytes are not an image this build decodes, or decoding it would pass the limits.
    #[error("cannot decode: {message}")]
    Image {
        /// The reference as written (or what the bytes are, like "image 0 (buffer view 3)").
        reference: String,
        /// The decoder's reason.
        message: String,
    },
}

/// A file found inside the root: its canonical path.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct AssetPath(PathBuf);

impl AssetPath {
    /// The canonical path.
    pub fn path(&self) -> &Path {
        &self.0
    }

    /// The folder the file is in (relative references in it resolve against this).
    pub fn dir(&self) -> &Path {
        self.0.parent().unwrap_or(&self.0)
    }
}

/// The asset root, the read limits, and the tally of decoded images against the texture
/// budget (shared by clones: one scene's loads draw on one budget).
#[derive(Clone, Debug)]
pub struct AssetIo {
    root: PathBuf,
    /// Largest file read, in bytes.
    pub max_file_bytes: u64,
    /// Largest decoded image, in bytes of RGBA8.
    pub max_image_bytes: u64,
    /// Most bytes of all decoded images together, RGBA8 with their mip chains: an image
    /// that would pass it is downscaled to fit, with a note ([`take_notes`](Self::take_notes)).
    pub max_texture_bytes: u64,
    tally: Arc<TextureTally>,
}

impl PartialEq for AssetIo {
    /// The same root and limits (the tallies are not compared).
    fn eq(&self, other: &Self) -> bool {
        (
            &self.root,
            self.max_file_bytes,
            self.max_image_bytes,
            self.max_texture_bytes,
        ) == (
            &other.root,
            other.max_file_bytes,
            other.max_image_bytes,
            other.max_texture_bytes,
        )
    }
}

impl Eq for AssetIo {}

impl AssetIo {
    /// An asset root at `root` (made absolute and canonical where it exists) with the default
    /// limits.
    pub fn with_root(root: impl AsRef<Path>) -> Self {
        let root = root.as_ref();
        let root = std::fs::canonicalize(root).unwrap_or_else(|_| std::path::absolute(root).unwrap_or(root.to_owned()));
        Self {
            root,
            max_file_bytes: DEFAULT_MAX_FILE_BYTES,
            max_image_bytes: DEFAULT_MAX_IMAGE_BYTES,
            max_texture_bytes: DEFAULT_MAX_TEXTURE_BYTES,
            tally: Arc::default(),
        }
    }

    /// The default root for a file at `file` (a scene or a model): the nearest enclosing
    /// folder named `assets`, else the file's own folder.
    pub fn for_file(file: &Path) -> Self {
        Self::for_dir(file.parent().unwrap_or(Path::new("")))
    }

    /// The default root for files named from `dir` (the current folder when empty): the
    /// nearest enclosing folder named `assets`, else `dir` itself.
    pub fn for_dir(dir: &Path) -> Self {
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        let dir = std::fs::canonicalize(dir).unwrap_or(dir.to_owned());
        let assets = dir.ancestors().find(|a| a.file_name().is_some_and(|n| n == "assets"));
        Self::with_root(assets.unwrap_or(&dir))
    }

    /// The asset root.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// Resolves `reference` (relative, `/`-separated) against the folder `dir` (inside the
    /// root) to a regular file inside the root.
    pub fn resolve(&self, dir: &Path, reference: &str) -> Result<AssetPath, AssetError> {
        let outside = || AssetError::Outside {
            reference: reference.to_owned(),
            root: self.root.clone(),
        };
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        let dir = std::fs::canonicalize(dir).map_err(|_| outside())?;
        let relative = Path::new(reference);
        if reference.is_empty() || reference.contains('\0') || relative.has_root() {
            return Err(outside());
        }
        // NOTE: `..` is resolved lexically first, so that a path that leaves the root is refused
        // without touching the file system outside it.
        let mut lexical = dir.strip_prefix(&self.root).map_err(|_| outside())?.to_owned();
        for part in relative.components() {
            match part {
                Component::Normal(name) => lexical.push(name),
                Component::CurDir => {}
                Component::ParentDir => {
                    if !lexical.pop() {
                        return Err(outside());
                    }
                }
                Component::Prefix(_) | Component::RootDir => return Err(outside()),
            }
        }
        let joined = self.root.join(&lexical);
        let canonical = std::fs::canonicalize(&joined).map_err(|_| AssetError::Missing {
            reference: reference.to_owned(),
            path: joined.clone(),
        })?;
        // A symbolic link inside the root may point out of it.
        if !canonical.starts_with(&self.root) {
            return Err(outside());
        }
        match std::fs::metadata(&canonical) {
            Ok(meta) if meta.is_file() => Ok(AssetPath(canonical)),
            Ok(_) => Err(AssetError::NotAFile {
                reference: reference.to_owned(),
            }),
            Err(_) => Err(AssetError::Missing {
                reference: reference.to_owned(),
                path: joined,
            }),
        }
    }

    /// Reads a resolved file whole, refusing files over the cap (or over `expected` bytes,
    /// when the caller knows how much it needs: only that much is read).
    pub fn read(&self, file: &AssetPath, reference: &str, expected: Option<u64>) -> Result<Vec<u8>, AssetError> {
        let read_error = |e: std::io::Error| AssetError::Read {
            reference: reference.to_owned(),
            message: e.to_string(),
        };
        let handle = File::open(file.path()).map_err(read_error)?;
        let meta = handle.metadata().map_err(read_error)?;
        if !meta.is_file() {
            return Err(AssetError::NotAFile {
                reference: reference.to_owned(),
            });
        }
        let size = meta.len();
        let wanted = expected.map_or(size, |e| e.min(size));
        if wanted > self.max_file_bytes {
            return Err(AssetError::TooLarge {
                reference: reference.to_owned(),
                size: wanted,
                max: self.max_file_bytes,
            });
        }
        let mut bytes = Vec::with_capacity(wanted as usize);
        handle.take(wanted).read_to_end(&mut bytes).map_err(read_error)?;
        Ok(bytes)
    }
}

mod decode;

pub use decode::{TextureTally, mip_chain_bytes};
