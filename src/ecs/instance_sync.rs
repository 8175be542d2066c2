//! The instance sync system: mirrors mesh entities into [`RenderInstances`], rebuilding the
//! list when an instance appeared, went or changed its draw key or shadow flags, and
//! rewriting in place the instances that only moved or were posed: their slots, sphere chunks
//! and bounds are rewritten and listed in [`RenderInstances::updated`], so the GPU copy is
//! patched instead of uploaded whole. The change scans skip [`Static`](crate::ecs::Static)
//! entities by archetype ([`ChangedInstances`]).

use bevy_ecs::change_detection::DetectChanges;
use bevy_ecs::entity::{Entity, EntityHashMap};
use bevy_ecs::system::{Local, Query, Res, ResMut};
use glam::{Vec3, Vec4};

use crate::ecs::assets::{Materials, Meshes};
use crate::ecs::caster_changes::{CasterChanges, CasterState};
use crate::ecs::instance_changes::ChangedInstances;
use crate::ecs::instance_rows::{InstanceQueryData, NOT_A_CASTER, Row};
use crate::ecs::instances::{RECEIVER_GRID, RenderInstances, index_runs, push_row, rebuild};
use crate::ecs::origin::RenderOrigin;
use crate::ecs::shadow_lods::ShadowLods;
use crate::math::aabb::Aabb;
use crate::math::chunks::CHUNK;
use crate::shader::contract::INSTANCE_FLAG_RECEIVE_SHADOWS;

/// Reused storage of [`sync_instances`].
#[derive(Default)]
pub struct SyncScratch {
    dirty: Vec<Entity>,
    plan: Plan,
    casters: Vec<(Entity, CasterState)>,
    removed: Vec<Entity>,
}

/// What a sync does without a rebuild: instances rewritten in place, removed (left as
/// tombstones) and appended.
#[derive(Default)]
struct Plan {
    rows: Vec<(u32, Row)>,
    /// Instances to remove, and their entities.
    removes: Vec<(u32, Entity)>,
    adds: Vec<Row>,
    /// Entities both removed and appended (new draw key or shadow flags), sorted.
    rekeyed: Vec<Entity>,
}

