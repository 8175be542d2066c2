//! Shadow views culled by culling chunk only, for a renderer that culls casters one by one on
//! the GPU ([`ShadowCulling::gpu_shadows`](crate::ecs::receiver_culling::ShadowCulling::gpu_shadows)):
//! every caster chunk whose sphere meets a view's volume (a cascade's box, a spot light's
//! frustum, a cube face's frustum within its light's reach) gives that view its runs (casters
//! of one draw key, [`ShadowRun`]), each drawn by a batch of the view's group with room for
//! all its casters; the GPU tests each member against the volume and lists those that pass in
//! their batch. The CPU touches no caster: a frame costs one test per chunk and view, one
//! entry per run, and the view's footprint from its chunks' bounds.

use glam::{Mat4, Vec3};

use crate::ecs::assets::MeshHandle;
use crate::ecs::draw_groups::{ShadowRun, push_room};
use crate::ecs::footprints::add_chunk_footprint;
use crate::ecs::instances::{DrawKey, RenderInstances};
use crate::ecs::lod_table::lod_key;
use crate::ecs::view_cache::CachedView;
use crate::ecs::view_list::ShadowView;
use crate::math::cascades::{CascadeSet, MAX_SUN_VIEWS};
use crate::math::chunk_groups::{GroupTest, frustum_test, visit_groups};
use crate::math::chunks::{CHUNK, visit_cascade_chunks};
use crate::math::footprint::ClipProjector;
use crate::math::frustum::Frustum;

/// Members of a chunk taken together when its footprint is refined member by member (see
/// [`add_chunk_footprint`]): every member of a listed chunk counts, not only those the GPU
/// will draw, so runs of eight neighbours (along the Morton curve) bound them at an eighth of
/// the cost.
const FOOTPRINT_STEP: usize = 8;

/// The fewest casters in a scene whose shadow views are culled by chunk for the GPU: below
/// it the CPU culls caster by caster (what a few thousand sphere tests cost is less than a
/// compute dispatch and the conservative footprints of whole chunks).
pub const GPU_SHADOW_MIN_CASTERS: usize = 16_384;

/// Lists in the entries of `want` (bits of `entries`, one per cascade of `set`; those emptied
/// by the caller) the runs of the caster chunks that meet each cascade's box, with a batch per
/// run of the cascade's mesh level (`table`, from
/// [`lod_table`](crate::ecs::lod_table::lod_table)), and each cascade's footprint from those
/// chunks; marks an entry `partial` when a chunk only straddles its box (its members are then
/// not all drawn). The other entries are left as they are.
pub(crate) fn cull_sun_runs(
    set: &CascadeSet,
    instances: &RenderInstances,
    table: &[[MeshHandle; MAX_SUN_VIEWS]],
    views: &[ShadowView],
    (entries, want): (&mut [CachedView], u8),
) {
    let mut projectors = [ClipProjector::new(&glam::Mat4::IDENTITY); MAX_SUN_VIEWS];
    for (projector, view) in projectors.iter_mut().zip(views) {
        *projector = ClipProjector::new(&view.clip_from_world);
    }
    let n = instances.casters.len();
    let cascades = entries.len().min(MAX_SUN_VIEWS);
    // NOTE: only the wanted cascades are tested: a chunk that meets only held ones costs
    // nothing past its group's test.
    visit_cascade_chunks(set, &instances.caster_chunks, (n, want), |k, overlap, inside| {
        let mut bits = overlap & want;
        while bits != 0 {
            let c = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            if c >= cascades {
                continue;
            }
            list_chunk(&mut entries[c], &projectors[c], instances, k, inside & (1 << c) != 0);
        }
    });
    for (c, entry) in entries.iter_mut().enumerate().take(cascades) {
        if want & 1 << c != 0 {
            number_batches(entry, instances, |key| lod_key(table, key, c));
        }
    }
}

/// Lists in `entry` (emptied by the caller) the runs of the caster chunks that meet `frustum`
/// (and, for a cube face, the sphere `reach`: its light's position and range), each drawn
/// whole with its own mesh, and the view's footprint under `clip_from_world` from those
/// chunks; marks the entry `partial` when a chunk is not wholly inside.
pub(crate) fn cull_frustum_runs(
    frustum: &Frustum,
    reach: Option<(Vec3, f32)>,
    clip_from_world: &Mat4,
    instances: &RenderInstances,
    entry: &mut CachedView,
) {
    let projector = ClipProjector::new(clip_from_world);
    let n = instances.casters.len();
    let chunks = &instances.caster_chunks;
    let count = n.div_ceil(CHUNK).min(chunks.len());
    let test = |center, radius| frustum_test(frustum, reach, center, radius);
    visit_groups(&chunks.groups, count, test, |first, end, whole| {
        for k in first..end {
            // NOTE: a chunk with a member that is not finite has an infinite sphere: its
            // members are tested on the GPU.
            let (center, radius) = (chunks.centers[k], chunks.radii[k]);
            let inside = match whole {
                Some(()) => true,
                None if radius.is_finite() => match frustum_test(frustum, reach, center, radius) {
                    GroupTest::Outside => continue,
                    GroupTest::Whole(()) => true,
                    GroupTest::Split => false,
                },
                None => false,
            };
            list_chunk(entry, &projector, instances, k, inside);
        }
    });
    number_batches(entry, instances, |key| key);
}

/// Adds caster chunk `k` to `entry`: its runs, its footprint under `projector`, and whether it
/// lies wholly `inside` the view's volume.
fn list_chunk(entry: &mut CachedView, projector: &ClipProjector, instances: &RenderInstances, k: usize, inside: bool) {
    entry.partial.0 |= !inside;
    let members = k * CHUNK..((k + 1) * CHUNK).min(instances.casters.len());
    add_chunk_footprint(&mut entry.footprint, projector, instances, k, (members, FOOTPRINT_STEP));
    entry
        .runs
        .extend(instances.caster_runs_of_chunk(k).map(|(first, end)| ShadowRun {
            first,
            count: end - first,
            ..ShadowRun::default()
        }));
}

/// Gives each run of `entry` its batch in the entry's group (the mesh `draw` gives its key,
/// with room for the run), runs of one batch taking consecutive room.
fn number_batches(entry: &mut CachedView, instances: &RenderInstances, draw: impl Fn(DrawKey) -> DrawKey) {
    let mut len = 0;
    for run in &mut entry.runs {
        let instance = instances.casters[run.first as usize] as usize;
        let key = draw(instances.keys[instance]);
        let (masked, index) = push_room(&mut entry.group, &mut len, key, run.count);
        run.batch = index as u32 | if masked { MASKED } else { 0 };
    }
    // NOTE: masked batches are numbered after the opaque ones.
    let opaque = entry.group.opaque.len() as u32;
    for run in &mut entry.runs {
        if run.batch & MASKED != 0 {
            run.batch = opaque + (run.batch & !MASKED);
        }
    }
}

/// Marks a run's batch as masked while the opaque batches are still being counted.
const MASKED: u32 = 1 << 31;
