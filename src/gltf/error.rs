//! The error type of glTF loading. Every message starts with the file given to
//! [`load`](crate::gltf::load), then says what is wrong and where.

use std::io;
use std::path::PathBuf;

use crate::asset_io::AssetError;
use crate::diagnostic::{Report, SourceLines, Spot, more_problems};
use crate::scene::MAX_LISTED_PROBLEMS;

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
        /// Where in the JSON text the problem is, for showing its line
        /// ([`render_error`](crate::diagnostic::render_error)); not part of the message.
        json: JsonContext,
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

/// Where in a `.gltf` file's JSON text a [`GltfError::Invalid`] is, with the lines, so that
/// [`render_error`](crate::diagnostic::render_error) can show them.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum JsonContext {
    /// Not shown: a GLB container (binary), a problem of the container itself, or JSON that
    /// is not UTF-8.
    #[default]
    Unknown,
    /// A JSON syntax error or a value of the wrong type, where serde_json found it.
    Position {
        /// Line, from 1.
        line: usize,
        /// Column in characters, from 1 (serde_json counts bytes).
        column: usize,
        /// What is wrong, without the position.
        message: String,
        /// The line.
        source_lines: SourceLines,
    },
    /// Broken glTF rules, each at a JSON path like `meshes[0].primitives[0].indices`.
    Paths {
        /// Each problem: its JSON path, and what is wrong there.
        problems: Vec<(String, String)>,
        /// The line of each of the first problems whose path was found in the text.
        source_lines: SourceLines,
    },
}

impl GltfError {
    /// The problems of an invalid `.gltf` file with their lines, for
    /// [`render_error`](crate::diagnostic::render_error); `None` for other errors.
    pub(crate) fn report(&self) -> Option<Report<'_>> {
        let GltfError::Invalid { path, json, .. } = self else {
            return None;
        };
        let origin = path.display().to_string();
        match json {
            JsonContext::Unknown => None,
            JsonContext::Position {
                line,
                column,
                message,
                source_lines,
            } => Some(Report {
                origin,
                spots: vec![Spot {
                    at: Some((*line, *column)),
                    line: source_lines.get(0),
                    message: format!("not valid glTF: {message}"),
                    help: None,
                }],
                more: None,
            }),
            JsonContext::Paths { problems, source_lines } => {
                let spots = (problems.iter().take(MAX_LISTED_PROBLEMS).enumerate())
                    .map(|(i, (at, problem))| {
                        let line = source_lines.get(i);
                        Spot {
                            at: line.map(|l| (l.line, l.column)),
                            line,
                            message: format!("not valid glTF: {at}: {problem}"),
                            help: None,
                        }
                    })
                    .collect();
                let more = problems.len().saturating_sub(MAX_LISTED_PROBLEMS);
                Some(Report {
                    more: (more > 0).then(|| more_problems(&origin, more)),
                    origin,
                    spots,
                })
            }
        }
    }
}
