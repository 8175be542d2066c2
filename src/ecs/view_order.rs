//! Draw order of the camera view: by draw key (so each mesh and material stays one instanced
//! draw), and within a key front to back, culling chunk by culling chunk (64 instances close
//! together in space), nearest chunk first. The depth prepass then fills near surfaces first
//! and later fragments fail the depth test early. Ordering whole chunks keeps it cheap: a
//! sort of a few hundred runs, not of every visible instance.

use glam::Vec3;

use crate::ecs::draw_groups::DrawKey;
use crate::math::chunks::CHUNK;

/// A run of visible instances sharing a draw key and a culling chunk.
#[derive(Clone, Copy, Debug)]
pub struct Run {
    /// Their draw key.
    pub key: DrawKey,
    distance: f32,
    start: u32,
    end: u32,
}

impl Run {
    /// The run's instances, from the `visible` list it was made from.
    pub fn of<'a>(&self, visible: &'a [u32]) -> &'a [u32] {
        &visible[self.start as usize..self.end as usize]
    }
}

/// Splits `visible` (ascending instance indices) into `runs` ordered by draw key, then by the
/// distance from `eye` to the centre of the runs' culling chunk (`chunk_centers`), nearest
/// first; instances of one chunk keep their order.
pub fn front_to_back(visible: &[u32], keys: &[DrawKey], chunk_centers: &[Vec3], eye: Vec3, runs: &mut Vec<Run>) {
    runs.clear();
    let mut i = 0;
    while i < visible.len() {
        let first = visible[i] as usize;
        let (key, chunk) = (keys[first], first / CHUNK);
        let mut end = i + 1;
        while end < visible.len() && visible[end] as usize / CHUNK == chunk && keys[visible[end] as usize] == key {
            end += 1;
        }
        let distance = chunk_centers.get(chunk).map_or(0.0, |c| c.distance_squared(eye));
        runs.push(Run {
            key,
            // NOTE: a non-finite distance (a chunk with a non-finite member) sorts last.
            distance: if distance.is_nan() { f32::INFINITY } else { distance },
            start: i as u32,
            end: end as u32,
        });
        i = end;
    }
    runs.sort_by(|a, b| a.key.cmp(&b.key).then(a.distance.total_cmp(&b.distance)));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ecs::assets::{MaterialHandle, MeshHandle};

    fn key(mesh: u32) -> DrawKey {
        DrawKey {
            masked: false,
            double_sided: false,
            mesh: MeshHandle(mesh),
            material: MaterialHandle(0),
        }
    }

    #[test]
    fn keys_stay_together_and_chunks_come_nearest_first() {
        // Three chunks: 0 far, 1 near, 2 middle; mesh 0 in chunks 0 and 1, mesh 1 in chunk 2
        // and at the end of chunk 1.
        let n = 3 * CHUNK;
        let keys: Vec<DrawKey> = (0..n)
            .map(|i| {
                if i >= 2 * CHUNK || i == 2 * CHUNK - 1 {
                    key(1)
                } else {
                    key(0)
                }
            })
            .collect();
        let centers = [
            Vec3::new(0.0, 0.0, 100.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 0.0, 10.0),
        ];
        let visible: Vec<u32> = [3, 5, CHUNK + 2, CHUNK + 7, 2 * CHUNK - 1, 2 * CHUNK + 1]
            .iter()
            .map(|&i| i as u32)
            .collect();
        let mut runs = Vec::new();
        front_to_back(&visible, &keys, &centers, Vec3::ZERO, &mut runs);
        let out: Vec<u32> = runs.iter().flat_map(|r| r.of(&visible).iter().copied()).collect();
        let (c, k) = (CHUNK as u32, 2 * CHUNK as u32);
        // Mesh 0: chunk 1 (near) before chunk 0 (far); mesh 1: chunk 1 before chunk 2.
        assert_eq!(out, [c + 2, c + 7, 3, 5, k - 1, k + 1]);
        let mut sorted = out.clone();
        sorted.sort();
        assert_eq!(sorted, visible, "every visible instance once");
    }
}
