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

impl Shown for f32 {
    fn shown(&self) -> String {
        format!("{self}")
    }
}

impl Shown for Vec2 {
    fn shown(&self) -> String {
        format!("({}, {})", self.x, self.y)
    }
}

impl Shown for Vec3 {
    fn shown(&self) -> String {
        format!("({}, {}, {})", self.x, self.y, self.z)
    }
}

impl Shown for Vec4 {
    fn shown(&self) -> String {
        format!("({}, {}, {}, {})", self.x, self.y, self.z, self.w)
    }
}

impl Shown for UVec3 {
    fn shown(&self) -> String {
        format!("({}, {}, {})", self.x, self.y, self.z)
    }
}
