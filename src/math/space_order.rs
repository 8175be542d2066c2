//! Casters in space order: a second chunking of the casters' bounding spheres, along one Morton
//! curve through the scene regardless of draw key. The casters' own chunks follow their draw
//! order (by key, then in space), so where each mesh's few copies are spread over the whole
//! scene (a field of boxes of a thousand sizes) every chunk spans the scene and a small box
//! rejects none of them. A small box (a clipmap level's newly covered strip) is culled over
//! these chunks instead, and its hits sorted back into draw order.

use glam::Vec3;

use crate::math::aabb::Aabb;
use crate::math::cascades::CascadeSet;
use crate::math::chunks::{CHUNK, SphereChunks, visit_casters_chunked};

/// Position of `p` along a 3D Morton (Z-order) curve over the cube around `bounds` (its
/// largest side on every axis), 10 bits per axis. A cube, not the box: in a flat scene (a
/// 2 km field 40 m high) the box's scale would spend a third of the bits on the thin axis,
/// and runs of consecutive instances would spread hundreds of metres across. A point that is
/// not finite gets some code in range.
pub fn morton_code(bounds: &Aabb, p: Vec3) -> u32 {
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

/// The casters' spheres reordered along a Morton curve, with their chunks.
#[derive(Clone, Debug, Default)]
pub struct SpaceOrder {
    /// Caster indices (into the arrays this was built from), in space order.
    order: Vec<u32>,
    /// Per caster index: its place in `order`.
    rank: Vec<u32>,
    /// The casters' centres, in space order.
    centers: Vec<Vec3>,
    /// The casters' radii, in space order.
    radii: Vec<f32>,
    /// Chunks of `centers`/`radii`.
    chunks: SphereChunks,
    /// Chunks to refit (scratch of [`refit`](Self::refit)).
    stale: Vec<u32>,
}

impl SpaceOrder {
    /// Orders the spheres `centers`/`radii` (equal lengths) along a Morton curve through their
    /// bounds; ties keep index order.
    pub fn build(centers: &[Vec3], radii: &[f32]) -> Self {
        let n = centers.len().min(radii.len());
        let bounds = centers[..n]
            .iter()
            .filter(|c| c.is_finite())
            .fold(Aabb::EMPTY, |b, &c| b.union(Aabb::new(c, c)));
        let mut order: Vec<u32> = (0..n as u32).collect();
        order.sort_by_cached_key(|&i| (morton_code(&bounds, centers[i as usize]), i));
        let mut space = SpaceOrder {
            rank: vec![0; n],
            centers: order.iter().map(|&i| centers[i as usize]).collect(),
            radii: order.iter().map(|&i| radii[i as usize]).collect(),
            order,
            ..SpaceOrder::default()
        };
        for (r, &i) in space.order.iter().enumerate() {
            space.rank[i as usize] = r as u32;
        }
        space.chunks = SphereChunks::build(&space.centers, &space.radii);
        space
    }

    /// Adds the spheres appended to `centers`/`radii` since this was built or last extended,
    /// at the end of the order (they are not placed along the curve until the next build).
    pub fn extend(&mut self, centers: &[Vec3], radii: &[f32]) {
        let before = self.order.len();
        let n = centers.len().min(radii.len());
        for i in before..n {
            self.rank.push(self.order.len() as u32);
            self.order.push(i as u32);
            self.centers.push(centers[i]);
            self.radii.push(radii[i]);
        }
        if n > before {
            self.chunks.rebuild_from(before / CHUNK, &self.centers, &self.radii);
        }
    }

    /// Takes the moved spheres `moved` (caster indices) from `centers`/`radii` and refits
    /// their chunks, each once. Indices past what this holds are ignored.
    pub fn refit(&mut self, moved: impl IntoIterator<Item = u32>, centers: &[Vec3], radii: &[f32]) {
        self.stale.clear();
        for i in moved {
            let Some(&r) = self.rank.get(i as usize) else { continue };
            let (Some(&c), Some(&radius)) = (centers.get(i as usize), radii.get(i as usize)) else {
                continue;
            };
            self.centers[r as usize] = c;
            self.radii[r as usize] = radius;
            self.stale.push(r / CHUNK as u32);
        }
        self.stale.sort_unstable();
        self.stale.dedup();
        for &k in &self.stale {
            self.chunks.refit(k as usize * CHUNK, &self.centers, &self.radii);
        }
    }

    /// Number of spheres held.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    /// True when no sphere is held.
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// Appends to `hits` `(caster index, cascade bits)` for every sphere some box of `set`
    /// reaches (the bits [`visit_casters_chunked`] gives it over these chunks), sorted by caster
    /// index: the casters' draw order.
    pub fn cull_sorted(&self, set: &CascadeSet, hits: &mut Vec<(u32, u8)>) {
        let first = hits.len();
        visit_casters_chunked(set, &self.centers, &self.radii, &self.chunks, |start, masks| {
            for (&caster, &mask) in self.order[start..].iter().zip(masks) {
                if mask != 0 {
                    hits.push((caster, mask));
                }
            }
        });
        hits[first..].sort_unstable_by_key(|h| h.0);
    }
}

#[cfg(test)]
#[path = "space_order_tests.rs"]
mod tests;
