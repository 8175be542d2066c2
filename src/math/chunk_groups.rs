//! Groups of culling chunks: consecutive runs of [`GROUP`] chunk spheres share one sphere and
//! box, tested before their chunks. A million spheres make 15 625 chunks but only 245 groups,
//! so a view that sees a small part of a large scene decides most of it group by group.

use glam::Vec3;

use crate::math::aabb::Aabb;
use crate::math::frustum::Frustum;

/// Chunks per group.
pub const GROUP: usize = 64;

/// One sphere and box per group of [`GROUP`] consecutive chunks (see
/// [`SphereChunks::groups`](crate::math::chunks::SphereChunks::groups)).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ChunkGroups {
    /// Group centres.
    pub centers: Vec<Vec3>,
    /// Group radii: every chunk sphere of the group lies inside. Infinite when a chunk's is.
    pub radii: Vec<f32>,
    /// Group boxes: the union of the chunks' boxes (empty when a chunk's is).
    pub boxes: Vec<Aabb>,
}

impl ChunkGroups {
    /// Makes the groups from group `first` on again from the chunks' `centers`, `radii` and
    /// `boxes` (equal lengths).
    pub fn rebuild_from(&mut self, first: usize, centers: &[Vec3], radii: &[f32], boxes: &[Aabb]) {
        let first = first.min(self.centers.len());
        self.centers.truncate(first);
        self.radii.truncate(first);
        self.boxes.truncate(first);
        let start = (first * GROUP).min(centers.len());
        for k in (start..centers.len()).step_by(GROUP) {
            let end = (k + GROUP).min(centers.len());
            let (center, radius, bounds) = group_sphere(&centers[k..end], &radii[k..end], &boxes[k..end]);
            self.centers.push(center);
            self.radii.push(radius);
            self.boxes.push(bounds);
        }
    }

    /// Refits the group holding chunk `chunk` to the chunks now in `centers`, `radii` and
    /// `boxes`; a chunk past the groups does nothing.
    pub fn refit(&mut self, chunk: usize, centers: &[Vec3], radii: &[f32], boxes: &[Aabb]) {
        let g = chunk / GROUP;
        let end = (g * GROUP + GROUP).min(centers.len());
        if g >= self.centers.len() || g * GROUP >= end {
            return;
        }
        let range = g * GROUP..end;
        let (center, radius, bounds) = group_sphere(&centers[range.clone()], &radii[range.clone()], &boxes[range]);
        self.centers[g] = center;
        self.radii[g] = radius;
        self.boxes[g] = bounds;
    }

    /// Number of groups.
    pub fn len(&self) -> usize {
        self.centers.len()
    }

    /// True when there are no groups.
    pub fn is_empty(&self) -> bool {
        self.centers.is_empty()
    }
}

/// The sphere and box around one group's chunk spheres `c`/`r` and boxes `b` (non-empty); a
/// chunk whose sphere is infinite gives an infinite sphere and an empty box.
fn group_sphere(c: &[Vec3], r: &[f32], b: &[Aabb]) -> (Vec3, f32, Aabb) {
    if r.iter().any(|r| !r.is_finite()) {
        return (Vec3::ZERO, f32::INFINITY, Aabb::EMPTY);
    }
    let (center, radius) = enclosing_sphere(c, r);
    (center, radius, b.iter().fold(Aabb::EMPTY, |a, b| a.union(*b)))
}

