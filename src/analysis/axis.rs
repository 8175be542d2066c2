//! A plot axis: a data range that starts and ends on a tick, with about six "nice" (1-2-5)
//! ticks, their labels, and where a value falls along it.

/// One axis: its range, which starts and ends on a tick, and the tick step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Axis {
    pub lo: f64,
    pub hi: f64,
    pub step: f64,
}

impl Axis {
    /// A range with about six 1-2-5 ticks around the finite `values`; it starts at 0 when
    /// the values are non-negative and 0 is no farther below them than their own span.
    pub fn fit(values: impl Iterator<Item = f64>) -> Self {
        let (mut lo, mut hi) = values
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
        if lo > hi {
            (lo, hi) = (0.0, 1.0);
        } else if lo == hi {
            let half = if lo == 0.0 { 0.5 } else { lo.abs() * 0.2 };
            (lo, hi) = (lo - half, hi + half);
        }
        let pad = (hi - lo) * 0.08;
        (lo, hi) = if lo >= 0.0 && lo <= hi - lo {
            (0.0, hi + pad)
        } else {
            (lo - pad, hi + pad)
        };
        // The 1-2-5 step nearest to a sixth of the range (thresholds at the geometric means).
        let raw = (hi - lo) / 6.0;
        let magnitude = 10f64.powf(raw.log10().floor());
        let n = raw / magnitude;
        let step = magnitude
            * if n < 1.41 {
                1.0
            } else if n < 3.16 {
                2.0
            } else if n < 7.07 {
                5.0
            } else {
                10.0
            };
        Self {
            lo: (lo / step).floor() * step,
            hi: (hi / step).ceil() * step,
            step,
        }
    }

    /// The tick values, from `lo` to `hi`.
    pub fn ticks(&self) -> Vec<f64> {
        let first = (self.lo / self.step - 1e-6).ceil() as i64;
        let last = (self.hi / self.step + 1e-6).floor() as i64;
        (first..=last).map(|k| k as f64 * self.step).collect()
    }

    /// `v` with as many decimals as the step needs.
    pub fn label(&self, v: f64) -> String {
        let decimals = (-(self.step.log10() + 1e-9).floor()).max(0.0) as usize;
        format!("{:.*}", decimals, if v == 0.0 { 0.0 } else { v })
    }

    /// Where `v` falls between `lo` (0) and `hi` (1).
    pub fn fraction(&self, v: f64) -> f32 {
        ((v - self.lo) / (self.hi - self.lo)) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_ticks_are_nice() {
        // [0.8, 3.4] starts at 0, pads to 3.61; a sixth is 0.6, nearest 1-2-5 step 0.5.
        let a = Axis::fit([0.8, 3.4].into_iter());
        assert_eq!((a.lo, a.hi, a.step), (0.0, 4.0, 0.5));
        assert_eq!(a.ticks().len(), 9);
        assert_eq!(a.label(1.5), "1.5");
        let a = Axis::fit([0.012, 0.081].into_iter());
        assert_eq!(a.step, 0.02);
        assert_eq!(a.label(0.04), "0.04");
        assert!(a.lo == 0.0 && a.hi >= 0.081);
        // Far from zero: does not start at zero.
        let a = Axis::fit([20.0, 23.0].into_iter());
        assert_eq!((a.lo, a.hi, a.step), (19.5, 23.5, 0.5));
        assert_eq!(a.label(20.0), "20.0");
        let a = Axis::fit([f64::NAN, 7.0].into_iter());
        assert!(a.lo <= 7.0 && a.hi >= 7.0 && a.hi > a.lo, "{a:?}");
        let a = Axis::fit(std::iter::empty());
        assert_eq!((a.lo, a.step), (0.0, 0.2));
        assert_eq!(
            Axis {
                lo: 0.0,
                hi: 100.0,
                step: 20.0
            }
            .label(40.0),
            "40"
        );
    }
}
