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
    /// Texels per cell of the grid the start lies on (`first_texel` is a multiple of it).
    pub cell: f64,
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
/// of `resolution` texels (at least 2), its start on a grid of cells of a power-of-two
/// number of texels.
///
/// The width is `quantize_extent_up(max(spread · res / (res − min_cell), min_width))` (the
/// extra `min_cell` texels pay for moving the start down onto the grid; `min_cell` is raised
/// to a power of two and clamped into `1..=resolution / 4`) and a cell is the largest power of
/// two of whole texels that the width leaves over the spread (at least `min_cell`, at most a
/// quarter of the map): the width is rounded up anyway, and the slack that leaves lets the
/// box hold still while `lo` moves within a cell, at no cost in texels. The start is `lo`
/// rounded down to a whole cell, so the result covers the interval; with a cell of `2^k`
/// texels, the map's mip level `k` keeps its texels' world positions as the box moves.
/// `spread` should be computed without the camera position, so that a pure translation leaves
/// the width, the cell and the texel grid bit-identical.
pub fn snap_interval(lo: f64, spread: f64, resolution: f64, min_width: f64, min_cell: f64) -> TexelSnap {
    let res = resolution.max(2.0);
    let most = pow2_floor((res / 4.0).max(1.0));
    let min_cell = pow2_ceil(min_cell.max(1.0)).min(most);
    let width = quantize_extent_up((spread * res / (res - min_cell)).max(min_width));
    let texel = width / res;
    // NOTE: shrunk by a part in a billion so rounding never makes a cell the slack misses.
    let slack = (width - spread.max(0.0)) / texel * (1.0 - 1e-9);
    let cell = if slack.is_finite() && slack >= 1.0 {
        pow2_floor(slack).clamp(min_cell, most)
    } else {
        min_cell
    };
    TexelSnap {
        first_texel: (lo / (texel * cell)).floor() * cell,
        width,
        texel,
        cell,
    }
}

/// The largest power of two not above `x` (`x` at least 1 and finite).
fn pow2_floor(x: f64) -> f64 {
    let mut p = x.log2().floor().exp2();
    // NOTE: log2 rounds; step back or on so the result is exact.
    while p > x {
        p *= 0.5;
    }
    while p * 2.0 <= x {
        p *= 2.0;
    }
    p
}

/// The smallest power of two not below `x` (`x` at least 1 and finite).
fn pow2_ceil(x: f64) -> f64 {
    let p = pow2_floor(x);
    if p < x { p * 2.0 } else { p }
}

/// `[lo, hi]` widened to whole multiples of `step` (unchanged where `step` is not positive).
pub fn snap_outwards(lo: f64, hi: f64, step: f64) -> (f64, f64) {
    if step > 0.0 && step.is_finite() {
        ((lo / step).floor() * step, (hi / step).ceil() * step)
    } else {
        (lo, hi)
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
            let s = snap_interval(lo, spread, res, 0.0, 1.0);
            assert!(s.min() <= lo, "{s:?}");
            assert!(s.max() >= lo + spread, "{s:?}");
            assert!(s.min() > lo - s.cell * s.texel * 1.000001, "{s:?}");
            assert_eq!(s.first_texel, s.first_texel.round());
            assert_eq!(s.first_texel % s.cell, 0.0, "{s:?}");
            // The cell is a power of two of the texels the rounded width leaves spare.
            assert!(s.cell >= 1.0 && s.cell * s.texel <= s.width - spread, "{s:?}");
            assert_eq!(s.cell, s.cell.log2().round().exp2(), "{s:?}");
            assert_eq!(s.texel, s.width / res);
        }
    }

    #[test]
    fn translation_moves_the_start_by_whole_texels() {
        let a = snap_interval(10.0, 7.0, 1024.0, 0.0, 1.0);
        let b = snap_interval(10.0 + 0.3 * a.texel, 7.0, 1024.0, 0.0, 1.0);
        let c = snap_interval(10.0 + 5.7 * a.texel, 7.0, 1024.0, 0.0, 1.0);
        assert_eq!(a.width, b.width);
        let db = b.first_texel - a.first_texel;
        let dc = c.first_texel - a.first_texel;
        assert_eq!((a.cell, b.cell, c.cell), (a.cell, a.cell, a.cell));
        assert_eq!(db % a.cell, 0.0);
        assert_eq!(dc % a.cell, 0.0);
        assert!(db.abs() <= a.cell && dc.abs() <= 6.0 + a.cell, "{db} {dc} {a:?}");
    }

    #[test]
    fn a_coarse_grid_covers_and_holds_while_the_start_stays_in_its_cell() {
        let (spread, res, min_cell) = (7.0, 1024.0, 64.0);
        let a = snap_interval(10.0, spread, res, 0.0, min_cell);
        assert!(a.cell >= min_cell && a.first_texel % a.cell == 0.0, "{a:?}");
        assert!(a.width >= spread * res / (res - min_cell), "{a:?}");
        // Every start in the cell gives the same box, which covers it.
        let step = a.cell * a.texel;
        let cell_start = a.min();
        for k in 0..32 {
            let lo = cell_start + step * (f64::from(k) / 32.0);
            let b = snap_interval(lo, spread, res, 0.0, min_cell);
            assert_eq!(b, a, "{lo}");
            assert!(b.min() <= lo && b.max() >= lo + spread, "{lo}: {b:?}");
        }
        // The next cell moves the box by one cell.
        let c = snap_interval(cell_start + step * 1.01, spread, res, 0.0, min_cell);
        assert_eq!(c.first_texel - a.first_texel, a.cell);
        // A cell past a quarter of the map is cut to a quarter; one not a power of two is
        // raised to one.
        let d = snap_interval(10.0, spread, 16.0, 0.0, 100.0);
        assert_eq!(d.cell, 4.0);
        assert_eq!(snap_interval(10.0, spread, 1024.0, 0.0, 100.0).cell, 128.0);
        assert!(d.min() <= 10.0 && d.max() >= 17.0, "{d:?}");
    }

    #[test]
    fn the_slack_of_the_rounded_width_makes_the_cell() {
        // 7 · 1024 / 1023 rounds up to 2^(23/8) = 7.34: 46.9 texels of slack, cells of 32.
        let a = snap_interval(10.0, 7.0, 1024.0, 0.0, 1.0);
        assert_eq!(a.width, quantize_extent_up(7.0 * 1024.0 / 1023.0));
        assert_eq!(a.cell, 32.0, "{a:?}");
        // A spread just under a grid value leaves one texel.
        let w = quantize_extent_up(5.0);
        let b = snap_interval(0.3, w * 1023.0 / 1024.0, 1024.0, 0.0, 1.0);
        assert_eq!((b.width, b.cell), (w, 1.0), "{b:?}");
    }

    #[test]
    fn powers_of_two() {
        for (x, lo, hi) in [
            (1.0, 1.0, 1.0),
            (3.0, 2.0, 4.0),
            (64.0, 64.0, 64.0),
            (100.5, 64.0, 128.0),
        ] {
            assert_eq!((pow2_floor(x), pow2_ceil(x)), (lo, hi), "{x}");
        }
    }

    #[test]
    fn outward_snapping() {
        assert_eq!(snap_outwards(-0.5, 2.5, 2.0), (-2.0, 4.0));
        assert_eq!(snap_outwards(2.0, 4.0, 2.0), (2.0, 4.0));
        assert_eq!(snap_outwards(-0.5, 2.5, 0.0), (-0.5, 2.5));
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
