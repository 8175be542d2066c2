//! Keyframe tracks as glTF animations store them: key times and values, sampled with step,
//! linear (spherical for rotations) or cubic-spline (Hermite, with in and out tangents per
//! key) interpolation, held at the first and last key outside their range.

use glam::{Quat, Vec3};

/// How a track's values between two keys are found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// The earlier key's value.
    Step,
    /// Linear (vectors) or spherical linear (rotations).
    Linear,
    /// Cubic Hermite spline: each key holds an in-tangent, a value and an out-tangent.
    CubicSpline,
}

/// A value a track can hold.
pub trait Keyed: Copy {
    /// Linear interpolation from `a` to `b` by `t` in `[0, 1]`.
    fn interpolate(a: Self, b: Self, t: f32) -> Self;
    /// `a·x + b·y`, for the spline's basis.
    fn combine(x: Self, a: f32, y: Self, b: f32) -> Self;
    /// The value as a track gives it out (a unit rotation).
    fn finish(self) -> Self {
        self
    }
}

impl Keyed for Vec3 {
    fn interpolate(a: Self, b: Self, t: f32) -> Self {
        a.lerp(b, t)
    }
    fn combine(x: Self, a: f32, y: Self, b: f32) -> Self {
        x * a + y * b
    }
}

impl Keyed for Quat {
    fn interpolate(a: Self, b: Self, t: f32) -> Self {
        a.slerp(b, t)
    }
    fn combine(x: Self, a: f32, y: Self, b: f32) -> Self {
        x * a + y * b
    }
    fn finish(self) -> Self {
        unit_rotation(self)
    }
}

/// `q` scaled to unit length; the identity where it has no length (or none that is finite).
pub fn unit_rotation(q: Quat) -> Quat {
    let length = q.length();
    if length.is_finite() && length > 1e-12 {
        q / length
    } else {
        Quat::IDENTITY
    }
}

/// One animated property: strictly increasing key times (seconds) and the values at them
/// (three per key with [`Interpolation::CubicSpline`]: in-tangent, value, out-tangent).
#[derive(Clone, Debug, PartialEq)]
pub struct Track<T> {
    /// Key times, strictly increasing, at least one.
    pub times: Vec<f32>,
    /// Values: one per key, or three with a cubic spline.
    pub values: Vec<T>,
    /// How values between keys are found.
    pub interpolation: Interpolation,
}

impl<T: Keyed> Track<T> {
    /// The value of key `k` (the middle of its triplet for a cubic spline).
    fn key(&self, k: usize) -> T {
        match self.interpolation {
            Interpolation::CubicSpline => self.values[3 * k + 1],
            _ => self.values[k],
        }
    }

    /// The last key's time (0 for a track without keys).
    pub fn duration(&self) -> f32 {
        self.times.last().copied().unwrap_or(0.0)
    }

    /// The value at `time` seconds: the first key's before it, the last key's after.
    ///
    /// # Panics
    /// If the track has no key, or fewer values than its keys need.
    pub fn sample(&self, time: f32) -> T {
        let n = self.times.len();
        assert!(n > 0, "a track has at least one key");
        let next = self.times.partition_point(|&t| t <= time);
        if next == 0 {
            return self.key(0).finish();
        }
        if next == n {
            return self.key(n - 1).finish();
        }
        let (k, t0, t1) = (next - 1, self.times[next - 1], self.times[next]);
        let span = t1 - t0;
        let s = ((time - t0) / span).clamp(0.0, 1.0);
        match self.interpolation {
            Interpolation::Step => self.key(k),
            Interpolation::Linear => T::interpolate(self.key(k), self.key(k + 1), s),
            Interpolation::CubicSpline => {
                let (s2, s3) = (s * s, s * s * s);
                let out_tangent = self.values[3 * k + 2];
                let in_tangent = self.values[3 * (k + 1)];
                let start = T::combine(
                    self.key(k),
                    2.0 * s3 - 3.0 * s2 + 1.0,
                    out_tangent,
                    span * (s3 - 2.0 * s2 + s),
                );
                let end = T::combine(self.key(k + 1), -2.0 * s3 + 3.0 * s2, in_tangent, span * (s3 - s2));
                T::combine(start, 1.0, end, 1.0)
            }
        }
        .finish()
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use super::{Interpolation, Track};

    fn track(interpolation: Interpolation, values: Vec<Vec3>) -> Track<Vec3> {
        Track {
            times: vec![1.0, 2.0, 4.0],
            values,
            interpolation,
        }
    }

    #[test]
    fn keys_are_held_outside_the_range_and_hit_at_their_times() {
        let keys = vec![Vec3::X, Vec3::Y, Vec3::Z];
        for interpolation in [Interpolation::Step, Interpolation::Linear] {
            let t = track(interpolation, keys.clone());
            assert_eq!(t.sample(-5.0), Vec3::X);
            assert_eq!(t.sample(1.0), Vec3::X);
            assert_eq!(t.sample(2.0), Vec3::Y);
            assert_eq!(t.sample(4.0), Vec3::Z);
            assert_eq!(t.sample(100.0), Vec3::Z);
        }
        assert_eq!(track(Interpolation::Step, keys.clone()).sample(3.9), Vec3::Y);
        assert_eq!(track(Interpolation::Linear, keys).sample(3.0), Vec3::new(0.0, 0.5, 0.5));
    }

    #[test]
    fn a_cubic_spline_passes_its_keys_and_follows_its_tangents() {
        // Zero tangents: a smoothstep between keys, through each key.
        let zero = Vec3::ZERO;
        let values = vec![zero, Vec3::X, zero, zero, Vec3::Y, zero, zero, Vec3::Z, zero];
        let t = track(Interpolation::CubicSpline, values);
        assert_eq!(t.sample(1.0), Vec3::X);
        assert_eq!(t.sample(2.0), Vec3::Y);
        assert_eq!(t.sample(4.0), Vec3::Z);
        assert!((t.sample(1.5) - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6);
        // Tangents matching a straight line reproduce it: value 0 → 1 over 1 s, slope 1.
        let line = Track {
            times: vec![0.0, 1.0],
            values: vec![Vec3::X, zero, Vec3::X, Vec3::X, Vec3::X, Vec3::X],
            interpolation: Interpolation::CubicSpline,
        };
        for s in [0.1, 0.25, 0.5, 0.9] {
            assert!(
                (line.sample(s) - Vec3::X * s).length() < 1e-6,
                "{s}: {}",
                line.sample(s)
            );
        }
    }

    #[test]
    fn rotations_stay_unit_and_take_the_short_way() {
        let a = Quat::from_rotation_y(0.0);
        let b = Quat::from_rotation_y(1.5);
        let t = Track {
            times: vec![0.0, 1.0],
            values: vec![a, -b],
            interpolation: Interpolation::Linear,
        };
        for s in [0.0, 0.3, 0.5, 1.0] {
            let q = t.sample(s);
            assert!((q.length() - 1.0).abs() < 1e-5);
            let angle = q.angle_between(Quat::from_rotation_y(1.5 * s));
            assert!(angle < 1e-3, "{s}: {angle} rad off");
        }
        let spline = Track {
            times: vec![0.0, 1.0],
            values: vec![
                Quat::IDENTITY * 0.0,
                a,
                Quat::IDENTITY * 0.0,
                Quat::IDENTITY * 0.0,
                b,
                Quat::IDENTITY * 0.0,
            ],
            interpolation: Interpolation::CubicSpline,
        };
        assert!((spline.sample(0.5).length() - 1.0).abs() < 1e-5);
    }
}
