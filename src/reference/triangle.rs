//! Two-sided ray/triangle intersection and alpha-mask lookup, the per-hit work of the any-hit
//! shadow query.

use glam::{Vec2, Vec3};

use super::AlphaMask;

/// Marks a triangle without an alpha mask in [`Tri::masked`].
pub(crate) const OPAQUE: u32 = u32::MAX;

/// Slack on the barycentric range tests, so that a ray through the shared edge of two triangles
/// cannot slip between them through rounding (it may hit both, which an any-hit query does not
/// mind). Moves open edges outwards by a millionth of the triangle's size.
const BARYCENTRIC_SLACK: f32 = 1e-6;

/// A world-space triangle stored as a corner and two edges.
///
/// Edges rather than corners keep the intersection exact-ish far from the origin: `v1 − v0`
/// is computed once, and `origin − v0` is a difference of nearby numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Tri {
    /// First corner.
    pub v0: Vec3,
    /// Second corner minus the first.
    pub e1: Vec3,
    /// Third corner minus the first.
    pub e2: Vec3,
    /// Index into the scene's masked-triangle table, or [`OPAQUE`].
    pub masked: u32,
}

impl Tri {
    /// Möller–Trumbore, both faces: the barycentric weights `(u, v)` of the second and third
    /// corners where the ray `origin + t·dir`, `0 < t < t_max`, crosses the triangle, if it
    /// does.
    #[inline(always)]
    pub(crate) fn intersect(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Vec2> {
        let p = dir.cross(self.e2);
        let det = self.e1.dot(p);
        if det == 0.0 {
            return None;
        }
        let inv = 1.0 / det;
        let s = origin - self.v0;
        let u = s.dot(p) * inv;
        // NOTE: a NaN is in no range, so it misses.
        if !(-BARYCENTRIC_SLACK..=1.0 + BARYCENTRIC_SLACK).contains(&u) {
            return None;
        }
        let q = s.cross(self.e1);
        let v = dir.dot(q) * inv;
        if !(v >= -BARYCENTRIC_SLACK && u + v <= 1.0 + BARYCENTRIC_SLACK) {
            return None;
        }
        let t = self.e2.dot(q) * inv;
        (t > 0.0 && t < t_max).then_some(Vec2::new(u, v))
    }
}

/// Texture coordinates of a masked triangle: `uv = uv0 + duv1·u + duv2·v`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct MaskedTri {
    /// UV at the first corner.
    pub uv0: Vec2,
    /// UV at the second corner minus `uv0`.
    pub duv1: Vec2,
    /// UV at the third corner minus `uv0`.
    pub duv2: Vec2,
    /// Index into the scene's mask table.
    pub mask: u32,
}

impl MaskedTri {
    /// The texture coordinate at barycentric weights `bary` (of the second and third corners).
    #[inline]
    pub(crate) fn uv(&self, bary: Vec2) -> Vec2 {
        self.uv0 + self.duv1 * bary.x + self.duv2 * bary.y
    }
}

/// An [`AlphaMask`] reduced to one flag per texel: does the texel stop rays?
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct MaskTexels {
    width: u32,
    height: u32,
    opaque: Vec<bool>,
}

impl MaskTexels {
    /// Thresholds the mask: a texel stops rays unless `alpha / 255 · factor < cutoff`.
    ///
    /// A mask whose size is zero or whose `alpha` is shorter than `width · height` counts as a
    /// single texel of alpha 1, so that only `factor` and `cutoff` matter.
    pub(crate) fn new(mask: &AlphaMask) -> Self {
        let texels = mask.width as usize * mask.height as usize;
        let clear = |a: u8| f32::from(a) / 255.0 * mask.factor < mask.cutoff;
        let stops = |a: u8| !clear(a);
        if texels == 0 || mask.alpha.len() < texels {
            return Self {
                width: 1,
                height: 1,
                opaque: vec![stops(255)],
            };
        }
        Self {
            width: mask.width,
            height: mask.height,
            opaque: mask.alpha[..texels].iter().map(|&a| stops(a)).collect(),
        }
    }

    /// True when every texel stops rays (the mask can be ignored).
    pub(crate) fn all_opaque(&self) -> bool {
        self.opaque.iter().all(|&o| o)
    }

