//! Chunked culling: consecutive runs of [`CHUNK`] bounding spheres share one bounding sphere,
//! tested first. A chunk wholly outside a view (or a cascade box) rejects all its members at
//! once, a chunk wholly inside accepts them all, and only chunks that straddle a boundary
//! test their members one by one. When the spheres are ordered spatially (the instance list
//! is sorted along a Morton curve within each draw key), most chunks are decided whole, so a
//! frame touches a fraction of the spheres.

use glam::Vec3;

use crate::math::aabb::Aabb;
use crate::math::cascades::CascadeSet;
use crate::math::cascades::MAX_SUN_VIEWS;
use crate::math::chunk_groups::{ChunkGroups, GROUP, GroupTest, enclosing_sphere, visit_groups};
use crate::math::culling::{CULL_PADDING, CascadeBoxes, cull_casters, cull_spheres_frustum};
use crate::math::frustum::Frustum;

/// Spheres per chunk.
pub const CHUNK: usize = 64;

/// One bounding sphere per chunk of [`CHUNK`] consecutive spheres.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SphereChunks {
    /// Chunk centres.
    pub centers: Vec<Vec3>,
    /// Chunk radii: every member sphere lies inside. Infinite when a member is not finite,
    /// so such chunks are always tested member by member.
    pub radii: Vec<f32>,
    /// Chunk boxes: the bounds of the member spheres (empty for a chunk with a member that is
    /// not finite). Tighter than the sphere for flat groups, such as casters on the ground.
    pub boxes: Vec<Aabb>,
    /// The largest member radius of each chunk (infinite for a chunk with a member that is
    /// not finite).
    pub max_radii: Vec<f32>,
    /// The chunks' groups, tested before their chunks.
    pub groups: ChunkGroups,
}

impl SphereChunks {
    /// Builds the chunk spheres of `centers`/`radii` (equal lengths).
    pub fn build(centers: &[Vec3], radii: &[f32]) -> Self {
        let mut chunks = SphereChunks::default();
        chunks.rebuild_from(0, centers, radii);
        chunks
    }

    /// Makes the chunks from chunk `first` on again from `centers`/`radii` (members appended
    /// to the arrays this was built from): as [`build`](Self::build) would, for those chunks.
    pub fn rebuild_from(&mut self, first: usize, centers: &[Vec3], radii: &[f32]) {
        let first = first.min(self.len());
        self.centers.truncate(first);
        self.radii.truncate(first);
        self.boxes.truncate(first);
        self.max_radii.truncate(first);
        let start = (first * CHUNK).min(centers.len().min(radii.len()));
        for (c, r) in centers[start..].chunks(CHUNK).zip(radii[start..].chunks(CHUNK)) {
            let (center, radius, bounds) = chunk_sphere(c, r);
            self.centers.push(center);
            self.radii.push(radius);
            self.boxes.push(bounds);
            self.max_radii.push(largest(r, radius));
        }
        let first_group = first / GROUP;
        self.groups
            .rebuild_from(first_group, &self.centers, &self.radii, &self.boxes);
    }

    /// Refits the chunk holding member `index` to its members now in `centers`/`radii` (the
    /// arrays this was built from, with some members moved): as [`build`](Self::build) would,
    /// for that chunk only. An index past the chunks does nothing.
    pub fn refit(&mut self, index: usize, centers: &[Vec3], radii: &[f32]) {
        let k = index / CHUNK;
        let end = (k * CHUNK + CHUNK).min(centers.len()).min(radii.len());
        if k >= self.len() || k * CHUNK >= end {
            return;
        }
        let (center, radius, bounds) = chunk_sphere(&centers[k * CHUNK..end], &radii[k * CHUNK..end]);
        self.centers[k] = center;
        self.radii[k] = radius;
        self.boxes[k] = bounds;
        self.max_radii[k] = largest(&radii[k * CHUNK..end], radius);
        self.groups.refit(k, &self.centers, &self.radii, &self.boxes);
    }

    /// Number of chunks.
    pub fn len(&self) -> usize {
        self.centers.len()
    }

    /// True when there are no chunks.
    pub fn is_empty(&self) -> bool {
        self.centers.is_empty()
    }
}

/// The largest of a chunk's member radii `r`; infinite for a chunk whose sphere is (a member
/// that is not finite).
fn largest(r: &[f32], chunk_radius: f32) -> f32 {
    if chunk_radius.is_infinite() {
        return f32::INFINITY;
    }
    r.iter().fold(0.0, |m, &r| m.max(r))
}

