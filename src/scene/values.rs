//! The value checks a scene's fields share (a direction that normalises, a colour, a size)
//! and how a checked value is shown in a message, as a scene file would write it.

use glam::{UVec3, Vec2, Vec3, Vec4};

/// Shortest vector a direction may be: about the shortest whose squared length a 32-bit float
/// still holds, so that it normalises.
pub(crate) const MIN_DIRECTION_LENGTH: f64 = 1e-22;

pub(crate) fn is_direction(v: Vec3) -> bool {
    v.is_finite() && v.as_dvec3().length() >= MIN_DIRECTION_LENGTH && v.length_squared().is_finite()
}

pub(crate) fn is_colour(v: Vec3) -> bool {
    v.is_finite() && v.min_element() >= 0.0
}

pub(crate) fn is_rgba(v: Vec4) -> bool {
    v.is_finite() && v.min_element() >= 0.0 && v.w <= 1.0
}

pub(crate) fn is_size2(v: Vec2) -> bool {
    v.is_finite() && v.min_element() > 0.0
}

pub(crate) fn is_size3(v: Vec3) -> bool {
    v.is_finite() && v.min_element() > 0.0
}

/// A value as a scene file would write it: `0.5`, `(1, 0, 2)`.
pub(crate) trait Shown {
    /// The value as a scene file would write it.
    fn shown(&self) -> String;
}

/// A number as a message shows it: in decimal, except very small and very large magnitudes
/// in scientific notation (`1e-30`, not thirty zeros).
pub fn number(x: f32) -> String {
    let m = x.abs();
    if x.is_finite() && m != 0.0 && !(1e-4..1e9).contains(&m) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

impl Shown for f32 {
    fn shown(&self) -> String {
        number(*self)
    }
}

impl Shown for Vec2 {
    fn shown(&self) -> String {
        format!("({}, {})", number(self.x), number(self.y))
    }
}

impl Shown for Vec3 {
    fn shown(&self) -> String {
        format!("({}, {}, {})", number(self.x), number(self.y), number(self.z))
    }
}

impl Shown for Vec4 {
    fn shown(&self) -> String {
        format!(
            "({}, {}, {}, {})",
            number(self.x),
            number(self.y),
            number(self.z),
            number(self.w)
        )
    }
}

impl Shown for UVec3 {
    fn shown(&self) -> String {
        format!("({}, {}, {})", self.x, self.y, self.z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_far_from_one_are_shown_in_scientific_notation() {
        assert_eq!(number(89.99), "89.99");
        assert_eq!(number(0.0), "0");
        assert_eq!(number(1e-30), "1e-30");
        assert_eq!(number(-3e38), "-3e38");
        assert_eq!(number(f32::NAN), "NaN");
        assert_eq!(Vec3::new(0.0, -1e-30, 2.5).shown(), "(0, -1e-30, 2.5)");
    }
}
