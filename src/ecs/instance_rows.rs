//! One mesh entity as a row of the instance list
//! ([`RenderInstances`](crate::ecs::instances::RenderInstances)): what the instance sync reads
//! of it, its draw key, placement, bounds and GPU data.

use bevy_ecs::entity::Entity;
use bevy_transform::components::GlobalTransform;
use glam::{Mat4, Vec3};

use crate::ecs::assets::{Materials, Meshes};
use crate::ecs::caster_changes::CasterState;
use crate::ecs::components::{Mesh3d, MeshMaterial3d};
use crate::ecs::draw_groups::DrawKey;
use crate::ecs::placement::is_valid_placement;
use crate::ecs::skinning::SkinnedMesh;
use crate::math::aabb::Aabb;
use crate::shader::contract::{INSTANCE_FLAG_RECEIVE_SHADOWS, INSTANCE_FLAG_UNTEXTURED};
use crate::shader::instance::InstanceGpu;

/// Marks an instance that casts no shadow in [`RenderInstances`]' caster index.
pub(crate) const NOT_A_CASTER: u32 = u32::MAX;

/// What the instance sync reads of a mesh entity.
pub(crate) type InstanceQueryData = (
    Entity,
    &'static GlobalTransform,
    &'static Mesh3d,
    &'static MeshMaterial3d,
    bevy_ecs::query::Has<crate::ecs::components::NotShadowCaster>,
    bevy_ecs::query::Has<crate::ecs::components::NotShadowReceiver>,
    Option<&'static SkinnedMesh>,
);

/// One item of [`InstanceQueryData`].
pub(crate) type InstanceQueryItem<'a> = (
    Entity,
    &'a GlobalTransform,
    &'a Mesh3d,
    &'a MeshMaterial3d,
    bool,
    bool,
    Option<&'a SkinnedMesh>,
);

/// One drawable instance, before it is placed in the list.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Row {
    /// Mesh and material.
    pub key: DrawKey,
    /// The entity drawn.
    pub entity: Entity,
    /// Placement, relative to the render origin.
    pub world_from_local: Mat4,
    /// Casts shadows.
    pub cast: bool,
    /// Receives shadows.
    pub receive: bool,
    /// World bounds, relative to the render origin.
    pub bounds: Aabb,
    /// The skinned pose (0 without a skin).
    pub pose: u64,
}

/// Why an entity is not drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Skip {
    /// Its mesh or material is not in the stores.
    MissingAsset,
    /// Its transform is not finite or has a zero scale.
    BadPlacement,
}

impl Row {
    /// The row of one mesh entity, relative to `origin`.
    pub fn of(item: InstanceQueryItem<'_>, meshes: &Meshes, materials: &Materials, origin: Vec3) -> Result<Row, Skip> {
        let (entity, transform, mesh, material, no_cast, no_receive, skin) = item;
        let (Some(mesh_data), Some(mat)) = (meshes.get(mesh.0), materials.get(material.0)) else {
            return Err(Skip::MissingAsset);
        };
        if !is_valid_placement(transform) {
            return Err(Skip::BadPlacement);
        }
        // Relative to the render origin (exact: the origin is on a power-of-two grid).
        let mut world_from_local = transform.to_matrix();
        world_from_local.w_axis -= origin.extend(0.0);
        // NOTE: a skinned mesh is bounded by its posed joints, never by its rest pose.
        let (local_bounds, pose) = match skin {
            Some(s) if !s.bounds.is_empty() => (s.bounds, s.pose),
            _ => (mesh_data.bounds(), 0),
        };
        Ok(Row {
            key: DrawKey {
                masked: mat.is_masked(),
                double_sided: mat.double_sided,
                mesh: mesh.0,
                material: material.0,
            },
            entity,
            world_from_local,
            cast: !no_cast,
            receive: !no_receive,
            bounds: local_bounds.transformed(&world_from_local),
            pose,
        })
    }

    /// The row's GPU data.
    pub fn gpu(&self, materials: &Materials) -> InstanceGpu {
        let mat = &materials.as_slice()[self.key.material.0 as usize];
        InstanceGpu {
            world_rows: InstanceGpu::world_rows(&self.world_from_local),
            base_color: mat.base_color,
            alpha_cutoff: mat.alpha_cutoff(),
            flags: if self.receive { INSTANCE_FLAG_RECEIVE_SHADOWS } else { 0 }
                | if mat.is_untextured() {
                    INSTANCE_FLAG_UNTEXTURED
                } else {
                    0
                },
            transmission: mat.effective_transmission(),
            _pad: 0,
        }
    }

    /// What the view caches remember of the row as a caster.
    pub fn caster_state(&self) -> CasterState {
        CasterState {
            bounds: self.bounds,
            key: self.key,
            pose: self.pose,
        }
    }
}
