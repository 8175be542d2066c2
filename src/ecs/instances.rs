//! The flat, sorted list of mesh instances the renderer and the culling work on, and its
//! rebuild. The instance sync ([`crate::ecs::instance_sync`]) rebuilds it when an instance is
//! added or removed or changes mesh, material or shadow flags, and rewrites in place the
//! instances that only moved (or were posed).

use bevy_ecs::entity::{Entity, EntityHashMap};
use bevy_ecs::resource::Resource;
use glam::Vec3;
use log::warn;

use crate::ecs::assets::{Materials, Meshes};
use crate::ecs::caster_changes::CasterState;
pub use crate::ecs::draw_groups::DrawKey;
use crate::ecs::instance_rows::{InstanceQueryItem, NOT_A_CASTER, Row, Skip};
use crate::math::aabb::Aabb;
use crate::math::chunks::{CHUNK, SphereChunks};
use crate::math::space_order::{SpaceOrder, morton_code};
use crate::shader::instance::InstanceGpu;

/// Cells per side of the grid the receivers' bounds given to the cascades are grown onto
/// ([`Aabb::snapped_out`]): a receiver moving inside them leaves every cascade as it was.
pub(crate) const RECEIVER_GRID: f32 = 256.0;

/// Every drawable instance, sorted by [`DrawKey`] and, within a key, along a Morton curve
/// through the scene (so consecutive instances are close in space and cull together), in
/// structure-of-arrays form. Positions and transforms are relative to [`RenderOrigin`](crate::ecs::origin::RenderOrigin).
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
    /// picks its shadow LOD ([`ShadowLods`](crate::ecs::shadow_lods::ShadowLods)).
    pub mesh_caster_radius: Vec<f32>,
    /// Number of leading casters with opaque materials; the rest are masked or were appended
    /// since the last rebuild (of any material).
    pub opaque_casters: usize,
    /// Chunk spheres of the casters (for chunked cascade culling).
    pub caster_chunks: SphereChunks,
    /// The casters' spheres in space order, whatever their draw keys (for culling small
    /// boxes: a clipmap level's strips).
    pub caster_space: SpaceOrder,
    /// Chunk spheres of all instances (for chunked camera culling).
    pub chunks: SphereChunks,
    /// World bounds of all casters.
    pub caster_bounds: Aabb,
    /// World bounds of everything that receives shadows, grown onto a grid of 1/256 of their
    /// size ([`Aabb::snapped_out`]) so that objects moving inside them leave them unchanged.
    pub receiver_bounds: Aabb,
    /// The render origin every position here is relative to.
    pub origin: Vec3,
    /// Bumped on every rebuild and every in-place update, so the renderer knows to upload.
    pub generation: u64,
    /// The generation of the latest rebuild: instance indices (and whatever is kept per
    /// index, such as the camera's seen flags) hold from it until the next rebuild.
    pub layout: u64,
    /// The instances rewritten by the latest change when it was an in-place update (from
    /// `generation - 1`); empty after a rebuild. See [`RenderInstances::patch_from`].
    pub updated: Vec<u32>,
    /// Per instance: its index in `casters`, or `u32::MAX` for an instance that casts no
    /// shadow.
    pub caster_index: Vec<u32>,
    /// The instance of each entity drawn.
    pub(crate) slots: EntityHashMap<u32>,
    /// Instances of entities removed since the last rebuild: drawn with a zero transform (so
    /// nothing) where they were, until the next rebuild drops them.
    pub tombstones: usize,
    /// Instances appended since the last rebuild (out of the draw-key and Morton order, until
    /// the next rebuild sorts them in).
    pub appended: usize,
    /// Where each run of instances of one draw key within one culling chunk starts
    /// (ascending; a run ends where the next one starts, the last at the list's end).
    pub run_starts: Vec<u32>,
    /// Per culling chunk, the index in `run_starts` of its first run, and one more entry: the
    /// number of runs.
    pub chunk_runs: Vec<u32>,
    /// [`run_starts`](Self::run_starts) of the casters: where each run of casters of one
    /// draw key within one caster culling chunk starts (caster indices).
    pub caster_run_starts: Vec<u32>,
    /// [`chunk_runs`](Self::chunk_runs) of the caster chunks (indexing `caster_run_starts`).
    pub caster_chunk_runs: Vec<u32>,
    /// Entities skipped because of an invalid transform, mesh or material.
    pub skipped: usize,
}

