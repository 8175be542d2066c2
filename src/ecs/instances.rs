//! The flat, sorted list of mesh instances the renderer and the culling work on. It is
//! rebuilt only when an instance is added, removed or changed, so a static scene costs
//! nothing per frame here.

use bevy_ecs::change_detection::DetectChanges;
use bevy_ecs::entity::Entity;
use bevy_ecs::lifecycle::RemovedComponents;
use bevy_ecs::query::{Changed, Has, Or, With};
use bevy_ecs::resource::Resource;
use bevy_ecs::system::{Local, Query, Res, ResMut};
use bevy_transform::components::GlobalTransform;
use glam::{Mat4, Vec3};
use log::warn;

use std::collections::HashMap;

use crate::ecs::assets::{Materials, Meshes};
use crate::ecs::caster_changes::{CasterChanges, CasterState};
use crate::ecs::components::{Mesh3d, MeshMaterial3d, NotShadowCaster, NotShadowReceiver};
pub use crate::ecs::draw_groups::DrawKey;
use crate::ecs::origin::RenderOrigin;
use crate::ecs::placement::is_valid_placement;
use crate::ecs::shadow_lods::ShadowLods;
use crate::ecs::skinning::SkinnedMesh;
use crate::math::aabb::Aabb;
use crate::math::chunks::SphereChunks;
use crate::shader::contract::INSTANCE_FLAG_RECEIVE_SHADOWS;
use crate::shader::instance::InstanceGpu;

/// Cells per side of the grid the receivers' bounds given to the cascades are grown onto
/// ([`Aabb::snapped_out`]): a receiver moving inside them leaves every cascade as it was.
const RECEIVER_GRID: f32 = 256.0;

/// Every drawable instance, sorted by [`DrawKey`] and, within a key, along a Morton curve
/// through the scene (so consecutive instances are close in space and cull together), in
/// structure-of-arrays form. Positions and transforms are relative to [`RenderOrigin`].
#[derive(Resource, Debug, Default)]
pub struct RenderInstances {
    /// GPU data, in draw order; index = instance index.
    pub gpu: Vec<InstanceGpu>,
    /// Draw key per instance.
    pub keys: Vec<DrawKey>,
    /// World bounding-sphere centre per instance.
    pub centers: Vec<Vec3>,
    /// World bounding-sphere radius per instance.
    pub radii: Vec<f32>,
    /// Instance indices of shadow casters, in draw order.
    pub casters: Vec<u32>,
    /// Bounding-sphere centres of the casters (parallel to `casters`).
    pub caster_centers: Vec<Vec3>,
    /// Bounding-sphere radii of the casters (parallel to `casters`).
    pub caster_radii: Vec<f32>,
    /// World bounds of each caster (relative to the render origin), parallel to `casters`.
    pub caster_boxes: Vec<Aabb>,
    /// Per mesh handle: the largest bounding radius of its casters (0 for none), which
    /// picks its shadow LOD ([`ShadowLods`]).
    pub mesh_caster_radius: Vec<f32>,
    /// Number of leading casters with opaque materials; the rest are masked.
    pub opaque_casters: usize,
    /// Chunk spheres of the casters (for chunked cascade culling).
    pub caster_chunks: SphereChunks,
    /// Chunk spheres of all instances (for chunked camera culling).
    pub chunks: SphereChunks,
    /// World bounds of all casters.
    pub caster_bounds: Aabb,
    /// World bounds of everything that receives shadows, grown onto a grid of 1/256 of their
    /// size ([`Aabb::snapped_out`]) so that objects moving inside them leave them unchanged.
    pub receiver_bounds: Aabb,
    /// The render origin every position here is relative to.
    pub origin: Vec3,
    /// Bumped on every rebuild, so the renderer knows to re-upload.
    pub generation: u64,
    /// Entities skipped because of an invalid transform, mesh or material.
    pub skipped: usize,
}

type InstanceQueryData = (
    Entity,
    &'static GlobalTransform,
    &'static Mesh3d,
    &'static MeshMaterial3d,
    Has<NotShadowCaster>,
    Has<NotShadowReceiver>,
    Option<&'static SkinnedMesh>,
);
type InstanceQueryItem<'a> = (
    Entity,
    &'a GlobalTransform,
    &'a Mesh3d,
    &'a MeshMaterial3d,
    bool,
    bool,
    Option<&'a SkinnedMesh>,
);

