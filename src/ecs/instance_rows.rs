//! One mesh entity as a row of [`RenderInstances`], and the in-place update of the rows whose
//! entities moved (or were posed) while keeping their mesh, material and shadow flags: their
//! slots, sphere chunks and bounds are rewritten and listed in [`RenderInstances::updated`], so
//! the GPU copy is patched instead of uploaded whole.

use bevy_ecs::entity::Entity;
use bevy_transform::components::GlobalTransform;
use glam::{Mat3, Mat4, Vec3};

use crate::ecs::assets::{Materials, Meshes};
use crate::ecs::caster_changes::CasterState;
use crate::ecs::components::{Mesh3d, MeshMaterial3d};
use crate::ecs::draw_groups::DrawKey;
use crate::ecs::instances::{RECEIVER_GRID, RenderInstances};
use crate::ecs::placement::is_valid_placement;
use crate::ecs::skinning::SkinnedMesh;
use crate::math::aabb::Aabb;
use crate::shader::contract::INSTANCE_FLAG_RECEIVE_SHADOWS;
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
            world_from_local: self.world_from_local,
            normal_from_local: normal_from_local(&self.world_from_local),
            base_color: mat.base_color,
            alpha_cutoff: mat.alpha_cutoff(),
            flags: if self.receive { INSTANCE_FLAG_RECEIVE_SHADOWS } else { 0 },
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

/// The normal matrix of a placement: the inverse transpose of its linear part.
fn normal_from_local(world_from_local: &Mat4) -> Mat4 {
    Mat4::from_mat3(Mat3::from_mat4(*world_from_local).inverse().transpose())
}

/// True when `row` can replace instance `slot` in place: same draw key and shadow flags.
pub(crate) fn fits_in_place(out: &RenderInstances, slot: u32, row: &Row) -> bool {
    let i = slot as usize;
    let receives = out.gpu[i].flags & INSTANCE_FLAG_RECEIVE_SHADOWS != 0;
    out.keys[i] == row.key && receives == row.receive && (out.caster_index[i] != NOT_A_CASTER) == row.cast
}

/// Rewrites the instances of `rows` (`(slot, row)` pairs sorted by slot, each accepted by
/// [`fits_in_place`]) and refits their chunks; the bounds of all casters and receivers only
/// grow. Bumps the generation, keeps the layout, lists the slots in `updated` and returns the
/// casters' new states in `casters`.
pub(crate) fn update_in_place(
    out: &mut RenderInstances,
    rows: &[(u32, Row)],
    materials: &Materials,
    casters: &mut Vec<(Entity, CasterState)>,
) {
    out.updated.clear();
    casters.clear();
    let mut receivers = Aabb::EMPTY;
    for (slot, row) in rows {
        let i = *slot as usize;
        out.gpu[i] = row.gpu(materials);
        let (center, radius) = row.bounds.bounding_sphere();
        out.centers[i] = center;
        out.radii[i] = radius;
        if row.receive {
            receivers = receivers.union(row.bounds);
        }
        let c = out.caster_index[i];
        if c != NOT_A_CASTER {
            let c = c as usize;
            out.caster_centers[c] = center;
            out.caster_radii[c] = radius;
            out.caster_boxes[c] = row.bounds;
            let m = &mut out.mesh_caster_radius[row.key.mesh.0 as usize];
            *m = m.max(radius);
            out.caster_bounds = out.caster_bounds.union(row.bounds);
            casters.push((row.entity, row.caster_state()));
        }
        out.updated.push(*slot);
    }
    // NOTE: one refit per chunk touched (rows are sorted by slot, so equal chunks are adjacent).
    let mut last = usize::MAX;
    for &(slot, _) in rows {
        let chunk = slot as usize / crate::math::chunks::CHUNK;
        if chunk != last {
            out.chunks.refit(slot as usize, &out.centers, &out.radii);
            last = chunk;
        }
    }
    let mut last = usize::MAX;
    for &(slot, _) in rows {
        let c = out.caster_index[slot as usize];
        if c != NOT_A_CASTER && c as usize / crate::math::chunks::CHUNK != last {
            out.caster_chunks
                .refit(c as usize, &out.caster_centers, &out.caster_radii);
            last = c as usize / crate::math::chunks::CHUNK;
        }
    }
    if !receivers.is_empty() && out.receiver_bounds.union(receivers) != out.receiver_bounds {
        out.receiver_bounds = out.receiver_bounds.union(receivers).snapped_out(RECEIVER_GRID);
    }
    out.generation += 1;
}
