//! Axis-aligned bounding boxes: construction, union, and transformation by an affine matrix
//! (Arvo's method).

use glam::{Mat4, Vec3};

/// An axis-aligned box given by its minimum and maximum corners.
///
/// A box with any `min` component greater than the matching `max` component (or a NaN) is
/// empty; [`Aabb::EMPTY`] is the canonical empty box and the identity of [`Aabb::union`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Default for Aabb {
    /// The empty box.
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The empty box: `min = +∞`, `max = −∞`, so that `EMPTY.union(b) == b` for any `b`.
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// A box from its two corners, taken as given (no reordering).
    pub const fn new(min: Vec3, max: Vec3) -> Self {
        Self { min, max }
    }

    /// The smallest box holding every point; [`Aabb::EMPTY`] for no points.
    pub fn from_points(points: &[Vec3]) -> Self {
        points.iter().fold(Self::EMPTY, |b, &p| b.with_point(p))
    }

    /// This box grown to hold `p` as well.
    pub fn with_point(self, p: Vec3) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// This box grown outwards onto a grid whose cell is the power of two at or above its
    /// largest side divided by `divisions`: small changes of the box (an object moving
    /// inside it, or past its edge by less than a cell) mostly leave the result unchanged.
    /// Empty and non-finite boxes are returned as they are.
    pub fn snapped_out(self, divisions: f32) -> Self {
        if self.is_empty() || !self.is_finite() {
            return self;
        }
        let side = (self.max - self.min).max_element().max(f32::MIN_POSITIVE);
        let cell = (side / divisions.max(1.0)).log2().ceil().exp2();
        if !(cell.is_finite() && cell > 0.0) {
            return self;
        }
        let snapped = Self {
            min: (self.min / cell).floor() * cell,
            max: (self.max / cell).ceil() * cell,
        };
        // NOTE: at huge coordinates the division and product round; never shrink.
        if snapped.is_finite() { snapped.union(self) } else { self }
    }

    /// The smallest box holding both boxes.
    pub fn union(self, other: Aabb) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// True when the box holds no point (some `min > max`, or a NaN bound).
    pub fn is_empty(&self) -> bool {
        // NOTE: written as a negated `<=` so a NaN bound also counts as empty.
        !self.min.cmple(self.max).all()
    }

    /// True when all six bounds are finite (an empty box is never finite).
    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }

    /// Centre point. Meaningless for an empty box.
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Half the size along each axis. Meaningless for an empty box.
    pub fn half_extents(&self) -> Vec3 {
        (self.max - self.min) * 0.5
    }

    /// The eight corners; bit 0 of the index selects `max.x`, bit 1 `max.y`, bit 2 `max.z`.
    pub fn corners(&self) -> [Vec3; 8] {
        std::array::from_fn(|i| {
            Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }

    /// The centre and radius of a sphere holding the box (the sphere through its corners).
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        (self.center(), self.half_extents().length())
    }

    /// The box bounding this box after the affine transform `m` (Arvo, "Transforming
    /// Axis-Aligned Bounding Boxes", Graphics Gems 1990).
    ///
    /// `m` must be affine (bottom row `0 0 0 1`); its projective row is ignored. The empty box
    /// stays empty.
    pub fn transformed(&self, m: &Mat4) -> Aabb {
        if self.is_empty() {
            // NOTE: the ±∞ bounds of an empty box would give ∞·0 = NaN below.
            return Self::EMPTY;
        }
        let t = m.w_axis.truncate();
        let mut min = t;
        let mut max = t;
        // Each output coordinate is a sum over input axes; for every term pick whichever of
        // the two input bounds makes it smaller (for min) or larger (for max).
        for (col, lo, hi) in [
            (m.x_axis.truncate(), self.min.x, self.max.x),
            (m.y_axis.truncate(), self.min.y, self.max.y),
            (m.z_axis.truncate(), self.min.z, self.max.z),
        ] {
            let a = col * lo;
            let b = col * hi;
            min += a.min(b);
            max += a.max(b);
        }
        Aabb { min, max }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snapping_grows_onto_a_power_of_two_grid_and_ignores_small_moves() {
        let b = Aabb::new(Vec3::new(-100.0, 0.0, -100.0), Vec3::new(100.0, 8.0, 100.0));
        // 200 m / 256 → a 1 m cell: already on it.
        assert_eq!(b.snapped_out(256.0), b);
        let moved = Aabb::new(Vec3::new(-100.3, 0.0, -99.6), Vec3::new(100.2, 8.4, 100.0));
        let s = moved.snapped_out(256.0);
        assert_eq!(
            s,
            Aabb::new(Vec3::new(-101.0, 0.0, -100.0), Vec3::new(101.0, 9.0, 100.0))
        );
        assert_eq!(moved.with_point(Vec3::new(0.0, 8.7, 0.0)).snapped_out(256.0), s);
        assert_eq!(Aabb::EMPTY.snapped_out(256.0), Aabb::EMPTY);
        let huge = Aabb::new(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX));
        assert_eq!(huge.snapped_out(256.0), huge);
    }
    use glam::Quat;

    #[test]
    fn empty_is_union_identity() {
        let b = Aabb::new(Vec3::new(-1.0, 2.0, 3.0), Vec3::new(4.0, 5.0, 6.0));
        assert!(Aabb::EMPTY.is_empty());
        assert!(!Aabb::EMPTY.is_finite());
        assert_eq!(Aabb::EMPTY.union(b), b);
        assert_eq!(b.union(Aabb::EMPTY), b);
        assert_eq!(Aabb::from_points(&[]), Aabb::EMPTY);
        assert!(Aabb::new(Vec3::splat(f32::NAN), Vec3::ONE).is_empty());
    }

    #[test]
    fn from_points_bounds_all_points() {
        let pts = [
            Vec3::new(1.0, -2.0, 0.5),
            Vec3::new(-3.0, 4.0, 2.0),
            Vec3::new(0.0, 0.0, -7.0),
        ];
        let b = Aabb::from_points(&pts);
        assert_eq!(b.min, Vec3::new(-3.0, -2.0, -7.0));
        assert_eq!(b.max, Vec3::new(1.0, 4.0, 2.0));
        assert_eq!(b.center(), Vec3::new(-1.0, 1.0, -2.5));
        assert_eq!(b.half_extents(), Vec3::new(2.0, 3.0, 4.5));
    }

    #[test]
    fn corners_are_distinct_and_on_the_box() {
        let b = Aabb::new(Vec3::new(-1.0, -2.0, -3.0), Vec3::new(1.0, 2.0, 3.0));
        let c = b.corners();
        for (i, p) in c.iter().enumerate() {
            assert_eq!(p.abs(), Vec3::new(1.0, 2.0, 3.0));
            for q in &c[i + 1..] {
                assert_ne!(p, q);
            }
        }
        assert_eq!(Aabb::from_points(&c), b);
    }

    #[test]
    fn bounding_sphere_holds_the_corners() {
        let b = Aabb::new(Vec3::new(0.0, 1.0, 2.0), Vec3::new(3.0, 5.0, 2.5));
        let (c, r) = b.bounding_sphere();
        for p in b.corners() {
            assert!(p.distance(c) <= r * (1.0 + 1e-6));
        }
        assert!((r - Vec3::new(1.5, 2.0, 0.25).length()).abs() < 1e-6);
    }

    #[test]
    fn transformed_matches_transformed_corners() {
        let b = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(2.0, 3.0, 4.0));
        let m = Mat4::from_scale_rotation_translation(
            Vec3::new(2.0, 0.5, 1.0),
            Quat::from_euler(glam::EulerRot::YXZ, 0.7, -0.3, 1.1),
            Vec3::new(10.0, -5.0, 3.0),
        );
        let got = b.transformed(&m);
        let want = Aabb::from_points(&b.corners().map(|p| m.transform_point3(p)));
        assert!(got.min.abs_diff_eq(want.min, 1e-5), "{got:?} vs {want:?}");
        assert!(got.max.abs_diff_eq(want.max, 1e-5), "{got:?} vs {want:?}");
    }

    #[test]
    fn transformed_by_translation_and_empty() {
        let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let t = b.transformed(&Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)));
        assert_eq!(t, Aabb::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(2.0, 3.0, 4.0)));
        assert!(Aabb::EMPTY.transformed(&Mat4::IDENTITY).is_empty());
    }
}