/// Rebuilds [`RenderInstances`] when any mesh entity, mesh or material changed.
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
pub fn sync_instances(
    mut instances: ResMut<RenderInstances>,
    all: Query<InstanceQueryData>,
    // NOTE: only mesh entities count; a moving camera must not trigger a rebuild. One
    // query per component: a still frame scans every entity of each, and single-filter
    // loops run several times faster than one loop over an `Or` of them.
    moved: Query<(), (With<Mesh3d>, Changed<GlobalTransform>)>,
    meshes_changed: Query<(), Changed<Mesh3d>>,
    materials_changed: Query<(), (With<Mesh3d>, Changed<MeshMaterial3d>)>,
    flags_changed: Query<(), (With<Mesh3d>, Or<(Changed<NotShadowCaster>, Changed<NotShadowReceiver>)>)>,
    posed: Query<(), (With<Mesh3d>, Changed<SkinnedMesh>)>,
    mut removed_meshes: RemovedComponents<Mesh3d>,
    mut removed_non_casters: RemovedComponents<NotShadowCaster>,
    mut removed_receivers: RemovedComponents<NotShadowReceiver>,
    meshes: Res<Meshes>,
    materials: Res<Materials>,
    lods: Option<Res<ShadowLods>>,
    origin: Res<RenderOrigin>,
    mut changes: ResMut<CasterChanges>,
    mut casters_before: Local<HashMap<Entity, CasterState>>,
) {
    let removed = removed_meshes.read().count() + removed_non_casters.read().count() + removed_receivers.read().count();
    let everything = instances.generation == 0
        || meshes.is_changed()
        || materials.is_changed()
        || lods.is_some_and(|l| l.is_changed())
        || instances.origin != origin.0;
    let changed = || {
        !moved.is_empty()
            || !meshes_changed.is_empty()
            || !materials_changed.is_empty()
            || !flags_changed.is_empty()
            || !posed.is_empty()
    };
    if !everything && removed == 0 && !changed() {
        return;
    }
    let casters = rebuild(&mut instances, all.iter(), &meshes, &materials, origin.0);
    changes.record(
        instances.generation,
        everything,
        &mut casters_before,
        casters.into_iter(),
    );
}