/// The sphere (centre, radius) and box around one chunk's member spheres `c`/`r` (non-empty,
/// equal lengths); a member that is not finite gives an infinite sphere and an empty box.
fn chunk_sphere(c: &[Vec3], r: &[f32]) -> (Vec3, f32, Aabb) {
    let finite = c.iter().all(|p| p.is_finite()) && r.iter().all(|r| r.is_finite());
    if !finite {
        return (Vec3::ZERO, f32::INFINITY, Aabb::EMPTY);
    }
    let bounds = c.iter().zip(r).fold(Aabb::EMPTY, |b, (p, r)| {
        let r = Vec3::splat(r.max(0.0));
        b.union(Aabb {
            min: *p - r,
            max: *p + r,
        })
    });
    let (center, radius) = enclosing_sphere(c, r);
    (center, radius, bounds)
}

/// Cascade bits a chunk sphere overlaps, and those whose box contains it entirely, among the
/// cascades of `mask`.
fn classify_cascades(boxes: &CascadeBoxes, rows: &[[f32; 3]; 3], (center, radius): (Vec3, f32), mask: u8) -> (u8, u8) {
    let p = [0, 1, 2].map(|i| rows[i][0] * center.x + rows[i][1] * center.y + rows[i][2] * center.z);
    // Generous padding: chunk decisions must never be stricter than the member test.
    let r = radius + 4.0 * CULL_PADDING * (p[0].abs() + p[1].abs() + p[2].abs() + radius);
    let (mut overlap, mut inside) = (0u8, 0u8);
    for k in 0..boxes.count.min(MAX_SUN_VIEWS) {
        if mask & (1 << k) == 0 {
            continue;
        }
        let [min_x, min_y, min_z] = boxes.min[k];
        let [max_x, max_y] = boxes.max[k];
        let dx = (min_x - p[0]).max(p[0] - max_x).max(0.0);
        let dy = (min_y - p[1]).max(p[1] - max_y).max(0.0);
        let dz = (min_z - p[2]).max(0.0);
        if dx * dx + dy * dy + dz * dz <= r * r {
            overlap |= 1 << k;
        }
        if p[0] - r >= min_x && p[0] + r <= max_x && p[1] - r >= min_y && p[1] + r <= max_y && p[2] - r >= min_z {
            inside |= 1 << k;
        }
    }
    (overlap & boxes.active & mask, inside & boxes.active & mask)
}

/// [`cull_casters`] with chunk-level early decisions; `chunks` must be built from the same
/// `centers`/`radii`. A caster gets at least the bits the exact test gives; a chunk accepted
/// whole may add a bit for a member within its chunk's reach of a box edge.
pub fn cull_casters_chunked(
    set: &CascadeSet,
    centers: &[Vec3],
    radii: &[f32],
    chunks: &SphereChunks,
    masks: &mut [u8],
) {
    masks.fill(0);
    visit_casters_chunked(set, centers, radii, chunks, |start, bits| {
        masks[start..start + bits.len()].copy_from_slice(bits);
    });
}

/// [`cull_casters_chunked`] for a set of boxes that reaches few casters (a clipmap level's
/// strips): `visit(start, masks)` is called only for the chunks some box reaches, with the
/// cascade bits of the chunk's casters from `start` on, so the casters of the other chunks
/// cost nothing past their chunk's test.
pub fn visit_casters_chunked(
    set: &CascadeSet,
    centers: &[Vec3],
    radii: &[f32],
    chunks: &SphereChunks,
    mut visit: impl FnMut(usize, &[u8]),
) {
    let n = centers.len().min(radii.len());
    let mut masks = [0u8; CHUNK];
    visit_cascade_chunks(set, chunks, (n, u8::MAX), |k, overlap, inside| {
        let start = k * CHUNK;
        let end = (start + CHUNK).min(n);
        let masks = &mut masks[..end - start];
        if overlap == inside {
            masks.fill(overlap);
        } else {
            cull_casters(set, &centers[start..end], &radii[start..end], masks);
        }
        visit(start, masks);
    });
}

