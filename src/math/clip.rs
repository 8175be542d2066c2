//! The part of a view-frustum slice that holds receivers: the light-space bounds of a slice
//! (a convex hexahedron) clipped to the world box of everything that receives shadows. A
//! cascade fitted to it spends no texels on sky, on space below the ground, or on ground
//! beyond the scene's edge, which very wide or very flat views are mostly made of.

use glam::{DMat3, DVec3};

/// The slice's six faces as quads of corner indices (corners in the order of
/// [`CameraBasis::slice_offsets`](crate::math::frustum::CameraBasis::slice_offsets): the near
/// rectangle, then the far one, each bottom-left, bottom-right, top-right, top-left).
const FACES: [[usize; 4]; 6] = [
    [0, 1, 2, 3],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
];

/// A plane `n · p = d` with `n` pointing out of the solid.
#[derive(Clone, Copy, Debug)]
struct HalfSpace {
    n: DVec3,
    d: f64,
}

/// Light-space bounds `(lo, hi)` (`rot · p`) of the part of the slice with corners `corners`
/// (any frame, in `FACES`' order) inside the box `[box_min, box_max]` (same frame); None
/// when they do not meet. Exact for a convex slice: the points taken are the vertices of the
/// intersection (corners of either inside the other, and edges of either through the other's
/// faces), with a tolerance of a billionth of the larger solid's size.
pub fn clipped_bounds(corners: &[DVec3; 8], box_min: DVec3, box_max: DVec3, rot: &DMat3) -> Option<(DVec3, DVec3)> {
    if !(box_min.cmple(box_max).all() && corners.iter().all(|c| c.is_finite())) {
        return None;
    }
    let slice_size = corners
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &c| {
            (lo.min(c), hi.max(c))
        });
    let scale = (slice_size.1 - slice_size.0)
        .max_element()
        .max((box_max - box_min).max_element())
        .max(1e-300);
    let eps = scale * 1e-9;
    let planes = slice_planes(corners);
    let in_slice = |p: DVec3| planes.iter().flatten().all(|h| h.n.dot(p) - h.d <= eps);
    let in_box = |p: DVec3| p.cmpge(box_min - eps).all() && p.cmple(box_max + eps).all();

    let mut bounds = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    let mut add = |p: DVec3| {
        let l = *rot * p;
        bounds = (bounds.0.min(l), bounds.1.max(l));
    };
    for &c in corners {
        if in_box(c) {
            add(c);
        }
    }
    let box_corners: [DVec3; 8] = std::array::from_fn(|i| {
        DVec3::new(
            if i & 1 == 0 { box_min.x } else { box_max.x },
            if i & 2 == 0 { box_min.y } else { box_max.y },
            if i & 4 == 0 { box_min.z } else { box_max.z },
        )
    });
    for &c in &box_corners {
        if in_slice(c) {
            add(c);
        }
    }
    // The slice's edges through the box's faces.
    for (a, b) in slice_edges().map(|(i, j)| (corners[i], corners[j])) {
        for axis in 0..3 {
            for v in [box_min[axis], box_max[axis]] {
                let span = b[axis] - a[axis];
                if span == 0.0 {
                    continue;
                }
                let t = (v - a[axis]) / span;
                if (0.0..=1.0).contains(&t) {
                    let p = a + (b - a) * t;
                    if in_box(p) {
                        add(p);
                    }
                }
            }
        }
    }
    // The box's edges through the slice's faces.
    for (a, b) in box_edges().map(|(i, j)| (box_corners[i], box_corners[j])) {
        for h in planes.iter().flatten() {
            let span = h.n.dot(b - a);
            if span == 0.0 {
                continue;
            }
            let t = (h.d - h.n.dot(a)) / span;
            if (0.0..=1.0).contains(&t) {
                let p = a + (b - a) * t;
                if in_slice(p) {
                    add(p);
                }
            }
        }
    }
    (bounds.0.cmple(bounds.1).all()).then_some(bounds)
}

/// The slice's faces as outward half-spaces; None for a face too small to have a plane (the
/// near rectangle of a slice starting at the camera).
fn slice_planes(corners: &[DVec3; 8]) -> [Option<HalfSpace>; 6] {
    let centre = corners.iter().sum::<DVec3>() / 8.0;
    FACES.map(|[a, b, c, d]| {
        let (p, q, r, s) = (corners[a], corners[b], corners[c], corners[d]);
        // The quad's normal from its diagonals: defined even if one edge is degenerate.
        let n = (r - p).cross(s - q);
        let len = n.length();
        if !(len > 0.0 && len.is_finite()) {
            return None;
        }
        let mut n = n / len;
        let mut d = n.dot((p + q + r + s) * 0.25);
        if n.dot(centre) - d > 0.0 {
            n = -n;
            d = -d;
        }
        Some(HalfSpace { n, d })
    })
}

/// The slice's twelve edges: the near and far rectangles and the four lines between them.
fn slice_edges() -> [(usize, usize); 12] {
    [
        (0, 1),
        (1, 2),
        (2, 3),
        (3, 0),
        (4, 5),
        (5, 6),
        (6, 7),
        (7, 4),
        (0, 4),
        (1, 5),
        (2, 6),
        (3, 7),
    ]
}

