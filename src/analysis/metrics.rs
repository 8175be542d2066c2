//! Per-pixel error of a shadow technique against a ray-traced reference.
//!
//! Both inputs are shadow factors (1 = fully lit, 0 = fully shadowed) of the same pixels. The
//! reference classifies each pixel as fully lit, fully shadowed or penumbra ([`Thresholds`]);
//! the metrics are the mean, 95th percentile and maximum absolute error, the mean error inside
//! the penumbra, the rates of shadow acne and light leaks, and the signed bias.

use serde::Serialize;

/// Where the reference counts as fully lit or fully shadowed, and what counts as acne or leak.
///
/// Defaults: fully lit reference ≥ 0.98, fully shadowed ≤ 0.02, penumbra strictly between;
/// acne = reference fully lit and technique < 0.9; leak = reference fully shadowed and
/// technique > 0.1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thresholds {
    /// A reference value at or above this is fully lit (default 0.98).
    pub lit: f32,
    /// A reference value at or below this is fully shadowed (default 0.02).
    pub shadowed: f32,
    /// A fully lit reference pixel whose technique value is below this is acne (default 0.9).
    pub acne_below: f32,
    /// A fully shadowed reference pixel whose technique value is above this is a leak (default 0.1).
    pub leak_above: f32,
}

impl Default for Thresholds {
    fn default() -> Self {
        Self {
            lit: 0.98,
            shadowed: 0.02,
            acne_below: 0.9,
            leak_above: 0.1,
        }
    }
}

/// Error of a technique against the reference over a set of pixels.
///
/// Every field is 0 when no pixel was measured; `penumbra_mae` is 0 without penumbra pixels,
/// `acne_rate` without fully lit and `leak_rate` without fully shadowed reference pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ErrorMetrics {
    /// Pixels measured: included, and neither value NaN.
    pub pixels: u64,
    /// Mean absolute error.
    pub mae: f64,
    /// Measured pixels whose reference is strictly between fully shadowed and fully lit.
    pub penumbra_pixels: u64,
    /// Mean absolute error over the penumbra pixels.
    pub penumbra_mae: f64,
    /// 95th percentile of the absolute error (nearest rank: a measured value, not interpolated).
    pub p95: f64,
    /// Largest absolute error.
    pub max: f64,
    /// Measured pixels the reference sees fully lit.
    pub lit_pixels: u64,
    /// Measured pixels the reference sees fully shadowed.
    pub shadowed_pixels: u64,
    /// Acne pixels divided by fully lit reference pixels.
    pub acne_rate: f64,
    /// Leak pixels divided by fully shadowed reference pixels.
    pub leak_rate: f64,
    /// Mean signed error, technique − reference: negative is too dark, positive too bright.
    pub bias: f64,
    /// Included pixels skipped because the technique or the reference value was NaN.
    pub skipped_nan: u64,
}

/// Compares `technique` with `reference` over the pixels `i` for which `include(i)` holds.
///
/// # Panics
/// If the two slices differ in length.
pub fn error_metrics(
    technique: &[f32],
    reference: &[f32],
    include: impl Fn(usize) -> bool,
    t: &Thresholds,
) -> ErrorMetrics {
    assert_eq!(
        technique.len(),
        reference.len(),
        "technique and reference differ in pixel count"
    );
    let mut acc = Accumulator::default();
    for (i, (&tech, &reference)) in technique.iter().zip(reference).enumerate() {
        if include(i) {
            acc.add(tech, reference, t);
        }
    }
    acc.finish()
}

/// [`error_metrics`] split by cascade: `cascade[i]` is the cascade (0..=3) that shaded pixel
/// `i`; any other value (255 = none) leaves the pixel out of every entry.
///
/// # Panics
/// If the three slices differ in length.
pub fn per_cascade(
    technique: &[f32],
    reference: &[f32],
    cascade: &[u8],
    include: impl Fn(usize) -> bool,
    t: &Thresholds,
) -> [ErrorMetrics; 4] {
    assert_eq!(
        technique.len(),
        reference.len(),
        "technique and reference differ in pixel count"
    );
    assert_eq!(
        technique.len(),
        cascade.len(),
        "cascade indices and pixels differ in count"
    );
    let mut acc: [Accumulator; 4] = Default::default();
    for (i, ((&tech, &reference), &c)) in technique.iter().zip(reference).zip(cascade).enumerate() {
        if let Some(acc) = acc.get_mut(usize::from(c))
            && include(i)
        {
            acc.add(tech, reference, t);
        }
    }
    acc.map(Accumulator::finish)
}