/// A sphere around the spheres `c`/`r` (finite, non-empty, equal lengths; a negative radius
/// counts as 0): centred on the box of the centres, reaching the farthest sphere, padded by a
/// relative 1e-5 so f32 rounding of the distances never leaves one poking out. The chunks'
/// spheres and the groups' are made alike.
pub(crate) fn enclosing_sphere(c: &[Vec3], r: &[f32]) -> (Vec3, f32) {
    let (lo, hi) = c.iter().fold((c[0], c[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let center = (lo + hi) * 0.5;
    let reach = c
        .iter()
        .zip(r)
        .map(|(p, r)| p.distance(center) + r.max(0.0))
        .fold(0.0, f32::max);
    (center, reach * (1.0 + 1e-5) + 1e-6)
}

/// Calls `visit(first, end, whole)` for each group of `groups` that `test` (given a group's
/// centre and radius) does not reject, with its chunks `first..end` (of `chunks` chunks) and
/// what `test` said of it: `Some(whole)` when `test` decided for all its chunks (the group's
/// answer holds for each), `None` when each chunk must be tested. A group whose sphere is not
/// finite is never decided whole.
pub fn visit_groups<T>(
    groups: &ChunkGroups,
    chunks: usize,
    mut test: impl FnMut(Vec3, f32) -> GroupTest<T>,
    mut visit: impl FnMut(usize, usize, Option<&T>),
) {
    for (g, (&center, &radius)) in groups.centers.iter().zip(&groups.radii).enumerate() {
        let (first, end) = (g * GROUP, ((g + 1) * GROUP).min(chunks));
        if first >= end {
            break;
        }
        if !radius.is_finite() {
            visit(first, end, None);
            continue;
        }
        match test(center, radius) {
            GroupTest::Outside => {}
            GroupTest::Whole(answer) => visit(first, end, Some(&answer)),
            GroupTest::Split => visit(first, end, None),
        }
    }
    // NOTE: chunks past the groups (groups not made for them) are tested one by one.
    let covered = (groups.len() * GROUP).min(chunks);
    if covered < chunks {
        visit(covered, chunks, None);
    }
}

/// A group test against `frustum` (and, with `reach`, the sphere of a light's position and
/// range): outside when the group's sphere is outside a plane or out of reach, whole when it
/// is inside every plane and within reach.
pub fn frustum_test(frustum: &Frustum, reach: Option<(Vec3, f32)>, center: Vec3, radius: f32) -> GroupTest<()> {
    let distance = reach.map_or(0.0, |(light, _)| center.distance(light));
    let range = reach.map_or(f32::INFINITY, |(_, range)| range);
    if !frustum.intersects_sphere(center, radius) || distance > range + radius {
        GroupTest::Outside
    } else if frustum.planes.iter().all(|p| p.distance(center) >= radius) && distance + radius <= range {
        GroupTest::Whole(())
    } else {
        GroupTest::Split
    }
}

/// What a test says of a group of chunks.
pub enum GroupTest<T> {
    /// No chunk of it can pass: skipped.
    Outside,
    /// Every chunk of it gets this answer.
    Whole(T),
    /// Its chunks must be tested one by one.
    Split,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn group_spheres_hold_their_chunks_and_refits_equal_rebuilds() {
        let n: usize = 200;
        let mut centers: Vec<Vec3> = (0..n)
            .map(|i| Vec3::new(i as f32 * 3.0, (i % 7) as f32, -(i as f32)))
            .collect();
        let mut radii: Vec<f32> = (0..n).map(|i| 0.5 + (i % 5) as f32).collect();
        let boxes = |c: &[Vec3], r: &[f32]| -> Vec<Aabb> {
            c.iter()
                .zip(r)
                .map(|(c, &r)| Aabb::new(*c - Vec3::splat(r), *c + Vec3::splat(r)))
                .collect()
        };
        let mut groups = ChunkGroups::default();
        groups.rebuild_from(0, &centers, &radii, &boxes(&centers, &radii));
        assert_eq!(groups.len(), n.div_ceil(GROUP));
        for (k, (c, r)) in centers.iter().zip(&radii).enumerate() {
            let g = k / GROUP;
            assert!(
                c.distance(groups.centers[g]) + r <= groups.radii[g],
                "chunk {k} pokes out"
            );
        }
        centers[130] = Vec3::new(-500.0, 2.0, 9.0);
        radii[130] = 40.0;
        radii[3] = f32::INFINITY;
        let b = boxes(&centers, &radii);
        groups.refit(130, &centers, &radii, &b);
        groups.refit(3, &centers, &radii, &b);
        let mut fresh = ChunkGroups::default();
        fresh.rebuild_from(0, &centers, &radii, &b);
        assert_eq!(groups, fresh);
        assert!(groups.radii[0].is_infinite());
        let mut visited = Vec::new();
        let test = |_: Vec3, _: f32| GroupTest::Whole(());
        visit_groups(&groups, n, test, |first, end, whole| {
            visited.push((first, end, whole.is_some()))
        });
        assert_eq!(
            visited,
            [(0, 64, false), (64, 128, true), (128, 192, true), (192, 200, true)]
        );
    }
}
