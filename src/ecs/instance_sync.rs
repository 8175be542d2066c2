//! The instance sync system: mirrors mesh entities into [`RenderInstances`], rebuilding the
//! list when an instance appeared, went or changed its draw key or shadow flags, and
//! rewriting in place the instances that only moved or were posed: their slots, sphere chunks
//! and bounds are rewritten and listed in [`RenderInstances::updated`], so the GPU copy is
//! patched instead of uploaded whole. The change scans skip [`Static`](crate::ecs::Static)
//! entities by archetype ([`ChangedInstances`]).

use bevy_ecs::change_detection::DetectChanges;
use bevy_ecs::entity::{Entity, EntityHashMap};
use bevy_ecs::system::{Local, Query, Res, ResMut};
use glam::Vec3;

use crate::ecs::assets::{Materials, Meshes};
use crate::ecs::caster_changes::{CasterChanges, CasterState};
use crate::ecs::instance_changes::ChangedInstances;
use crate::ecs::instance_rows::{InstanceQueryData, NOT_A_CASTER, Row};
use crate::ecs::instances::{RECEIVER_GRID, RenderInstances, rebuild};
use crate::ecs::origin::RenderOrigin;
use crate::ecs::shadow_lods::ShadowLods;
use crate::math::aabb::Aabb;
use crate::math::chunks::CHUNK;
use crate::shader::contract::INSTANCE_FLAG_RECEIVE_SHADOWS;

/// Reused storage of [`sync_instances`].
#[derive(Default)]
pub struct SyncScratch {
    dirty: Vec<Entity>,
    rows: Vec<(u32, Row)>,
    casters: Vec<(Entity, CasterState)>,
}

/// Mirrors mesh entities into [`RenderInstances`]: rebuilds it when an instance appeared, went
/// or changed its draw key or shadow flags (or any mesh or material asset, the shadow LODs or
/// the render origin changed), and rewrites in place the instances that only moved or were
/// posed.
#[allow(clippy::too_many_arguments)]
pub fn sync_instances(
    mut instances: ResMut<RenderInstances>,
    all: Query<InstanceQueryData>,
    mut changed: ChangedInstances,
    meshes: Res<Meshes>,
    materials: Res<Materials>,
    lods: Option<Res<ShadowLods>>,
    origin: Res<RenderOrigin>,
    mut changes: ResMut<CasterChanges>,
    mut casters_before: Local<EntityHashMap<CasterState>>,
    mut scratch: Local<SyncScratch>,
) {
    let scratch = &mut *scratch;
    let removed = changed.collect(&mut scratch.dirty);
    let everything = instances.generation == 0
        || meshes.is_changed()
        || materials.is_changed()
        || lods.is_some_and(|l| l.is_changed())
        || instances.origin != origin.0;
    if !everything && removed == 0 {
        if scratch.dirty.is_empty() {
            return;
        }
        if in_place_rows(
            &instances,
            &all,
            &scratch.dirty,
            &meshes,
            &materials,
            origin.0,
            &mut scratch.rows,
        ) {
            if scratch.rows.is_empty() {
                return;
            }
            update_in_place(&mut instances, &scratch.rows, &materials, &mut scratch.casters);
            changed.stats.updates += 1;
            changes.record_updates(instances.generation, &mut casters_before, scratch.casters.drain(..));
            return;
        }
    }
    let casters = rebuild(&mut instances, all.iter(), &meshes, &materials, origin.0);
    changed.stats.rebuilds += 1;
    changes.record(
        instances.generation,
        everything,
        &mut casters_before,
        casters.into_iter(),
    );
}

/// The rows of the `dirty` entities, sorted by slot, when every one can be rewritten in place
/// (it is drawn, still drawable, and kept its draw key and shadow flags); false when the list
/// must be rebuilt. Entities that are not mesh entities and were not drawn are ignored.
fn in_place_rows(
    instances: &RenderInstances,
    all: &Query<InstanceQueryData>,
    dirty: &[Entity],
    meshes: &Meshes,
    materials: &Materials,
    origin: Vec3,
    rows: &mut Vec<(u32, Row)>,
) -> bool {
    rows.clear();
    for &entity in dirty {
        let item = all.get(entity).ok();
        let Some(slot) = instances.slot(entity) else {
            if item.is_some() {
                return false;
            }
            continue;
        };
        let Some(Ok(row)) = item.map(|item| Row::of(item, meshes, materials, origin)) else {
            return false;
        };
        if !fits_in_place(instances, slot, &row) {
            return false;
        }
        rows.push((slot, row));
    }
    rows.sort_unstable_by_key(|r| r.0);
    true
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
        let chunk = slot as usize / CHUNK;
        if chunk != last {
            out.chunks.refit(slot as usize, &out.centers, &out.radii);
            last = chunk;
        }
    }
    let mut last = usize::MAX;
    for &(slot, _) in rows {
        let c = out.caster_index[slot as usize];
        if c != NOT_A_CASTER && c as usize / CHUNK != last {
            out.caster_chunks
                .refit(c as usize, &out.caster_centers, &out.caster_radii);
            last = c as usize / CHUNK;
        }
    }
    if !receivers.is_empty() && out.receiver_bounds.union(receivers) != out.receiver_bounds {
        out.receiver_bounds = out.receiver_bounds.union(receivers).snapped_out(RECEIVER_GRID);
    }
    out.generation += 1;
}