    /// Whether the texel nearest to `uv` stops rays. Repeat wrapping; `v = 0` is the top row;
    /// a NaN coordinate reads texel 0.
    #[inline]
    pub(crate) fn opaque_at(&self, uv: Vec2) -> bool {
        let fx = uv.x - uv.x.floor();
        let fy = uv.y - uv.y.floor();
        // NOTE: `as u32` saturates (NaN gives 0) and the `min` catches fx rounding up to 1.
        let x = ((fx * self.width as f32) as u32).min(self.width - 1);
        let y = ((fy * self.height as f32) as u32).min(self.height - 1);
        self.opaque[y as usize * self.width as usize + x as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: Vec3, b: Vec3, c: Vec3) -> Tri {
        Tri {
            v0: a,
            e1: b - a,
            e2: c - a,
            masked: OPAQUE,
        }
    }

    #[test]
    fn hits_both_faces_and_reports_barycentrics() {
        let t = tri(Vec3::ZERO, Vec3::X, Vec3::Z);
        let up = t.intersect(Vec3::new(0.25, -1.0, 0.5), Vec3::Y, f32::INFINITY).unwrap();
        assert!((up - Vec2::new(0.25, 0.5)).length() < 1e-6, "{up}");
        let down = t
            .intersect(Vec3::new(0.25, 1.0, 0.5), Vec3::NEG_Y, f32::INFINITY)
            .unwrap();
        assert!((down - Vec2::new(0.25, 0.5)).length() < 1e-6, "{down}");
        // Oblique ray.
        let d = Vec3::new(0.1, 1.0, -0.2).normalize();
        let o = Vec3::new(0.3, 0.0, 0.3) - d * 5.0;
        let b = t.intersect(o, d, f32::INFINITY).unwrap();
        assert!((b - Vec2::new(0.3, 0.3)).length() < 1e-5, "{b}");
    }

    #[test]
    fn misses_outside_behind_and_parallel() {
        let t = tri(Vec3::ZERO, Vec3::X, Vec3::Z);
        assert!(t.intersect(Vec3::new(0.6, -1.0, 0.6), Vec3::Y, f32::INFINITY).is_none()); // past the hypotenuse
        assert!(
            t.intersect(Vec3::new(-0.1, -1.0, 0.5), Vec3::Y, f32::INFINITY)
                .is_none()
        );
        assert!(
            t.intersect(Vec3::new(0.5, -1.0, -0.1), Vec3::Y, f32::INFINITY)
                .is_none()
        );
        assert!(t.intersect(Vec3::new(0.2, 1.0, 0.2), Vec3::Y, f32::INFINITY).is_none()); // behind the origin
        assert!(t.intersect(Vec3::new(-1.0, 0.0, 0.2), Vec3::X, f32::INFINITY).is_none()); // in the plane
        assert!(
            t.intersect(Vec3::new(0.2, -1.0, 0.2), Vec3::NAN, f32::INFINITY)
                .is_none()
        );
        // A light at distance 0.5 below the triangle (which is 1 away): the triangle is behind it.
        assert!(t.intersect(Vec3::new(0.25, -1.0, 0.5), Vec3::Y, 0.5).is_none());
        assert!(t.intersect(Vec3::new(0.25, -1.0, 0.5), Vec3::Y, 1.5).is_some());
    }

    #[test]
    fn shared_edge_is_watertight_far_from_the_origin() {
        // Two triangles of a square at 1e5 m; rays straight through the diagonal must hit one.
        let o = Vec3::new(1e5, 3.0, 1e5);
        let (a, b, c, d) = (
            o,
            o + Vec3::X * 50.0,
            o + Vec3::new(50.0, 0.0, 50.0),
            o + Vec3::Z * 50.0,
        );
        let t1 = tri(a, b, c);
        let t2 = tri(a, c, d);
        for i in 0..=1000 {
            // Start points and directions symmetric in x and z, so every ray crosses y = 3
            // exactly on the diagonal.
            let s = i as f32 * 0.05;
            let p = Vec3::new(o.x + s, 0.0, o.z + s);
            let a = 0.001 * (i % 7) as f32 - 0.003;
            let dir = Vec3::new(a, 1.0, a).normalize();
            let hit = t1.intersect(p, dir, f32::INFINITY).is_some() || t2.intersect(p, dir, f32::INFINITY).is_some();
            let along = (p + dir * (3.0 / dir.y)).x - o.x;
            if along > 0.01 && along < 49.99 {
                assert!(hit, "ray {i} slipped through the diagonal");
            }
        }
    }

    fn mask(width: u32, height: u32, alpha: Vec<u8>) -> AlphaMask {
        AlphaMask {
            width,
            height,
            alpha,
            factor: 1.0,
            cutoff: 0.5,
        }
    }

    #[test]
    fn mask_lookup_is_nearest_with_repeat_and_top_row_first() {
        // 2×2: top row opaque/clear, bottom row clear/opaque.
        let m = MaskTexels::new(&mask(2, 2, vec![255, 0, 0, 255]));
        assert!(m.opaque_at(Vec2::new(0.25, 0.25)));
        assert!(!m.opaque_at(Vec2::new(0.75, 0.25)));
        assert!(!m.opaque_at(Vec2::new(0.25, 0.75)));
        assert!(m.opaque_at(Vec2::new(0.75, 0.75)));
        assert!(m.opaque_at(Vec2::new(1.25, -0.75)));
        assert!(!m.opaque_at(Vec2::new(-0.25, 3.25)));
        assert!(m.opaque_at(Vec2::new(0.9999999, 0.9999999)));
        assert!(m.opaque_at(Vec2::NAN));
        assert!(!m.all_opaque());
    }

    #[test]
    fn mask_threshold_uses_factor_and_cutoff() {
        let mut am = mask(3, 1, vec![127, 128, 255]);
        let m = MaskTexels::new(&am);
        assert_eq!(m.opaque, [false, true, true]);
        am.factor = 0.4;
        assert_eq!(MaskTexels::new(&am).opaque, [false, false, false]);
        am.factor = 1.0;
        am.cutoff = 0.0;
        assert!(MaskTexels::new(&am).all_opaque());
        // Malformed masks fall back to a single texel of alpha 1.
        let short = MaskTexels::new(&mask(4, 4, vec![0; 3]));
        assert!(short.all_opaque());
        let mut empty = mask(0, 7, vec![]);
        empty.factor = 0.2;
        assert!(!MaskTexels::new(&empty).opaque_at(Vec2::new(0.3, 0.3)));
    }
}
