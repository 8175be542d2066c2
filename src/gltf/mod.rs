//! glTF 2.0 models as pure data: meshes, materials, decoded images and the flattened node
//! hierarchy of one scene, read from `.gltf` (JSON with external or `data:` buffers and
//! images) or `.glb` files.
//!
//! [`load`] never panics on user data: buffer lengths, buffer views, accessors (offset,
//! count, stride, element size, sparse storage) and indices are checked before anything is
//! read, and every [`GltfError`] message names the file and the problem. What is skipped or
//! approximated (line and point primitives, computed normals, blended materials, ...) is
//! listed in [`GltfModel::warnings`].
//!
//! Nothing here touches the renderer or the ECS; [`sample`] builds the procedural fern
//! model shipped in `assets/models/`.

mod accessor;
mod error;
mod json_path;
mod load;
mod material;
mod mesh;
mod nodes;
pub mod sample;

use std::path::Path;

use glam::{Mat4, Vec4};

use crate::asset_io::AssetIo;
use crate::ecs::assets::{AlphaMode, ImageData};
use crate::mesh::MeshData;

pub use error::{GltfError, JsonContext};
pub use mesh::{MAX_MODEL_INDICES, MAX_MODEL_VERTICES, MAX_PRIMITIVE_INDICES, MAX_PRIMITIVE_VERTICES};
pub use nodes::{MAX_DRAWN_PRIMITIVES, MAX_NODE_VISITS};

/// Everything penumbra uses from a glTF file.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfModel {
    /// Meshes; the index is the glTF mesh index.
    pub meshes: Vec<GltfMesh>,
    /// Materials; the index is the glTF material index.
    pub materials: Vec<GltfMaterial>,
    /// Distinct images decoded to RGBA8 (glTF images that name one file share an entry);
    /// [`GltfMaterial::base_color_texture`] indexes this list.
    pub images: Vec<ImageData>,
    /// Every node with a mesh in the loaded scene, flattened, depth first in file order.
    pub nodes: Vec<GltfNodeInstance>,
    /// Things skipped or approximated while loading, human readable, one per entry.
    pub warnings: Vec<String>,
}

/// A glTF mesh: its triangle primitives.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfMesh {
    /// The mesh's name in the file.
    pub name: Option<String>,
    /// Triangle primitives in file order. Point and line primitives are skipped (with a
    /// warning), so an index here may differ from the glTF primitive index.
    pub primitives: Vec<GltfPrimitive>,
}

/// One primitive of a mesh, converted to an indexed triangle list.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfPrimitive {
    /// Vertices (position, normal, `TEXCOORD_0`) and triangle-list indices.
    pub mesh: MeshData,
    /// Index into [`GltfModel::materials`]; `None` for glTF's default material.
    pub material: Option<usize>,
}

/// The parts of a glTF metallic-roughness material that shadows and the forward pass use.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfMaterial {
    /// The material's name in the file.
    pub name: Option<String>,
    /// Linear RGBA base colour factor, multiplied with the texture.
    pub base_color: Vec4,
    /// Index into [`GltfModel::images`] of the base-colour texture's image.
    pub base_color_texture: Option<usize>,
    /// Opaque or alpha-masked; glTF's `BLEND` becomes `Mask(0.5)` with a warning.
    pub alpha_mode: AlphaMode,
    /// Whether back faces are drawn (and cast shadows) too.
    pub double_sided: bool,
    /// `KHR_materials_diffuse_transmission`'s `diffuseTransmissionFactor` (0 without the
    /// extension): the share of light a thin double-sided surface passes to its other side.
    pub transmission: f32,
}

/// A node of the scene that draws a mesh, with its transform composed through its ancestors.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfNodeInstance {
    /// Index into [`GltfModel::meshes`].
    pub mesh: usize,
    /// Mesh space to model (scene root) space: the product of every ancestor's local
    /// matrix and the node's own, parent first.
    pub model_from_mesh: Mat4,
    /// The node's name in the file.
    pub name: Option<String>,
}

/// Loads a `.gltf` or `.glb` file. External buffers and images are resolved relative to the
/// file's directory, inside the default asset root of [`AssetIo::for_file`]. The scene drawn
/// is the file's `scene`, else scene 0, else every root node.
pub fn load(path: &Path) -> Result<GltfModel, GltfError> {
    load::load(path, &AssetIo::for_file(path))
}

/// Like [`load`], with URIs confined to `io`'s asset root and read under its limits.
pub fn load_with(path: &Path, io: &AssetIo) -> Result<GltfModel, GltfError> {
    load::load(path, io)
}
