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
mod animation;
mod error;
mod json_path;
mod load;
mod material;
mod mesh;
mod nodes;
pub mod pose;
pub mod sample;
mod skin;

use std::path::Path;

use glam::{Mat4, Quat, Vec3, Vec4};

use crate::asset_io::AssetIo;
use crate::ecs::assets::{AlphaMode, ImageData};
pub use crate::math::pose::NodeProperty;
use crate::math::skinning::JointWeights;
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
    /// Every node of the file, in index order: parents and rest transforms, which skins'
    /// joints and animations name.
    pub hierarchy: Vec<GltfNode>,
    /// Skins; the index is the glTF skin index.
    pub skins: Vec<GltfSkin>,
    /// Animations of node translations, rotations and scales.
    pub animations: Vec<GltfAnimation>,
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
    /// Each vertex's joints and weights (`JOINTS_0`, `WEIGHTS_0`, normalised), for a
    /// skinned primitive.
    pub influences: Option<Vec<JointWeights>>,
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
    /// The node's index in the file.
    pub node: usize,
    /// Index into [`GltfModel::skins`] of the node's skin.
    pub skin: Option<usize>,
}

/// One node of the file: its parent and its rest transform (translation, rotation, scale;
/// a matrix in the file is decomposed).
#[derive(Clone, Debug, PartialEq)]
pub struct GltfNode {
    /// The node's name in the file.
    pub name: Option<String>,
    /// The node whose child it is.
    pub parent: Option<usize>,
    /// Rest translation.
    pub translation: Vec3,
    /// Rest rotation, unit length.
    pub rotation: Quat,
    /// Rest scale.
    pub scale: Vec3,
}

/// A skin: the nodes that are its joints, and for each the inverse bind matrix that takes the
/// mesh's bind space into the joint's space.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfSkin {
    /// The skin's name in the file.
    pub name: Option<String>,
    /// Node indices of the joints (at most [`MAX_JOINTS`](crate::math::skinning::MAX_JOINTS)).
    pub joints: Vec<usize>,
    /// One invertible matrix per joint (identity where the file gives none).
    pub inverse_bind: Vec<Mat4>,
}

/// An animation: channels that move nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfAnimation {
    /// The animation's name in the file.
    pub name: Option<String>,
    /// Node channels (morph-target weights are skipped).
    pub channels: Vec<GltfChannel>,
}

impl GltfAnimation {
    /// The last key time of any channel, seconds.
    pub fn duration(&self) -> f32 {
        self.channels.iter().map(|c| c.property.duration()).fold(0.0, f32::max)
    }
}

/// One channel: a track of one node's translation, rotation or scale.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfChannel {
    /// Index into [`GltfModel::hierarchy`].
    pub node: usize,
    /// The property and its track.
    pub property: NodeProperty,
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