/// Rebuilds the instance list from scratch; returns the state of every caster.
fn rebuild<'a>(
    out: &mut RenderInstances,
    items: impl Iterator<Item = InstanceQueryItem<'a>>,
    meshes: &Meshes,
    materials: &Materials,
    origin: Vec3,
) -> Vec<(Entity, CasterState)> {
    let mut rows: Vec<(DrawKey, Entity, Mat4, bool, bool, Aabb, u64)> = Vec::new();
    let mut skipped = 0;
    for (entity, transform, mesh, material, no_cast, no_receive, skin) in items {
        let (Some(mesh_data), Some(mat)) = (meshes.get(mesh.0), materials.get(material.0)) else {
            warn!("entity {entity:?} refers to a missing mesh or material; it is not drawn");
            skipped += 1;
            continue;
        };
        if !is_valid_placement(transform) {
            warn!("entity {entity:?} has a non-finite or zero-scale transform {transform:?}; it is not drawn");
            skipped += 1;
            continue;
        }
        // Relative to the render origin (exact: the origin is on a power-of-two grid).
        let mut world_from_local = transform.to_matrix();
        world_from_local.w_axis -= origin.extend(0.0);
        // NOTE: a skinned mesh is bounded by its posed joints, never by its rest pose.
        let (local_bounds, pose) = match skin {
            Some(s) if !s.bounds.is_empty() => (s.bounds, s.pose),
            _ => (mesh_data.bounds(), 0),
        };
        let bounds = local_bounds.transformed(&world_from_local);
        let key = DrawKey {
            masked: mat.is_masked(),
            double_sided: mat.double_sided,
            mesh: mesh.0,
            material: material.0,
        };
        rows.push((key, entity, world_from_local, !no_cast, !no_receive, bounds, pose));
    }
    // NOTE: within a draw key, instances follow a Morton curve through the scene bounds so
    // culling chunks are compact; the entity tie-break keeps the order (and so the image)
    // identical from run to run.
    let scene = rows.iter().fold(Aabb::EMPTY, |b, r| b.union(r.5));
    rows.sort_by_cached_key(|r| (r.0, morton_code(&scene, r.5.center()), r.1));

    out.gpu.clear();
    out.keys.clear();
    out.centers.clear();
    out.radii.clear();
    out.casters.clear();
    out.caster_centers.clear();
    out.caster_radii.clear();
    out.caster_boxes.clear();
    out.mesh_caster_radius.clear();
    out.caster_bounds = Aabb::EMPTY;
    out.receiver_bounds = Aabb::EMPTY;
    out.opaque_casters = 0;
    for (i, (key, _, world_from_local, cast, receive, bounds, _)) in rows.iter().enumerate() {
        let mat = &materials.as_slice()[key.material.0 as usize];
        let normal = Mat4::from_mat3(glam::Mat3::from_mat4(*world_from_local).inverse().transpose());
        out.gpu.push(InstanceGpu {
            world_from_local: *world_from_local,
            normal_from_local: normal,
            base_color: mat.base_color,
            alpha_cutoff: mat.alpha_cutoff(),
            flags: if *receive { INSTANCE_FLAG_RECEIVE_SHADOWS } else { 0 },
            transmission: mat.effective_transmission(),
            _pad: 0,
        });
        if *receive {
            out.receiver_bounds = out.receiver_bounds.union(*bounds);
        }
        let (center, radius) = bounds.bounding_sphere();
        out.keys.push(*key);
        out.centers.push(center);
        out.radii.push(radius);
        if *cast {
            out.casters.push(i as u32);
            out.caster_centers.push(center);
            out.caster_radii.push(radius);
            out.caster_boxes.push(*bounds);
            let m = key.mesh.0 as usize;
            if out.mesh_caster_radius.len() <= m {
                out.mesh_caster_radius.resize(m + 1, 0.0);
            }
            out.mesh_caster_radius[m] = out.mesh_caster_radius[m].max(radius);
            out.caster_bounds = out.caster_bounds.union(*bounds);
            if !key.masked {
                out.opaque_casters += 1;
            }
        }
    }
    out.receiver_bounds = out.receiver_bounds.snapped_out(RECEIVER_GRID);
    out.caster_chunks = SphereChunks::build(&out.caster_centers, &out.caster_radii);
    out.chunks = SphereChunks::build(&out.centers, &out.radii);
    out.origin = origin;
    out.skipped = skipped;
    out.generation += 1;
    rows.iter()
        .filter(|r| r.3)
        .map(|&(key, entity, _, _, _, bounds, pose)| (entity, CasterState { bounds, key, pose }))
        .collect()
}

/// Position of `p` along a 3D Morton (Z-order) curve over the cube around `bounds` (its
/// largest side on every axis), 10 bits per axis. A cube, not the box: in a flat scene (a
/// 2 km field 40 m high) the box's scale would spend a third of the bits on the thin axis,
/// and runs of consecutive instances would spread hundreds of metres across.
fn morton_code(bounds: &Aabb, p: Vec3) -> u32 {
    let size = Vec3::splat((bounds.max - bounds.min).max_element().max(1e-6));
    let q = ((p - bounds.min) / size * 1023.0).clamp(Vec3::ZERO, Vec3::splat(1023.0));
    let spread = |v: f32| {
        let mut x = v as u32 & 0x3ff;
        x = (x | (x << 16)) & 0x0300_00ff;
        x = (x | (x << 8)) & 0x0300_f00f;
        x = (x | (x << 4)) & 0x030c_30c3;
        (x | (x << 2)) & 0x0924_9249
    };
    spread(q.x) | (spread(q.y) << 1) | (spread(q.z) << 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_codes_interleave_axes_and_stay_in_range() {
        let b = Aabb::new(Vec3::ZERO, Vec3::splat(1023.0));
        assert_eq!(morton_code(&b, Vec3::ZERO), 0);
        assert_eq!(morton_code(&b, Vec3::new(1.0, 0.0, 0.0)), 0b001);
        assert_eq!(morton_code(&b, Vec3::new(0.0, 1.0, 0.0)), 0b010);
        assert_eq!(morton_code(&b, Vec3::new(0.0, 0.0, 1.0)), 0b100);
        assert_eq!(morton_code(&b, Vec3::splat(1023.0)), (1 << 30) - 1);
        // Outside the bounds clamps; a degenerate box does not divide by zero.
        assert_eq!(morton_code(&b, Vec3::splat(-5.0)), 0);
        let flat = Aabb::new(Vec3::ZERO, Vec3::new(10.0, 0.0, 10.0));
        assert!(morton_code(&flat, Vec3::new(5.0, 0.0, 5.0)) > 0);
    }
}
