//! Temporal stability: how much the shadow at fixed world points changes as the camera moves.
//!
//! Each frame (one camera pose) holds the shadow factor at the same N world points. A point's
//! spread is the largest minus the smallest value over the frames; a perfectly stable
//! technique has spread 0 everywhere, and shimmering cascades show as spread at shadow edges.

use serde::Serialize;

use crate::analysis::metrics::percentile;

/// A point whose spread exceeds this counts as unstable.
pub const UNSTABLE_SPREAD: f64 = 0.05;

/// Spread statistics over the measured points; all 0 when none was measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Shimmer {
    /// Points measured: those without a NaN in any frame.
    pub points: u64,
    /// Mean spread (max − min over frames).
    pub mean_spread: f64,
    /// 95th percentile of the spread (nearest rank).
    pub p95_spread: f64,
    /// Largest spread.
    pub max_spread: f64,
    /// Fraction of the measured points whose spread exceeds [`UNSTABLE_SPREAD`].
    pub unstable_fraction: f64,
    /// Points skipped because some frame's value was NaN.
    pub skipped_nan: u64,
}

/// Spread statistics of `values`, one `Vec` per frame, each with the value at the same points.
///
/// No frames means no points; one frame gives spread 0 at every point.
///
/// # Panics
/// If the frames differ in length.
pub fn shimmer(values: &[Vec<f32>]) -> Shimmer {
    let Some(first) = values.first() else {
        return Shimmer::default();
    };
    let n = first.len();
    assert!(
        values.iter().all(|f| f.len() == n),
        "shimmer frames differ in point count"
    );
    let mut spreads = Vec::with_capacity(n);
    let mut skipped_nan = 0;
    for point in 0..n {
        let (mut lo, mut hi, mut nan) = (f32::INFINITY, f32::NEG_INFINITY, false);
        for frame in values {
            let v = frame[point];
            nan |= v.is_nan();
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if nan {
            skipped_nan += 1;
        } else {
            spreads.push(f64::from(hi) - f64::from(lo));
        }
    }
    let points = spreads.len() as u64;
    if points == 0 {
        return Shimmer {
            skipped_nan,
            ..Shimmer::default()
        };
    }
    let count = spreads.len() as f64;
    let unstable = spreads.iter().filter(|&&s| s > UNSTABLE_SPREAD).count();
    Shimmer {
        points,
        mean_spread: spreads.iter().sum::<f64>() / count,
        max_spread: spreads.iter().copied().fold(0.0, f64::max),
        unstable_fraction: unstable as f64 / count,
        p95_spread: percentile(&mut spreads, 95),
        skipped_nan,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-6
    }

    #[test]
    fn constant_frames_are_stable() {
        let frame = vec![0.0, 0.3, 1.0, 0.5];
        let s = shimmer(&[frame.clone(), frame.clone(), frame]);
        assert_eq!(
            s,
            Shimmer {
                points: 4,
                ..Shimmer::default()
            }
        );
    }

    #[test]
    fn varying_frames() {
        // Spreads per point: 0.5, 0.0, 0.02, 1.0.
        let frames = vec![
            vec![0.5, 0.2, 0.50, 0.0],
            vec![1.0, 0.2, 0.52, 1.0],
            vec![0.75, 0.2, 0.51, 0.5],
        ];
        let s = shimmer(&frames);
        assert_eq!((s.points, s.skipped_nan), (4, 0));
        assert!(close(s.mean_spread, (0.5 + 0.0 + 0.02 + 1.0) / 4.0), "{s:?}");
        assert!(close(s.max_spread, 1.0) && close(s.p95_spread, 1.0), "{s:?}");
        // 0.5 and 1.0 exceed 0.05; 0 and 0.02 do not.
        assert!(close(s.unstable_fraction, 0.5), "{s:?}");
    }

    #[test]
    fn nan_points_are_skipped_and_counted() {
        let frames = vec![
            vec![0.0, f32::NAN, 0.25],
            vec![0.1, 0.5, 0.25],
            vec![0.0, 0.5, f32::NAN],
        ];
        let s = shimmer(&frames);
        assert_eq!((s.points, s.skipped_nan), (1, 2));
        assert!(close(s.mean_spread, 0.1) && close(s.max_spread, 0.1), "{s:?}");
        assert!(close(s.unstable_fraction, 1.0), "{s:?}");
        let s = shimmer(&[vec![f32::NAN]]);
        assert_eq!(
            s,
            Shimmer {
                skipped_nan: 1,
                ..Shimmer::default()
            }
        );
    }

    #[test]
    fn no_frames_or_one_frame() {
        assert_eq!(shimmer(&[]), Shimmer::default());
        assert_eq!(
            shimmer(&[vec![0.2, 0.9]]),
            Shimmer {
                points: 2,
                ..Shimmer::default()
            }
        );
    }

    #[test]
    #[should_panic(expected = "differ")]
    fn ragged_frames_panic() {
        shimmer(&[vec![0.0, 1.0], vec![0.0]]);
    }
}