/// The `percent`-th percentile of `values` by nearest rank (the smallest value that at least
/// `percent` % of the values do not exceed); 0 for no values. Reorders `values`.
pub(crate) fn percentile(values: &mut [f64], percent: usize) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let rank = (values.len() * percent.min(100)).div_ceil(100).max(1);
    let (_, value, _) = values.select_nth_unstable_by(rank - 1, f64::total_cmp);
    *value
}

/// Running sums of one set of pixels.
#[derive(Default)]
struct Accumulator {
    abs_errors: Vec<f64>,
    sum_abs: f64,
    sum_signed: f64,
    max: f64,
    penumbra: u64,
    penumbra_sum: f64,
    lit: u64,
    acne: u64,
    shadowed: u64,
    leaks: u64,
    skipped_nan: u64,
}

impl Accumulator {
    fn add(&mut self, technique: f32, reference: f32, t: &Thresholds) {
        if technique.is_nan() || reference.is_nan() {
            self.skipped_nan += 1;
            return;
        }
        let signed = f64::from(technique) - f64::from(reference);
        let abs = signed.abs();
        self.abs_errors.push(abs);
        self.sum_abs += abs;
        self.sum_signed += signed;
        self.max = self.max.max(abs);
        if reference >= t.lit {
            self.lit += 1;
            self.acne += u64::from(technique < t.acne_below);
        } else if reference <= t.shadowed {
            self.shadowed += 1;
            self.leaks += u64::from(technique > t.leak_above);
        } else {
            self.penumbra += 1;
            self.penumbra_sum += abs;
        }
    }

    fn finish(mut self) -> ErrorMetrics {
        let pixels = self.abs_errors.len() as u64;
        ErrorMetrics {
            pixels,
            mae: ratio(self.sum_abs, pixels),
            penumbra_pixels: self.penumbra,
            penumbra_mae: ratio(self.penumbra_sum, self.penumbra),
            p95: percentile(&mut self.abs_errors, 95),
            max: self.max,
            lit_pixels: self.lit,
            shadowed_pixels: self.shadowed,
            acne_rate: ratio(self.acne as f64, self.lit),
            leak_rate: ratio(self.leaks as f64, self.shadowed),
            bias: ratio(self.sum_signed, pixels),
            skipped_nan: self.skipped_nan,
        }
    }
}

