//! The error type of glTF loading. Every message starts with the file given to
//! [`load`](crate::gltf::load), then says what is wrong and where.

use std::io;
use std::path::PathBuf;

use crate::asset_io::AssetError;

/// Why a glTF file could not be loaded.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GltfError {
    /// The `.gltf` or `.glb` file itself could not be read.
    #[error("{}: cannot read: {source}", path.display())]
    Io {
        /// The file given to [`load`](crate::gltf::load).
        path: PathBuf,
        /// The underlying error.
        source: io::Error,
    },
    /// Not glTF: a broken GLB container, malformed JSON, or JSON that breaks glTF's rules
    /// (an index to nothing, a missing required property, an unsupported required extension).
    #[error("{}: not valid glTF: {message}", path.display())]
    Invalid {
        /// The file given to [`load`](crate::gltf::load).
        path: PathBuf,
        /// What is wrong, with the JSON path where the rules are broken.
        message: String,
    },
    /// An external buffer or image could not be used: its URI leaves the asset folder or
    /// names no regular file, it is larger than allowed, or it cannot be read or decoded.
    #[error("{}: {what}: {source}", path.display())]
    Asset {
        /// The file given to [`load`](crate::gltf::load).
        path: PathBuf,
        /// The referring object and its URI, like ``buffer 0 (`fern.bin`)``.
        what: String,
        /// What is wrong.
        source: AssetError,
    },
    /// A buffer holds fewer bytes than its `byteLength` declares.
    #[error("{}: {what} is truncated: {actual} bytes, {declared} declared", path.display())]
    Truncated {
        /// The file given to [`load`](crate::gltf::load).
        path: PathBuf,
        /// The buffer and where its bytes come from, like ``buffer 0 (`fern.bin`)``.
        what: String,
        /// Bytes available.
        actual: u64,
        /// The buffer's `byteLength`.
        declared: u64,
    },
    /// A mesh primitive has no `POSITION` attribute.
    #[error("{}: mesh {mesh} primitive {primitive} has no POSITION attribute", path.display())]
    MissingPosition {
        /// The file given to [`load`](crate::gltf::load).
        path: PathBuf,
        /// glTF mesh index.
        mesh: usize,
        /// glTF primitive index within the mesh.
        primitive: usize,
    },
    /// A vertex index is not below the primitive's vertex count.
    #[error(
        "{}: mesh {mesh} primitive {primitive}: index {index} out of range ({vertices} vertices)",
        path.display()
    )]
    IndexOutOfRange {
        /// The file given to [`load`](crate::gltf::load).
        path: PathBuf,
        /// glTF mesh index.
        mesh: usize,
        /// glTF primitive index within the mesh.
        primitive: usize,
        /// The offending index.
        index: u32,
        /// The primitive's vertex count.
        vertices: usize,
    },
    /// A node is its own ancestor, so the hierarchy has no end.
    #[error("{}: node {node} is its own ancestor: {chain}", path.display())]
    NodeCycle {
        /// The file given to [`load`](crate::gltf::load).
        path: PathBuf,
        /// The node met twice on one path from the scene root.
        node: usize,
        /// The path that loops, like `node 0 → node 2 → node 0`.
        chain: String,
    },
    /// The data the JSON describes is inconsistent or unusable: a buffer view or accessor
    /// outside its storage, an unsupported accessor type, a non-finite position, a
    /// hierarchy too deep, ...
    #[error("{}: {context}: {problem}", path.display())]
    Data {
        /// The file given to [`load`](crate::gltf::load).
        path: PathBuf,
        /// The object at fault, like `mesh 0 primitive 1` or `buffer view 3`.
        context: String,
        /// What is wrong with it.
        problem: String,
    },
}