impl RenderInstances {
    /// The instances to patch for a copy that holds generation `held`: `Some(updated)` when
    /// the only change since is the latest in-place update, `None` when the copy must be
    /// written whole.
    pub fn patch_from(&self, held: Option<u64>) -> Option<&[u32]> {
        (held == Some(self.generation.wrapping_sub(1)) && self.layout != self.generation).then_some(&self.updated[..])
    }

    /// The runs of culling chunk `chunk` (instances of one draw key each), as `first..end`
    /// instance ranges.
    pub fn runs_of_chunk(&self, chunk: usize) -> impl Iterator<Item = (u32, u32)> + '_ {
        chunk_run_ranges(&self.run_starts, &self.chunk_runs, chunk, self.gpu.len())
    }

    /// The runs of caster culling chunk `chunk` (casters of one draw key each), as
    /// `first..end` caster ranges.
    pub fn caster_runs_of_chunk(&self, chunk: usize) -> impl Iterator<Item = (u32, u32)> + '_ {
        chunk_run_ranges(
            &self.caster_run_starts,
            &self.caster_chunk_runs,
            chunk,
            self.casters.len(),
        )
    }

    /// The instance index of `entity`, if it is drawn.
    pub fn slot(&self, entity: Entity) -> Option<u32> {
        self.slots.get(&entity).copied()
    }
}

/// Rebuilds the instance list from scratch; returns the state of every caster.
pub(crate) fn rebuild<'a>(
    out: &mut RenderInstances,
    items: impl Iterator<Item = InstanceQueryItem<'a>>,
    meshes: &Meshes,
    materials: &Materials,
    origin: Vec3,
) -> Vec<(Entity, CasterState)> {
    let mut rows: Vec<Row> = Vec::new();
    let mut skipped = 0;
    for item in items {
        let entity = item.0;
        match Row::of(item, meshes, materials, origin) {
            Ok(row) => rows.push(row),
            Err(Skip::MissingAsset) => {
                warn!("entity {entity:?} refers to a missing mesh or material; it is not drawn");
                skipped += 1;
            }
            Err(Skip::BadPlacement) => {
                warn!("entity {entity:?} has a non-finite or zero-scale transform; it is not drawn");
                skipped += 1;
            }
        }
    }
    // NOTE: within a draw key, instances follow a Morton curve through the scene bounds so
    // culling chunks are compact; the entity tie-break keeps the order (and so the image)
    // identical from run to run.
    let scene = rows.iter().fold(Aabb::EMPTY, |b, r| b.union(r.bounds));
    rows.sort_by_cached_key(|r| (r.key, morton_code(&scene, r.bounds.center()), r.entity));

    out.gpu.clear();
    out.keys.clear();
    out.centers.clear();
    out.radii.clear();
    out.casters.clear();
    out.caster_centers.clear();
    out.caster_radii.clear();
    out.caster_boxes.clear();
    out.mesh_caster_radius.clear();
    out.caster_index.clear();
    out.slots.clear();
    out.updated.clear();
    out.caster_bounds = Aabb::EMPTY;
    out.receiver_bounds = Aabb::EMPTY;
    out.opaque_casters = 0;
    for row in &rows {
        push_row(out, row, materials);
        if row.cast && !row.key.masked {
            out.opaque_casters += 1;
        }
    }
    index_runs(out, 0, 0);
    out.tombstones = 0;
    out.appended = 0;
    out.receiver_bounds = out.receiver_bounds.snapped_out(RECEIVER_GRID);
    out.caster_chunks = SphereChunks::build(&out.caster_centers, &out.caster_radii);
    out.caster_space = SpaceOrder::build(&out.caster_centers, &out.caster_radii);
    out.chunks = SphereChunks::build(&out.centers, &out.radii);
    out.origin = origin;
    out.skipped = skipped;
    out.generation += 1;
    out.layout = out.generation;
    rows.iter()
        .filter(|r| r.cast)
        .map(|r| (r.entity, r.caster_state()))
        .collect()
}

