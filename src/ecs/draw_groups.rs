//! Draw groups: the culled instances of each shadow view (and of the camera view), as runs of
//! instanced draws. The vectors keep their capacity, so culling allocates nothing once the
//! scene has been seen.

use bevy_ecs::resource::Resource;
use bytemuck::{Pod, Zeroable};

use crate::ecs::assets::{MaterialHandle, MeshHandle};

/// Draw order key: opaque before masked, single-sided before double-sided, then by mesh and
/// material, so every run of equal keys is one instanced draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct DrawKey {
    /// Alpha-masked material.
    pub masked: bool,
    /// Double-sided material (drawn without back-face culling).
    pub double_sided: bool,
    /// Mesh drawn.
    pub mesh: MeshHandle,
    /// Material drawn with.
    pub material: MaterialHandle,
}

/// One instanced draw: `count` instances listed at `first..first + count` of the group's
/// index list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawBatch {
    /// Mesh drawn.
    pub mesh: MeshHandle,
    /// Material (selects the texture for masked draws).
    pub material: MaterialHandle,
    /// The material is double-sided (no back-face culling in the camera view).
    pub double_sided: bool,
    /// First entry in the index list.
    pub first: u32,
    /// Number of instances.
    pub count: u32,
}

/// The draws of one view: opaque first, then alpha-masked.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DrawGroup {
    /// Draws with opaque materials (depth-only in the shadow pass).
    pub opaque: Vec<DrawBatch>,
    /// Draws with alpha-masked materials (alpha-tested).
    pub masked: Vec<DrawBatch>,
}

impl DrawGroup {
    /// Removes all draws, keeping capacity.
    pub fn clear(&mut self) {
        self.opaque.clear();
        self.masked.clear();
    }

    /// Instances drawn by this group.
    pub fn instance_count(&self) -> u32 {
        self.opaque.iter().chain(&self.masked).map(|b| b.count).sum()
    }

    /// Number of draw calls.
    pub fn draw_count(&self) -> usize {
        self.opaque.len() + self.masked.len()
    }

    /// Becomes a copy of `group`, whose index list is appended to `indices` here: the copy's
    /// batches point into `indices`. Keeps this group's allocations.
    pub fn append_copy(&mut self, group: &DrawGroup, list: &[u32], indices: &mut Vec<u32>) {
        let offset = indices.len() as u32;
        indices.extend_from_slice(list);
        self.opaque.clone_from(&group.opaque);
        self.masked.clone_from(&group.masked);
        self.opaque
            .iter_mut()
            .chain(self.masked.iter_mut())
            .for_each(|b| b.first += offset);
    }
}

/// Appends instance `index` with `key` to `indices`, extending the last batch of the right
/// list when the key matches, else starting a new one.
pub fn push_instance(group: &mut DrawGroup, indices: &mut Vec<u32>, key: DrawKey, index: u32) {
    push_run(group, indices, key, &[index]);
}

/// Appends instances `run`, all with `key`, to `indices` as [`push_instance`] does one by one.
pub fn push_run(group: &mut DrawGroup, indices: &mut Vec<u32>, key: DrawKey, run: &[u32]) {
    if run.is_empty() {
        return;
    }
    let mut len = indices.len() as u32;
    push_room(group, &mut len, key, run.len() as u32);
    indices.extend_from_slice(run);
}

/// Most coarser mesh levels the GPU chooses among per instance (a mesh's finest ones).
pub const GPU_LOD_LEVELS: usize = 4;

/// Instances `first..first + count` of the instance list, drawn by batch `batch` of a view
/// (numbered opaque first, then masked) once the GPU has culled them one by one; with
/// `levels` coarser mesh levels, batch `batch + l` draws level `l` (of relative error
/// `errors[l - 1]`), and each instance goes to the coarsest level its size on screen allows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct InstanceRun {
    /// First instance.
    pub first: u32,
    /// Number of instances (at most one culling chunk's).
    pub count: u32,
    /// The batch drawing them whole (the coarser levels' batches follow it).
    pub batch: u32,
    /// 0: the run is of instances; 1: of entries of the view's index list (the renderer's
    /// runs over a list the CPU culled).
    pub listed: u32,
    /// Coarser levels to choose among (at most [`GPU_LOD_LEVELS`]).
    pub levels: u32,
    /// Each coarser level's error, relative to an instance's bounding radius, finest first.
    pub errors: [f32; GPU_LOD_LEVELS],
}

/// Casters `first..first + count` (caster indices, at most one culling chunk's, of one draw
/// key) of shadow view `view`, drawn by the view's batch `batch` (numbered opaque first, then
/// masked) once the GPU has tested each against the view's volume.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
#[repr(C)]
pub struct ShadowRun {
    /// First caster.
    pub first: u32,
    /// Number of casters.
    pub count: u32,
    /// The batch drawing them.
    pub batch: u32,
    /// The view (its index in [`ShadowViews::views`](crate::ecs::view_list::ShadowViews::views);
    /// 0 while the view's entry holds it).
    pub view: u32,
}

