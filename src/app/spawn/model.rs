//! A scene object's glTF model: loaded and added to the prepared scene's stores with the
//! `gltf` feature, and a clear error without it.

use crate::app::spawn::{MeshPart, PreparedScene, SpawnError};
use crate::asset_io::{AssetIo, AssetPath};
#[cfg(feature = "gltf")]
use crate::ecs::assets::{ImageHandle, Material};
#[cfg(feature = "gltf")]
use crate::gltf;
#[cfg(feature = "gltf")]
use crate::{
    app::spawn::skinned::SkinPart, ecs::skinning::SkinSource, math::pose::Skeleton, math::skinning::JointWeights,
};
#[cfg(feature = "gltf")]
use glam::Mat4;
#[cfg(feature = "gltf")]
use std::{collections::HashMap, sync::Arc};

/// One primitive of a loaded model, as the prepared scene holds it.
#[cfg(feature = "gltf")]
struct Primitive {
    /// Index into the prepared meshes.
    mesh: usize,
    /// The model's own material, if any.
    material: Option<usize>,
    /// Joints and weights of a skinned primitive.
    influences: Option<Vec<JointWeights>>,
}

impl PreparedScene {
    /// Loads a glTF model and adds its images, materials and one mesh per primitive (its
    /// primitives without a material use the object's).
    #[cfg(feature = "gltf")]
    pub(super) fn add_model(
        &mut self,
        file: &AssetPath,
        io: &AssetIo,
        object: usize,
    ) -> Result<Vec<MeshPart>, SpawnError> {
        let file = file.path();
        let mut model = gltf::load_with(file, io).map_err(|e| SpawnError::Model {
            object,
            message: e.to_string(),
            error: Some(Box::new(e)),
        })?;
        for warning in &model.warnings {
            log::warn!("{}: {warning}", file.display());
        }
        let first_image = self.images.len();
        let first_material = self.materials.len();
        self.materials.extend(model.materials.iter().map(|m| Material {
            base_color: m.base_color,
            base_color_texture: m.base_color_texture.map(|i| ImageHandle((first_image + i) as u32)),
            alpha_mode: m.alpha_mode,
            double_sided: m.double_sided,
            transmission: m.transmission,
        }));
        self.images.append(&mut model.images);
        // Mesh index, material and influences of each primitive, per glTF mesh.
        let mut primitives: Vec<Vec<Primitive>> = Vec::with_capacity(model.meshes.len());
        let skeletons: Vec<Option<Arc<Skeleton>>> = (0..model.skins.len())
            .map(|s| model.skeleton(s).map(Arc::new))
            .collect();
        for mesh in std::mem::take(&mut model.meshes) {
            let mut list = Vec::with_capacity(mesh.primitives.len());
            for primitive in mesh.primitives {
                self.meshes.push(primitive.mesh);
                list.push(Primitive {
                    mesh: self.meshes.len() - 1,
                    material: primitive.material.map(|m| first_material + m),
                    influences: primitive.influences,
                });
            }
            primitives.push(list);
        }
        // A skinned node's primitives deform one bind pose per (primitive, skin); the node's
        // own transform is not used (its joints place it).
        let mut sources: HashMap<(usize, usize), usize> = HashMap::new();
        let mut skeleton_slots: HashMap<usize, usize> = HashMap::new();
        let mut parts = Vec::new();
        for node in &model.nodes {
            for p in primitives.get(node.mesh).map_or(&[][..], Vec::as_slice) {
                let skin = match (node.skin, &p.influences) {
                    (Some(s), Some(influences)) => skeletons.get(s).cloned().flatten().map(|skeleton| {
                        let joints = skeleton.joints.len();
                        let skeleton = *skeleton_slots.entry(s).or_insert_with(|| {
                            self.skeletons.push(skeleton);
                            self.skeletons.len() - 1
                        });
                        let source = *sources.entry((p.mesh, s)).or_insert_with(|| {
                            let vertices = self.meshes[p.mesh].vertices.clone();
                            self.skin_sources
                                .push(SkinSource::new(vertices, influences.clone(), joints));
                            self.skin_sources.len() - 1
                        });
                        SkinPart { source, skeleton }
                    }),
                    _ => None,
                };
                parts.push(MeshPart {
                    mesh: p.mesh,
                    material: p.material,
                    object_from_mesh: if skin.is_some() {
                        Mat4::IDENTITY
                    } else {
                        node.model_from_mesh
                    },
                    skin,
                });
            }
        }
        Ok(parts)
    }

    /// Without the `gltf` feature a model cannot be loaded: says so, naming the object and
    /// the file.
    #[cfg(not(feature = "gltf"))]
    pub(super) fn add_model(
        &mut self,
        file: &AssetPath,
        _io: &AssetIo,
        object: usize,
    ) -> Result<Vec<MeshPart>, SpawnError> {
        Err(SpawnError::Model {
            object,
            message: format!(
                "{}: cannot load the glTF model: penumbra was built without its `gltf` feature",
                file.path().display()
            ),
            error: None,
        })
    }
}
