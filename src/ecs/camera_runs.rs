//! The camera view culled by culling chunk only, for a renderer that culls instance by
//! instance on the GPU ([`ShadowCulling::gpu_camera`](crate::ecs::receiver_culling::ShadowCulling::gpu_camera)):
//! every chunk whose sphere meets the frustum gives its runs (instances of one draw key) to
//! [`ViewDrawGroups::runs`], each drawn with the coarsest mesh level the chunk's nearest depth
//! allows, ordered by draw key and level. The CPU touches no instance: a frame costs one
//! sphere test per chunk and one entry per run.

use crate::ecs::draw_groups::{DrawKey, InstanceRun, ViewDrawGroups, push_room};
use crate::ecs::instances::RenderInstances;
use crate::ecs::view_lod::ViewLod;
use crate::math::frustum::Frustum;

/// The fewest instances in the chunks that meet the frustum for which the view is culled by
/// chunk for the GPU: below it the CPU culls instance by instance (and the renderer's GPU
/// culling, about 0.13 ms at 1920×1080 on an H200 with its occlusion test, outweighs what a
/// small view could save).
pub const GPU_CAMERA_MIN_INSTANCES: usize = 16_384;

/// One run of a chunk that meets the frustum, before ordering.
#[derive(Clone, Copy, Debug)]
pub struct ChunkRun {
    key: DrawKey,
    /// The run's place: its draw key's rank among the keys listed, then its LOD mesh.
    order: u64,
    first: u32,
    end: u32,
}

/// Lists in `groups` (emptied first) the runs of the chunks of `instances` that meet
/// `frustum`, each with the mesh level `view_lod` gives its chunk, ordered by draw key and then
/// by level (so runs of one level share a batch: the GPU appends a batch's instances in no
/// particular order, so a front-to-back order inside it would be lost anyway); returns false,
/// listing nothing, when they hold fewer than [`GPU_CAMERA_MIN_INSTANCES`] instances. A chunk
/// with a member that is not finite is listed (the GPU tests its members).
pub fn cull_chunk_runs(
    frustum: &Frustum,
    view_lod: Option<&ViewLod>,
    instances: &RenderInstances,
    groups: &mut ViewDrawGroups,
    runs: &mut Vec<ChunkRun>,
) -> bool {
    runs.clear();
    groups.runs.clear();
    let chunks = &instances.chunks;
    let (mut candidates, mut rank, mut last) = (0, 0u64, None);
    for (k, (&center, &radius)) in chunks.centers.iter().zip(&chunks.radii).enumerate() {
        if radius.is_finite() && !frustum.intersects_sphere(center, radius) {
            continue;
        }
        // NOTE: instances are sorted by draw key, so runs come key after key.
        for (first, end) in instances.runs_of_chunk(k) {
            let key = instances.keys[first as usize];
            if last != Some(key) {
                rank += u64::from(last.is_some());
                last = Some(key);
            }
            let mesh = match view_lod {
                Some(v) => v.mesh_for_chunk(key.mesh, &chunks.boxes[k], chunks.max_radii[k]),
                None => key.mesh,
            };
            runs.push(ChunkRun {
                key: DrawKey { mesh, ..key },
                order: rank << 32 | u64::from(mesh.0),
                first,
                end,
            });
            candidates += (end - first) as usize;
        }
    }
    if candidates < GPU_CAMERA_MIN_INSTANCES {
        runs.clear();
        return false;
    }
    runs.sort_by_key(|r| r.order);
    let mut len = 0;
    for run in runs.iter() {
        let (masked, batch) = push_room(&mut groups.group, &mut len, run.key, run.end - run.first);
        groups.runs.push(InstanceRun {
            first: run.first,
            count: run.end - run.first,
            // NOTE: masked batches are numbered after the opaque ones, fixed below.
            batch: batch as u32 | if masked { MASKED } else { 0 },
            listed: 0,
        });
    }
    let opaque = groups.group.opaque.len() as u32;
    for run in &mut groups.runs {
        if run.batch & MASKED != 0 {
            run.batch = opaque + (run.batch & !MASKED);
        }
    }
    true
}

/// Marks a run's batch as masked while the opaque batches are still being counted.
const MASKED: u32 = 1 << 31;
