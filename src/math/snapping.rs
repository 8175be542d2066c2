//! Shadow-map stabilisation: box extents quantised on a fixed logarithmic grid and box
//! origins snapped to whole texels, plus the directed f64 → f32 roundings used to publish
//! conservative bounds.

/// Number of quantisation steps per doubling of a cascade's extent: an extent is rounded up
/// to the next `2^(i / 8)`, wasting at most 9 % of the shadow map.
pub const EXTENT_STEPS_PER_OCTAVE: f64 = 8.0;

/// `w` rounded up onto the fixed grid `2^(i / EXTENT_STEPS_PER_OCTAVE)`, `i` an integer.
///
/// The grid does not depend on anything but `w`, so two extents that differ by rounding
/// noise almost always quantise to the bit-identical value, and a box whose extent does not
/// change keeps its projection scale exactly. Non-positive or NaN inputs are first raised to
/// `f64::MIN_POSITIVE`, so the result is always positive and finite for finite input.
pub fn quantize_extent_up(w: f64) -> f64 {
    let w = w.max(f64::MIN_POSITIVE);
    let mut step = (w.log2() * EXTENT_STEPS_PER_OCTAVE).ceil();
    let mut q = (step / EXTENT_STEPS_PER_OCTAVE).exp2();
    // NOTE: log2/exp2 round, so a value just above a grid point can come back just below
    // it; step once more so the result always covers `w`.
    while q < w {
        step += 1.0;
        q = (step / EXTENT_STEPS_PER_OCTAVE).exp2();
    }
    q
}

/// One lateral axis of a cascade box after stabilisation: the box spans
/// `[first_texel · texel, first_texel · texel + width]`, `texel = width / resolution`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelSnap {
    /// Index of the texel grid line the box starts on (an integer-valued float).
    pub first_texel: f64,
    /// Box extent along the axis (a value on the quantisation grid).
    pub width: f64,
    /// World size of one texel, `width / resolution`.
    pub texel: f64,
}

impl TexelSnap {
    /// Lower bound of the box.
    pub fn min(&self) -> f64 {
        self.first_texel * self.texel
    }

    /// Upper bound of the box.
    pub fn max(&self) -> f64 {
        self.min() + self.width
    }
}

/// Stabilises the interval `[lo, lo + spread]` along one light-space axis for a shadow map
/// of `resolution` texels (at least 2).
///
/// The width is `quantize_extent_up(max(spread · res / (res − 1), min_width))` (the extra
/// texel pays for moving the start down onto the grid) and the start is `lo` rounded down to
/// a multiple of `width / res`, so the result covers the interval. `spread` should be
/// computed without the camera position, so that a pure translation leaves the width, and
/// with it the texel grid, bit-identical.
pub fn snap_interval(lo: f64, spread: f64, resolution: f64, min_width: f64) -> TexelSnap {
    let res = resolution.max(2.0);
    let width = quantize_extent_up((spread * res / (res - 1.0)).max(min_width));
    let texel = width / res;
    TexelSnap {
        first_texel: (lo / texel).floor(),
        width,
        texel,
    }
}

/// `x` as the largest f32 not above it (saturating at `±f32::MAX`).
pub(crate) fn f32_down(x: f64) -> f32 {
    let y = x as f32;
    let y = if f64::from(y) > x { y.next_down() } else { y };
    y.clamp(-f32::MAX, f32::MAX)
}

/// `x` as the smallest f32 not below it (saturating at `±f32::MAX`).
pub(crate) fn f32_up(x: f64) -> f32 {
    let y = x as f32;
    let y = if f64::from(y) < x { y.next_up() } else { y };
    y.clamp(-f32::MAX, f32::MAX)
}

/// `x` rounded to the nearest f32, clamped to `±f32::MAX` so the result is finite.
pub(crate) fn f32_sat(x: f64) -> f32 {
    let m = f64::from(f32::MAX);
    x.clamp(-m, m) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantization_is_upward_and_on_the_grid() {
        for w in [1e-9, 0.3, 1.0, 1.0001, 7.5, 1234.5, 3e20] {
            let q = quantize_extent_up(w);
            assert!(q >= w && q < w * 2f64.powf(1.0 / 8.0) * (1.0 + 1e-12), "{w} -> {q}");
            let steps = q.log2() * 8.0;
            assert!((steps - steps.round()).abs() < 1e-9, "{w} -> {q}");
        }
        assert_eq!(quantize_extent_up(1.0), 1.0);
        assert_eq!(quantize_extent_up(2.0), 2.0);
        assert!(quantize_extent_up(0.0) > 0.0);
        assert!(quantize_extent_up(f64::NAN) > 0.0);
    }

    #[test]
    fn nearby_extents_share_a_grid_value() {
        let a = quantize_extent_up(10.3);
        let b = quantize_extent_up(10.3 + 1e-9);
        assert_eq!(a.to_bits(), b.to_bits());
    }

    #[test]
    fn snapped_interval_covers_and_starts_on_the_grid() {
        for (lo, spread, res) in [
            (-3.7, 12.0, 1024.0),
            (1e6 + 0.123, 5.5, 2048.0),
            (-1e6, 0.001, 4096.0),
            (0.0, 1.0, 2.0),
        ] {
            let s = snap_interval(lo, spread, res, 0.0);
            assert!(s.min() <= lo, "{s:?}");
            assert!(s.max() >= lo + spread, "{s:?}");
            assert!(s.min() > lo - s.texel * 1.000001, "{s:?}");
            assert_eq!(s.first_texel, s.first_texel.round());
            assert_eq!(s.texel, s.width / res);
        }
    }

    #[test]
    fn translation_moves_the_start_by_whole_texels() {
        let a = snap_interval(10.0, 7.0, 1024.0, 0.0);
        let b = snap_interval(10.0 + 0.3 * a.texel, 7.0, 1024.0, 0.0);
        let c = snap_interval(10.0 + 5.7 * a.texel, 7.0, 1024.0, 0.0);
        assert_eq!(a.width, b.width);
        let db = b.first_texel - a.first_texel;
        let dc = c.first_texel - a.first_texel;
        assert!(db == 0.0 || db == 1.0);
        assert!(dc == 5.0 || dc == 6.0);
    }

    #[test]
    fn directed_rounding() {
        let x = 0.1_f64;
        assert!(f64::from(f32_down(x)) <= x && f64::from(f32_up(x)) >= x);
        assert!(f32_down(x) < f32_up(x));
        assert_eq!(f32_down(0.5), 0.5);
        assert_eq!(f32_up(0.5), 0.5);
        assert_eq!(f32_up(1e300), f32::MAX);
        assert_eq!(f32_down(-1e300), -f32::MAX);
        assert_eq!(f32_sat(1e39), f32::MAX);
    }
}