/// Calls `visit(k, overlap, inside)` for each chunk `k` of `chunks` (of `n` spheres) that
/// overlaps a cascade box of `set` among the bits of `mask`: the bits of those boxes its
/// sphere overlaps, and of those that hold it whole (a chunk whose sphere is not finite
/// overlaps every box and is inside none). The decisions are padded, never stricter than
/// [`cull_casters`]' member test. The boxes outside `mask` are not tested: a chunk that meets
/// only those is not visited.
pub fn visit_cascade_chunks(
    set: &CascadeSet,
    chunks: &SphereChunks,
    (n, mask): (usize, u8),
    mut visit: impl FnMut(usize, u8, u8),
) {
    let boxes = CascadeBoxes::new(set);
    let rows = set.light_rotation.transpose().to_cols_array_2d();
    let count = n.div_ceil(CHUNK).min(chunks.len());
    // NOTE: a group inside every box it overlaps gives its chunks its answer; a group that
    // overlaps none is skipped.
    let all = boxes.active & mask;
    let test = |center, radius| match classify_cascades(&boxes, &rows, (center, radius), all) {
        (0, _) => GroupTest::Outside,
        (overlap, inside) if overlap == inside => GroupTest::Whole(overlap),
        _ => GroupTest::Split,
    };
    visit_groups(&chunks.groups, count, test, |first, end, whole| {
        // NOTE: a split group's chunks are tested only against the boxes it straddles: they
        // are inside the boxes it is inside and outside those it does not reach.
        let group = (
            chunks.groups.centers.get(first / GROUP),
            chunks.groups.radii.get(first / GROUP),
        );
        let (reach, held) = match group {
            (Some(&center), Some(&radius)) if whole.is_none() && radius.is_finite() => {
                classify_cascades(&boxes, &rows, (center, radius), all)
            }
            _ => (all, 0),
        };
        for k in first..end {
            let (center, radius) = (chunks.centers[k], chunks.radii[k]);
            let (overlap, inside) = match whole {
                Some(&bits) => (bits, bits),
                None if radius.is_finite() => {
                    let (overlap, inside) = classify_cascades(&boxes, &rows, (center, radius), reach & !held);
                    (overlap | held, inside | held)
                }
                None => (all, 0),
            };
            if overlap != 0 {
                visit(k, overlap, inside);
            }
        }
    });
}

/// [`cull_spheres_frustum`] with chunk-level early decisions; `chunks` must be built from the
/// same `centers`/`radii`. Fills `out` (cleared first) with visible indices in ascending order.
pub fn cull_spheres_frustum_chunked(
    frustum: &Frustum,
    centers: &[Vec3],
    radii: &[f32],
    chunks: &SphereChunks,
    out: &mut Vec<u32>,
    scratch: &mut Vec<u32>,
) {
    out.clear();
    let n = centers.len().min(radii.len());
    for (k, (&center, &radius)) in chunks.centers.iter().zip(&chunks.radii).enumerate() {
        let start = k * CHUNK;
        if start >= n {
            break;
        }
        let end = (start + CHUNK).min(n);
        let mut min_distance = f32::INFINITY;
        for plane in &frustum.planes {
            min_distance = min_distance.min(plane.distance(center));
        }
        let r = radius * (1.0 + 1e-5) + 1e-5 * center.abs().max_element();
        if radius.is_finite() && min_distance < -r {
            continue;
        }
        if radius.is_finite() && min_distance >= r {
            out.extend(start as u32..end as u32);
            continue;
        }
        cull_spheres_frustum(frustum, &centers[start..end], &radii[start..end], scratch);
        out.extend(scratch.iter().map(|&i| i + start as u32));
    }
}

/// Clears `out` and fills it, in ascending order, with the indices of the spheres that touch
/// the sphere of `range` around `center` (a point light's reach): chunks wholly outside are
/// skipped, chunks wholly inside taken whole. Non-finite spheres are rejected. The candidates
/// a point light's six faces are then culled from.
pub fn cull_spheres_sphere_chunked(
    center: Vec3,
    range: f32,
    centers: &[Vec3],
    radii: &[f32],
    chunks: &SphereChunks,
    out: &mut Vec<u32>,
) {
    out.clear();
    let n = centers.len().min(radii.len());
    if !(center.is_finite() && range.is_finite()) {
        return;
    }
    let touches = |c: Vec3, r: f32| c.is_finite() && r.is_finite() && c.distance(center) <= range + r.max(0.0);
    for (k, (&chunk_center, &chunk_radius)) in chunks.centers.iter().zip(&chunks.radii).enumerate() {
        let start = k * CHUNK;
        if start >= n {
            break;
        }
        let end = (start + CHUNK).min(n);
        if chunk_radius.is_finite() {
            let distance = chunk_center.distance(center);
            if distance > range + chunk_radius {
                continue;
            }
            // NOTE: every member lies inside the chunk's sphere, so a chunk within the range
            // less its radius is inside whole.
            if distance + chunk_radius <= range {
                out.extend(start as u32..end as u32);
                continue;
            }
        }
        out.extend(
            (start..end)
                .filter(|&i| touches(centers[i], radii[i]))
                .map(|i| i as u32),
        );
    }
}

#[cfg(test)]
#[path = "chunks_tests.rs"]
mod tests;