/// Mirrors mesh entities into [`RenderInstances`]: rewrites in place the instances that moved
/// or were posed, appends new ones and leaves removed ones as tombstones (drawn as nothing);
/// rebuilds it when any mesh or material asset, the shadow LODs or the render origin changed,
/// when an entity cannot be drawn (its warning is counted then), or when the changes are
/// many (more than an eighth of the list) or the tombstones or the appended instances since the
/// last rebuild a quarter of it.
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
    changed.collect(&mut scratch.dirty);
    let everything = instances.generation == 0
        || meshes.is_changed()
        || materials.is_changed()
        || lods.is_some_and(|l| l.is_changed())
        || instances.origin != origin.0;
    if !everything {
        if scratch.dirty.is_empty() {
            return;
        }
        let planned = plan(
            &instances,
            &all,
            &scratch.dirty,
            (&meshes, &materials),
            origin.0,
            &mut scratch.plan,
        );
        let n = instances.gpu.len();
        let plan = &scratch.plan;
        // NOTE: appended instances are out of order and tombstones are dead weight: past a
        // quarter of the list either way, a rebuild sorts and compacts it again.
        let small = (plan.adds.len() + plan.removes.len()) * 8 <= n.max(64)
            && (instances.tombstones + plan.removes.len()) * 4 <= n
            && (instances.appended + plan.adds.len()) * 4 <= n;
        if planned && small {
            if plan.rows.is_empty() && plan.adds.is_empty() && plan.removes.is_empty() {
                return;
            }
            scratch.removed.clear();
            apply(
                &mut instances,
                plan,
                &materials,
                &mut scratch.casters,
                &mut scratch.removed,
            );
            changed.stats.updates += 1;
            let (states, removed) = (scratch.casters.drain(..), &scratch.removed);
            changes.record_updates(instances.generation, &mut casters_before, states, removed);
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

/// Plans the changes of the `dirty` entities: rewritten in place (sorted by slot), removed,
/// appended (a drawn entity whose draw key or shadow flags changed is removed and appended);
/// false when the list must be rebuilt (an entity cannot be drawn). Entities that are not mesh
/// entities and were not drawn are ignored.
fn plan(
    instances: &RenderInstances,
    all: &Query<InstanceQueryData>,
    dirty: &[Entity],
    (meshes, materials): (&Meshes, &Materials),
    origin: Vec3,
    plan: &mut Plan,
) -> bool {
    plan.rows.clear();
    plan.removes.clear();
    plan.adds.clear();
    plan.rekeyed.clear();
    for &entity in dirty {
        let row = match all.get(entity) {
            Ok(item) => match Row::of(item, meshes, materials, origin) {
                Ok(row) => Some(row),
                Err(_) => return false,
            },
            Err(_) => None,
        };
        match (instances.slot(entity), row) {
            (None, None) => {}
            (None, Some(row)) => plan.adds.push(row),
            (Some(slot), None) => plan.removes.push((slot, entity)),
            (Some(slot), Some(row)) if fits_in_place(instances, slot, &row) => plan.rows.push((slot, row)),
            (Some(slot), Some(row)) => {
                plan.removes.push((slot, entity));
                plan.adds.push(row);
                plan.rekeyed.push(entity);
            }
        }
    }
    plan.rows.sort_unstable_by_key(|r| r.0);
    plan.rekeyed.sort_unstable();
    true
}

/// Applies `plan`: rewrites its rows in place, turns its removed instances into tombstones
/// (their entities in `removed`) and appends its new ones; refits or extends the chunks and
/// the run index. Bumps the generation, keeps the layout, lists every instance written in
/// `updated` and returns the casters' new states in `casters`.
fn apply(
    out: &mut RenderInstances,
    plan: &Plan,
    materials: &Materials,
    casters: &mut Vec<(Entity, CasterState)>,
    removed: &mut Vec<Entity>,
) {
    update_in_place(out, &plan.rows, materials, casters);
    for &(slot, entity) in &plan.removes {
        let i = slot as usize;
        out.slots.remove(&entity);
        // NOTE: an entity appended again keeps its caster state, compared with the new one.
        if plan.rekeyed.binary_search(&entity).is_err() {
            removed.push(entity);
        }
        // NOTE: a zero transform draws nothing; the bounds stay until the next rebuild.
        out.gpu[i].world_rows = [Vec4::ZERO; 3];
        out.tombstones += 1;
        out.updated.push(slot);
    }
    if !plan.adds.is_empty() {
        let (instances, casters_before) = (out.gpu.len(), out.casters.len());
        let receivers = out.receiver_bounds;
        out.appended += plan.adds.len();
        for row in &plan.adds {
            out.updated.push(out.gpu.len() as u32);
            push_row(out, row, materials);
            if row.cast {
                casters.push((row.entity, row.caster_state()));
            }
        }
        if out.receiver_bounds != receivers {
            out.receiver_bounds = out.receiver_bounds.snapped_out(RECEIVER_GRID);
        }
        let (first, first_caster) = (instances / CHUNK, casters_before / CHUNK);
        out.chunks.rebuild_from(first, &out.centers, &out.radii);
        out.caster_chunks
            .rebuild_from(first_caster, &out.caster_centers, &out.caster_radii);
        out.caster_space.extend(&out.caster_centers, &out.caster_radii);
        index_runs(out, first, first_caster);
    }
    out.updated.sort_unstable();
    out.updated.dedup();
    out.generation += 1;
}

/// True when `row` can replace instance `slot` in place: same draw key and shadow flags.
pub(crate) fn fits_in_place(out: &RenderInstances, slot: u32, row: &Row) -> bool {
    let i = slot as usize;
    let receives = out.gpu[i].flags & INSTANCE_FLAG_RECEIVE_SHADOWS != 0;
    out.keys[i] == row.key && receives == row.receive && (out.caster_index[i] != NOT_A_CASTER) == row.cast
}

/// Rewrites the instances of `rows` (`(slot, row)` pairs sorted by slot, each accepted by
/// [`fits_in_place`]) and refits their chunks; the bounds of all casters and receivers only
/// grow. Lists the slots in `updated` (emptied first) and the casters' new states in `casters`
/// (emptied first).
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
    let moved = rows
        .iter()
        .map(|(slot, _)| out.caster_index[*slot as usize])
        .filter(|&c| c != NOT_A_CASTER);
    out.caster_space.refit(moved, &out.caster_centers, &out.caster_radii);
    if !receivers.is_empty() && out.receiver_bounds.union(receivers) != out.receiver_bounds {
        out.receiver_bounds = out.receiver_bounds.union(receivers).snapped_out(RECEIVER_GRID);
    }
}
