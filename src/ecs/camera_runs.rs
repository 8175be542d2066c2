//! The camera view culled by culling chunk only, for a renderer that culls instance by
//! instance on the GPU ([`ShadowCulling::gpu_camera`](crate::ecs::receiver_culling::ShadowCulling::gpu_camera)):
//! every chunk whose sphere meets the frustum gives its runs (instances of one draw key) to
//! [`ViewDrawGroups::runs`]. Each draw key gets one batch per mesh level (the mesh, then up to
//! [`GPU_LOD_LEVELS`] coarser levels where [`CameraLod`](crate::ecs::view_lod::CameraLod)
//! allows any), each with room for all the key's instances listed, and the GPU puts each
//! instance in the batch of the coarsest level its size on screen allows. The CPU touches no
//! instance: a frame costs one sphere test per chunk and one entry per run.

use crate::ecs::draw_groups::{DrawBatch, DrawGroup, DrawKey, GPU_LOD_LEVELS, InstanceRun, ViewDrawGroups};
use crate::ecs::instances::RenderInstances;
use crate::ecs::view_lod::ViewLod;
use crate::math::chunk_groups::{frustum_test, visit_groups};
use crate::math::frustum::Frustum;

/// The fewest instances in the chunks that meet the frustum for which the view is culled by
/// chunk for the GPU: below it the CPU culls instance by instance (and the renderer's GPU
/// culling, about 0.13 ms at 1920×1080 on an H200 with its occlusion test, outweighs what a
/// small view could save).
pub const GPU_CAMERA_MIN_INSTANCES: usize = 16_384;

/// Lists in `groups` (emptied first) the runs of the chunks of `instances` that meet
/// `frustum`, in instance order (so draw key after draw key), with a batch per key and mesh
/// level (levels from `view_lod`); returns false, listing nothing, when they hold fewer than
/// [`GPU_CAMERA_MIN_INSTANCES`] instances. A chunk with a member that is not finite is listed
/// (the GPU tests its members).
pub fn cull_chunk_runs(
    frustum: &Frustum,
    view_lod: Option<&ViewLod>,
    instances: &RenderInstances,
    groups: &mut ViewDrawGroups,
) -> bool {
    groups.runs.clear();
    let chunks = &instances.chunks;
    let mut candidates = 0;
    let test = |center, radius| frustum_test(frustum, None, center, radius);
    visit_groups(&chunks.groups, chunks.len(), test, |first, end, whole| {
        for k in first..end {
            let (center, radius) = (chunks.centers[k], chunks.radii[k]);
            if whole.is_none() && radius.is_finite() && !frustum.intersects_sphere(center, radius) {
                continue;
            }
            for (first, end) in instances.runs_of_chunk(k) {
                groups.runs.push(InstanceRun {
                    first,
                    count: end - first,
                    ..InstanceRun::default()
                });
                candidates += (end - first) as usize;
            }
        }
    });
    if candidates < GPU_CAMERA_MIN_INSTANCES {
        groups.runs.clear();
        return false;
    }
    groups.lod_error_per_depth = view_lod.map_or(0.0, ViewLod::error_per_depth);
    // NOTE: instances are sorted by draw key, so the runs of one key are consecutive.
    let (mut start, mut len) = (0, 0u32);
    while start < groups.runs.len() {
        let key = instances.keys[groups.runs[start].first as usize];
        let mut end = start + 1;
        while end < groups.runs.len() && instances.keys[groups.runs[end].first as usize] == key {
            end += 1;
        }
        let room: u32 = groups.runs[start..end].iter().map(|r| r.count).sum();
        let levels = view_lod.map_or(&[][..], |v| v.levels(key.mesh));
        let levels = &levels[..levels.len().min(GPU_LOD_LEVELS)];
        let mut errors = [0.0; GPU_LOD_LEVELS];
        for (e, level) in errors.iter_mut().zip(levels) {
            *e = level.relative_error;
        }
        let meshes = std::iter::once(key.mesh).chain(levels.iter().map(|l| l.mesh));
        let mut batch = None;
        for mesh in meshes {
            let b = push_batch(&mut groups.group, DrawKey { mesh, ..key }, len, room);
            batch.get_or_insert(b);
            len += room;
        }
        let batch = batch.unwrap_or_default() | if key.masked { MASKED } else { 0 };
        for run in &mut groups.runs[start..end] {
            run.batch = batch;
            run.levels = levels.len() as u32;
            run.errors = errors;
        }
        start = end;
    }
    // NOTE: masked batches are numbered after the opaque ones.
    let opaque = groups.group.opaque.len() as u32;
    for run in &mut groups.runs {
        if run.batch & MASKED != 0 {
            run.batch = opaque + (run.batch & !MASKED);
        }
    }
    true
}

/// Adds a batch of `count` entries from `first` for `key` (never merged with the one before:
/// each level's batch keeps its own number); returns its index in its list.
fn push_batch(group: &mut DrawGroup, key: DrawKey, first: u32, count: u32) -> u32 {
    let list = if key.masked {
        &mut group.masked
    } else {
        &mut group.opaque
    };
    list.push(DrawBatch {
        mesh: key.mesh,
        material: key.material,
        double_sided: key.double_sided,
        first,
        count,
    });
    (list.len() - 1) as u32
}

/// Marks a run's batch as masked while the opaque batches are still being counted.
const MASKED: u32 = 1 << 31;