/// `sum / count`, or 0 when `count` is 0.
fn ratio(sum: f64, count: u64) -> f64 {
    if count == 0 { 0.0 } else { sum / count as f64 }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-6
    }

    #[test]
    fn thresholds_default_to_the_documented_values() {
        let t = Thresholds::default();
        assert_eq!((t.lit, t.shadowed, t.acne_below, t.leak_above), (0.98, 0.02, 0.9, 0.1));
    }

    #[test]
    fn hand_made_arrays() {
        // Reference classes: lit, lit, shadowed, shadowed, penumbra, penumbra.
        let reference = [1.0, 0.99, 0.0, 0.01, 0.5, 0.25];
        let technique = [1.0, 0.5, 0.2, 0.0, 0.75, 0.25];
        // Signed errors: 0, -0.49, 0.2, -0.01, 0.25, 0.
        let m = error_metrics(&technique, &reference, |_| true, &Thresholds::default());
        assert_eq!(m.pixels, 6);
        assert_eq!(m.skipped_nan, 0);
        assert!(close(m.mae, (0.49 + 0.2 + 0.01 + 0.25) / 6.0), "{m:?}");
        assert!(close(m.bias, (-0.49 + 0.2 - 0.01 + 0.25) / 6.0), "{m:?}");
        assert_eq!(m.penumbra_pixels, 2);
        assert!(close(m.penumbra_mae, 0.25 / 2.0), "{m:?}");
        // ceil(0.95 · 6) = 6th smallest of |e| = the largest.
        assert!(close(m.p95, 0.49) && close(m.max, 0.49), "{m:?}");
        // Acne: 0.5 < 0.9 of the two lit pixels; leak: 0.2 > 0.1 of the two shadowed ones.
        assert!(close(m.acne_rate, 0.5) && close(m.leak_rate, 0.5), "{m:?}");
    }

    #[test]
    fn p95_is_the_nearest_rank() {
        // 100 errors 0.01, 0.02, ..., 1.00: the 95th smallest is 0.95.
        let reference = vec![0.0f32; 100];
        let technique: Vec<f32> = (1..=100).map(|i| i as f32 / 100.0).collect();
        let m = error_metrics(&technique, &reference, |_| true, &Thresholds::default());
        assert!(close(m.p95, 0.95), "{m:?}");
        assert!(close(m.max, 1.0), "{m:?}");
        assert!(close(m.mae, 0.505), "{m:?}");
        // All reference pixels are shadowed; leaks are the 90 values above 0.1.
        assert!(close(m.leak_rate, 0.9), "{m:?}");
        assert_eq!(m.acne_rate, 0.0);
        assert_eq!(percentile(&mut [], 95), 0.0);
        assert_eq!(percentile(&mut [3.0, 1.0, 2.0], 50), 2.0);
        assert_eq!(percentile(&mut [3.0, 1.0, 2.0], 0), 1.0);
    }

    #[test]
    fn include_selects_pixels() {
        let reference = [1.0, 1.0, 1.0, 1.0];
        let technique = [1.0, 0.0, 1.0, 0.0];
        let m = error_metrics(&technique, &reference, |i| i % 2 == 0, &Thresholds::default());
        assert_eq!(m.pixels, 2);
        assert_eq!((m.mae, m.acne_rate, m.max), (0.0, 0.0, 0.0));
        let m = error_metrics(&technique, &reference, |i| i % 2 == 1, &Thresholds::default());
        assert_eq!((m.pixels, m.mae, m.acne_rate, m.bias), (2, 1.0, 1.0, -1.0));
    }

    #[test]
    fn nan_pixels_are_skipped_and_counted() {
        let reference = [0.5, f32::NAN, 0.5, 0.5];
        let technique = [0.6, 0.5, f32::NAN, 0.5];
        let m = error_metrics(&technique, &reference, |_| true, &Thresholds::default());
        assert_eq!((m.pixels, m.skipped_nan, m.penumbra_pixels), (2, 2, 2));
        assert!(close(m.mae, 0.05) && close(m.max, 0.1), "{m:?}");
        assert!(m.p95.is_finite() && m.bias.is_finite());
        // Excluded NaN pixels are not counted.
        let m = error_metrics(&technique, &reference, |i| i != 1, &Thresholds::default());
        assert_eq!(m.skipped_nan, 1);
    }

    #[test]
    fn nothing_measured_is_all_zero() {
        let m = error_metrics(&[], &[], |_| true, &Thresholds::default());
        assert_eq!(m, ErrorMetrics::default());
        let m = error_metrics(&[f32::NAN], &[0.5], |_| true, &Thresholds::default());
        assert_eq!(
            m,
            ErrorMetrics {
                skipped_nan: 1,
                ..ErrorMetrics::default()
            }
        );
    }

    #[test]
    fn per_cascade_splits_by_index() {
        let reference = [0.5, 0.5, 0.5, 0.5, 0.5, 0.5];
        let technique = [0.6, 0.7, 0.5, 0.9, 0.0, 0.2];
        let cascade = [0, 0, 1, 3, 255, 7];
        let t = Thresholds::default();
        let c = per_cascade(&technique, &reference, &cascade, |_| true, &t);
        assert_eq!(c.map(|m| m.pixels), [2, 1, 0, 1]);
        assert!(close(c[0].penumbra_mae, 0.15), "{:?}", c[0]);
        assert_eq!(c[1].mae, 0.0);
        assert_eq!(c[2], ErrorMetrics::default());
        assert!(close(c[3].mae, 0.4), "{:?}", c[3]);
        // Each cascade equals error_metrics over its pixels.
        let direct = error_metrics(&technique, &reference, |i| cascade[i] == 0, &t);
        assert_eq!(c[0], direct);
        let c = per_cascade(&technique, &reference, &cascade, |i| i != 0, &t);
        assert_eq!(c[0].pixels, 1);
        assert!(close(c[0].mae, 0.2));
    }

    #[test]
    #[should_panic(expected = "differ")]
    fn mismatched_lengths_panic() {
        error_metrics(&[0.0], &[0.0, 1.0], |_| true, &Thresholds::default());
    }
}
