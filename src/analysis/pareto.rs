//! The Pareto front of (cost, error) points, lower being better in both.

/// For each `(cost, error)` point, whether it is on the Pareto front: no other point is at
/// most as large in both coordinates and strictly smaller in one.
///
/// Equal points do not dominate each other, so ties are all on the front or all off it. A
/// point with a NaN coordinate is never on the front and dominates nothing.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    // Every comparison with NaN is false, so a NaN point dominates nothing.
    points
        .iter()
        .map(|p| !p.0.is_nan() && !p.1.is_nan() && !points.iter().any(|q| dominates(*q, *p)))
        .collect()
}

/// Whether `a` dominates `b`: `a ≤ b` in both coordinates and `a < b` in one.
fn dominates(a: (f64, f64), b: (f64, f64)) -> bool {
    a.0 <= b.0 && a.1 <= b.1 && (a.0 < b.0 || a.1 < b.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_set() {
        let points = [(1.0, 0.5), (2.0, 0.2), (3.0, 0.3), (0.5, 0.9), (2.5, 0.1), (4.0, 0.1)];
        // (3.0, 0.3) is beaten by (2.0, 0.2); (4.0, 0.1) by (2.5, 0.1) with equal error.
        assert_eq!(pareto_front(&points), [true, true, false, true, true, false]);
    }

    #[test]
    fn ties() {
        // Identical points are both on the front; an equal-cost higher-error point is not.
        let points = [(1.0, 0.5), (1.0, 0.5), (1.0, 0.6), (2.0, 0.5)];
        assert_eq!(pareto_front(&points), [true, true, false, false]);
        assert_eq!(pareto_front(&[(1.0, 1.0)]), [true]);
        assert!(pareto_front(&[]).is_empty());
    }

    #[test]
    fn nan_is_never_on_the_front_and_dominates_nothing() {
        let points = [(f64::NAN, 0.0), (1.0, f64::NAN), (2.0, 0.5), (3.0, 0.4)];
        assert_eq!(pareto_front(&points), [false, false, true, true]);
        assert_eq!(pareto_front(&[(f64::NAN, f64::NAN)]), [false]);
    }

    #[test]
    fn infinite_cost_loses_to_finite() {
        let points = [(f64::INFINITY, 0.1), (1.0, 0.1), (f64::INFINITY, 0.0)];
        assert_eq!(pareto_front(&points), [false, true, true]);
    }
}