/// The instances the camera sees.
#[derive(Resource, Debug, Default)]
pub struct ViewDrawGroups {
    /// Draws.
    pub group: DrawGroup,
    /// Instance indices referenced by the batches (empty when the view is listed as `runs`).
    pub indices: Vec<u32>,
    /// The view culled by chunk only, for the GPU to cull instance by instance: runs of
    /// consecutive instances, each drawn by one batch; a batch's range (`first..first +
    /// count`) is then room in the list the GPU writes, as long as its runs together. Empty
    /// when the CPU culled every instance (`indices`).
    pub runs: Vec<InstanceRun>,
    /// The error allowed at unit view depth for the GPU's choice of levels (see
    /// [`ViewLod::error_per_depth`](crate::ecs::view_lod::ViewLod::error_per_depth); 0: no
    /// coarser level).
    pub lod_error_per_depth: f32,
    /// Bumped whenever `group` and `indices` are rebuilt (the renderer uploads them then).
    pub generation: u64,
}

impl ViewDrawGroups {
    /// The instances of the view's list before the GPU culls them: those listed, or every
    /// instance of every run, in list order.
    pub fn candidates(&self) -> impl Iterator<Item = u32> + '_ {
        let runs = self.runs.iter().flat_map(|r| r.first..r.first + r.count);
        self.indices.iter().copied().chain(runs)
    }

    /// Entries of the view's list: the room of every batch (the instances listed, or room for
    /// the runs' instances at each of their levels).
    pub fn entries(&self) -> usize {
        let group = &self.group;
        group.opaque.iter().chain(&group.masked).map(|b| b.count as usize).sum()
    }

    /// Instances the GPU will cull: those listed, or those of every run.
    pub fn candidate_count(&self) -> usize {
        self.indices.len() + self.runs.iter().map(|r| r.count as usize).sum::<usize>()
    }
}

/// Reserves `count` entries for instances with `key` in `group` at position `*len` of a list
/// only the GPU writes, as [`push_run`] would list them; returns the batch (masked or not, and
/// its index in that list).
pub fn push_room(group: &mut DrawGroup, len: &mut u32, key: DrawKey, count: u32) -> (bool, usize) {
    let list = if key.masked {
        &mut group.masked
    } else {
        &mut group.opaque
    };
    let position = *len;
    *len += count;
    match list.last_mut() {
        Some(last) if last.mesh == key.mesh && last.material == key.material && last.first + last.count == position => {
            last.count += count
        }
        _ => list.push(DrawBatch {
            mesh: key.mesh,
            material: key.material,
            double_sided: key.double_sided,
            first: position,
            count,
        }),
    }
    (key.masked, list.len() - 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(masked: bool, mesh: u32, material: u32) -> DrawKey {
        DrawKey {
            masked,
            double_sided: masked,
            mesh: MeshHandle(mesh),
            material: MaterialHandle(material),
        }
    }

    #[test]
    fn equal_keys_merge_into_one_batch() {
        let mut g = DrawGroup::default();
        let mut idx = Vec::new();
        push_instance(&mut g, &mut idx, key(false, 0, 0), 10);
        push_instance(&mut g, &mut idx, key(false, 0, 0), 11);
        push_instance(&mut g, &mut idx, key(false, 1, 0), 12);
        push_instance(&mut g, &mut idx, key(true, 1, 2), 13);
        push_instance(&mut g, &mut idx, key(true, 1, 2), 14);
        assert_eq!(idx, [10, 11, 12, 13, 14]);
        assert_eq!(g.opaque.len(), 2);
        assert_eq!(g.opaque[0].count, 2);
        assert_eq!(
            g.masked,
            [DrawBatch {
                mesh: MeshHandle(1),
                material: MaterialHandle(2),
                double_sided: true,
                first: 3,
                count: 2
            }]
        );
        assert_eq!(g.instance_count(), 5);
        assert_eq!(g.draw_count(), 3);
    }

    #[test]
    fn pushing_runs_equals_pushing_their_instances_one_by_one() {
        let runs: [(DrawKey, &[u32]); 4] = [
            (key(false, 0, 0), &[4, 5, 6]),
            (key(false, 0, 0), &[1]),
            (key(true, 1, 0), &[9, 2]),
            (key(false, 2, 0), &[]),
        ];
        let (mut by_run, mut run_indices) = (DrawGroup::default(), Vec::new());
        let (mut by_one, mut one_indices) = (DrawGroup::default(), Vec::new());
        for (k, run) in runs {
            push_run(&mut by_run, &mut run_indices, k, run);
            for &i in run {
                push_instance(&mut by_one, &mut one_indices, k, i);
            }
        }
        assert_eq!(by_run, by_one);
        assert_eq!(run_indices, one_indices);
        assert_eq!(by_run.opaque.len(), 1, "consecutive runs of one key merge");
        assert_eq!(by_run.instance_count(), 6);
    }
}