/// The box's twelve edges, its corners numbered by the bits x, y, z (1 = max).
fn box_edges() -> [(usize, usize); 12] {
    [
        (0, 1),
        (2, 3),
        (4, 5),
        (6, 7),
        (0, 2),
        (1, 3),
        (4, 6),
        (5, 7),
        (0, 4),
        (1, 5),
        (2, 6),
        (3, 7),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit-ish slice: near rectangle 2 × 2 at z = −1, far 6 × 6 at z = −3 (camera at the
    /// origin looking down −z).
    fn slice() -> [DVec3; 8] {
        let rect = |h: f64, z: f64| [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(x, y)| DVec3::new(x, y, z));
        let (n, f) = (rect(1.0, -1.0), rect(3.0, -3.0));
        [n[0], n[1], n[2], n[3], f[0], f[1], f[2], f[3]]
    }

    #[test]
    fn a_box_around_the_slice_leaves_its_bounds() {
        let (lo, hi) = clipped_bounds(&slice(), DVec3::splat(-10.0), DVec3::splat(10.0), &DMat3::IDENTITY).unwrap();
        assert_eq!((lo, hi), (DVec3::new(-3.0, -3.0, -3.0), DVec3::new(3.0, 3.0, -1.0)));
    }

    #[test]
    fn a_ground_slab_cuts_the_slice_to_its_height() {
        // Everything below y = −0.5 (a ground at y = −1 and casters up to 0.5 m on it).
        let (lo, hi) = clipped_bounds(
            &slice(),
            DVec3::new(-100.0, -1.0, -100.0),
            DVec3::new(100.0, -0.5, 100.0),
            &DMat3::IDENTITY,
        )
        .unwrap();
        assert!((lo.y + 1.0).abs() < 1e-12 && (hi.y + 0.5).abs() < 1e-12, "{lo} {hi}");
        // The slab meets the slice from the near plane (where the slice's floor is y = −1)
        // to the far plane; laterally the far rectangle's whole width.
        assert!((lo.x + 3.0).abs() < 1e-12 && (hi.x - 3.0).abs() < 1e-12, "{lo} {hi}");
        assert!((hi.z + 1.0).abs() < 1e-12 && (lo.z + 3.0).abs() < 1e-12, "{lo} {hi}");
    }

    #[test]
    fn a_small_box_inside_the_slice_is_its_own_bounds() {
        let (lo, hi) = clipped_bounds(
            &slice(),
            DVec3::new(-0.5, -0.25, -2.5),
            DVec3::new(0.5, 0.25, -1.5),
            &DMat3::IDENTITY,
        )
        .unwrap();
        assert_eq!((lo, hi), (DVec3::new(-0.5, -0.25, -2.5), DVec3::new(0.5, 0.25, -1.5)));
    }

    #[test]
    fn disjoint_solids_have_no_bounds_and_rotation_is_applied() {
        let far_away = clipped_bounds(&slice(), DVec3::splat(20.0), DVec3::splat(21.0), &DMat3::IDENTITY);
        assert_eq!(far_away, None);
        let behind = clipped_bounds(&slice(), DVec3::new(-1.0, -1.0, 0.5), DVec3::ONE, &DMat3::IDENTITY);
        assert_eq!(behind, None);
        // A quarter turn about z swaps x and y of the bounds.
        let rot = DMat3::from_rotation_z(std::f64::consts::FRAC_PI_2);
        let (lo, hi) = clipped_bounds(
            &slice(),
            DVec3::new(-0.5, -0.25, -2.5),
            DVec3::new(0.5, 0.25, -1.5),
            &rot,
        )
        .unwrap();
        assert!((lo - DVec3::new(-0.25, -0.5, -2.5)).abs().max_element() < 1e-12, "{lo}");
        assert!((hi - DVec3::new(0.25, 0.5, -1.5)).abs().max_element() < 1e-12, "{hi}");
    }

    #[test]
    fn the_bounds_hold_every_point_of_the_intersection_and_no_more() {
        // Sample points of the slice; those inside a tilted-ish box must lie in the bounds,
        // and the bounds must be reached by some of them (within the sampling step).
        let rot = DMat3::from_euler(glam::EulerRot::YXZ, 0.7, -0.4, 0.2);
        let (bmin, bmax) = (DVec3::new(-2.0, -0.3, -2.6), DVec3::new(1.0, 5.0, -1.2));
        let (lo, hi) = clipped_bounds(&slice(), bmin, bmax, &rot).unwrap();
        let c = slice();
        let mut seen = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        let n = 40;
        for i in 0..=n {
            for j in 0..=n {
                for k in 0..=n {
                    let (u, v, w) = (i as f64 / n as f64, j as f64 / n as f64, k as f64 / n as f64);
                    let near = c[0] + (c[1] - c[0]) * u + (c[3] - c[0]) * v;
                    let far = c[4] + (c[5] - c[4]) * u + (c[7] - c[4]) * v;
                    let p = near + (far - near) * w;
                    if p.cmpge(bmin).all() && p.cmple(bmax).all() {
                        let l = rot * p;
                        assert!(
                            l.cmpge(lo - 1e-9).all() && l.cmple(hi + 1e-9).all(),
                            "{l} outside {lo}..{hi}"
                        );
                        seen = (seen.0.min(l), seen.1.max(l));
                    }
                }
            }
        }
        assert!((seen.0 - lo).abs().max_element() < 0.2 && (seen.1 - hi).abs().max_element() < 0.2);
    }
}
