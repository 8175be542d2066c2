//! A scene object's glTF model: loaded and added to the prepared scene's stores with the
//! `gltf` feature, and a clear error without it.

use crate::app::spawn::{MeshPart, PreparedScene, SpawnError};
use crate::asset_io::{AssetIo, AssetPath};
#[cfg(feature = "gltf")]
use crate::ecs::assets::{ImageHandle, Material};
#[cfg(feature = "gltf")]
use crate::gltf;

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
        let model = gltf::load_with(file, io).map_err(|e| SpawnError::Model {
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
        self.images.extend(model.images);
        // Mesh index of each primitive, per glTF mesh.
        let mut primitives: Vec<Vec<(usize, Option<usize>)>> = Vec::with_capacity(model.meshes.len());
        for mesh in model.meshes {
            let mut list = Vec::with_capacity(mesh.primitives.len());
            for primitive in mesh.primitives {
                self.meshes.push(primitive.mesh);
                list.push((self.meshes.len() - 1, primitive.material.map(|m| first_material + m)));
            }
            primitives.push(list);
        }
        Ok(model
            .nodes
            .iter()
            .flat_map(|node| {
                let list = primitives.get(node.mesh).map_or(&[][..], Vec::as_slice);
                list.iter().map(move |&(mesh, material)| MeshPart {
                    mesh,
                    material,
                    object_from_mesh: node.model_from_mesh,
                })
            })
            .collect())
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