/// Appends `row` as the next instance (and caster): its data, bounds and slot; the chunks
/// and the run index are the caller's to update.
pub(crate) fn push_row(out: &mut RenderInstances, row: &Row, materials: &Materials) {
    let i = out.gpu.len();
    out.gpu.push(row.gpu(materials));
    if row.receive {
        out.receiver_bounds = out.receiver_bounds.union(row.bounds);
    }
    let (center, radius) = row.bounds.bounding_sphere();
    out.keys.push(row.key);
    out.centers.push(center);
    out.radii.push(radius);
    out.slots.insert(row.entity, i as u32);
    out.caster_index.push(if row.cast {
        out.casters.len() as u32
    } else {
        NOT_A_CASTER
    });
    if row.cast {
        out.casters.push(i as u32);
        out.caster_centers.push(center);
        out.caster_radii.push(radius);
        out.caster_boxes.push(row.bounds);
        let m = row.key.mesh.0 as usize;
        if out.mesh_caster_radius.len() <= m {
            out.mesh_caster_radius.resize(m + 1, 0.0);
        }
        out.mesh_caster_radius[m] = out.mesh_caster_radius[m].max(radius);
        out.caster_bounds = out.caster_bounds.union(row.bounds);
    }
}

/// The `(first, end)` ranges of the runs of chunk `chunk` in a run index (`starts`,
/// `chunk_runs`) over `total` elements.
fn chunk_run_ranges<'a>(
    starts: &'a [u32],
    chunk_runs: &[u32],
    chunk: usize,
    total: usize,
) -> impl Iterator<Item = (u32, u32)> + 'a {
    let runs = match (chunk_runs.get(chunk), chunk_runs.get(chunk + 1)) {
        (Some(&a), Some(&b)) => a as usize..b as usize,
        _ => 0..0,
    };
    runs.map(move |r| (starts[r], starts.get(r + 1).copied().unwrap_or(total as u32)))
}

/// Indexes the runs (instances of one draw key within one culling chunk) from culling chunk
/// `first` on, and the caster runs from caster chunk `first_caster` on, keeping those before.
pub(crate) fn index_runs(out: &mut RenderInstances, first: usize, first_caster: usize) {
    let keys = &out.keys;
    index_key_runs(keys.len(), |i| keys[i], first, &mut out.run_starts, &mut out.chunk_runs);
    let casters = &out.casters;
    let caster_key = |i: usize| keys[casters[i] as usize];
    let (starts, chunk_runs) = (&mut out.caster_run_starts, &mut out.caster_chunk_runs);
    index_key_runs(casters.len(), caster_key, first_caster, starts, chunk_runs);
}

/// Indexes the runs of equal keys (`key(i)` for `i < len`) within each chunk from chunk
/// `first` on into `starts` and `chunk_runs`, keeping those before.
fn index_key_runs(
    len: usize,
    key: impl Fn(usize) -> DrawKey,
    first: usize,
    starts: &mut Vec<u32>,
    chunk_runs: &mut Vec<u32>,
) {
    let first = first.min(chunk_runs.len());
    let kept = chunk_runs.get(first).map_or(starts.len(), |&r| r as usize);
    chunk_runs.truncate(first);
    starts.truncate(kept);
    for i in first * CHUNK..len {
        if i % CHUNK == 0 {
            chunk_runs.push(starts.len() as u32);
        }
        if i % CHUNK == 0 || key(i - 1) != key(i) {
            starts.push(i as u32);
        }
    }
    chunk_runs.push(starts.len() as u32);
}
