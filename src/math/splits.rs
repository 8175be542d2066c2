//! Cascade split distances by the practical split scheme (PSSM): a blend of logarithmic and
//! linear distributions of view depth, pulled in towards the logarithmic one for views wider
//! than 120°.

/// The most cascades a directional light can have.
pub const MAX_CASCADES: usize = 4;

/// Smallest near distance [`pssm_splits`] accepts; smaller, zero, negative or NaN values are
/// raised to it.
pub const MIN_SPLIT_NEAR: f32 = 1.0e-6;

/// Largest near distance [`pssm_splits`] accepts (a quarter of `f32::MAX`, so that a far
/// distance above it still exists).
pub const MAX_SPLIT_NEAR: f32 = f32::MAX / 4.0;

/// Smallest ratio `far / near` [`pssm_splits`] produces; a far distance closer than this is
/// pushed out to `near * MIN_SPLIT_RATIO`.
pub const MIN_SPLIT_RATIO: f32 = 1.001;

/// The view depths bounding each cascade by the practical split scheme.
///
/// `C_i = λ·n·(f/n)^(i/N) + (1 − λ)·(n + (f − n)·i/N)` for `i = 0..=N`, with `n = near`,
/// `f = max_distance`, `N = count`, `λ = lambda`. Element `0` is `near`, element `count` is
/// `max_distance`; cascade `i` covers view depths `[C_i, C_{i+1}]`. Entries after `count`
/// repeat `max_distance`.
///
/// Bad inputs are sanitised rather than rejected, so the result is always finite and the
/// first `count + 1` entries strictly increase:
/// - `count` is clamped into `1..=MAX_CASCADES`;
/// - `near` is clamped into [`MIN_SPLIT_NEAR`]`..=`[`MAX_SPLIT_NEAR`] (NaN becomes the
///   minimum);
/// - `max_distance` is raised to at least `near * MIN_SPLIT_RATIO` (NaN counts as too small,
///   `+∞` becomes `f32::MAX`);
/// - `lambda` is clamped into `0..=1` (NaN becomes 0.5).
pub fn pssm_splits(near: f32, max_distance: f32, count: usize, lambda: f32) -> [f32; MAX_CASCADES + 1] {
    let count = count.clamp(1, MAX_CASCADES);
    let near = if near.is_nan() {
        MIN_SPLIT_NEAR
    } else {
        near.clamp(MIN_SPLIT_NEAR, MAX_SPLIT_NEAR)
    };
    let far = if max_distance.is_nan() {
        near
    } else {
        max_distance.min(f32::MAX)
    };
    let far = far.max(near * MIN_SPLIT_RATIO);
    let lambda = if lambda.is_nan() { 0.5 } else { lambda.clamp(0.0, 1.0) };

    // NOTE: evaluated in f64: (f/n)^(i/N) with f/n up to ~1e44 and the linear term with
    // f − n would lose digits in f32; the blend is then rounded once.
    let (n, f, l) = (f64::from(near), f64::from(far), f64::from(lambda));
    let mut out = [far; MAX_CASCADES + 1];
    out[0] = near;
    for (i, slot) in out.iter_mut().enumerate().take(count).skip(1) {
        let t = i as f64 / count as f64;
        let log = n * (f / n).powf(t);
        let lin = n + (f - n) * t;
        *slot = (l * log + (1.0 - l) * lin) as f32;
    }
    // NOTE: both terms strictly increase in exact arithmetic, but rounding to f32 could tie
    // two neighbours when they are within an ulp; nudge upwards to keep them strictly
    // increasing (the ratio guard above leaves room below `far`).
    for i in 1..count {
        if out[i] <= out[i - 1] {
            out[i] = out[i - 1].next_up();
        }
    }
    out
}

/// Tangent of the widest half-angle (on either axis) whose splits [`wide_view_splits`] leaves
/// unchanged: a view up to 120° across.
///
/// NOTE: a slice's lateral extent, and so every texel of its cascade, grows with the tangent
/// of the half field of view. Up to 120° (a 16:9 view of 90° vertical is 121° across) the
/// PSSM splits are used as given; wider views pull them in (see [`wide_view_splits`]).
pub const WIDE_VIEW_TAN: f64 = 1.732_050_807_568_877_2;

/// The splits of a view whose widest half-angle has tangent `tan_half`: [`pssm_splits`] with
/// each inner split divided by `tan_half / WIDE_VIEW_TAN` (when above 1), so that its slice is
/// no wider than in a 120° view, but never nearer than the logarithmic split (`λ = 1`, which
/// keeps the shadow-map texel to screen-pixel ratio even across the cascades).
///
/// Takes the same arguments as [`pssm_splits`], sanitised the same way; a NaN or infinite
/// `tan_half` counts as a 120° view. The first `count + 1` entries still strictly increase,
/// the first is `near` and the last `max_distance`.
pub fn wide_view_splits(
    near: f32,
    max_distance: f32,
    count: usize,
    lambda: f32,
    tan_half: f64,
) -> [f32; MAX_CASCADES + 1] {
    let mut out = pssm_splits(near, max_distance, count, lambda);
    let widen = if tan_half.is_finite() {
        (tan_half / WIDE_VIEW_TAN).max(1.0)
    } else {
        1.0
    };
    if widen > 1.0 {
        let log = pssm_splits(near, max_distance, count, 1.0);
        let count = count.clamp(1, MAX_CASCADES);
        // NOTE: the maximum of two strictly increasing sequences strictly increases, and both
        // share the first and last entries.
        for i in 1..count {
            out[i] = ((f64::from(out[i]) / widen) as f32).max(log[i]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_and_logarithmic_extremes() {
        let lin = pssm_splits(1.0, 101.0, 4, 0.0);
        assert_eq!(lin, [1.0, 26.0, 51.0, 76.0, 101.0]);
        let log = pssm_splits(1.0, 10_000.0, 4, 1.0);
        for (got, want) in log.iter().zip([1.0, 10.0, 100.0, 1000.0, 10_000.0]) {
            assert!((got - want).abs() <= want * 1e-6, "{log:?}");
        }
    }

    #[test]
    fn wide_views_pull_the_splits_in_down_to_the_logarithmic_ones() {
        let pssm = pssm_splits(0.1, 120.0, 4, 0.6);
        assert_eq!(wide_view_splits(0.1, 120.0, 4, 0.6, WIDE_VIEW_TAN), pssm);
        assert_eq!(wide_view_splits(0.1, 120.0, 4, 0.6, f64::NAN), pssm);
        let log = pssm_splits(0.1, 120.0, 4, 1.0);
        let wide = wide_view_splits(0.1, 120.0, 4, 0.6, 2.0 * WIDE_VIEW_TAN);
        for i in 1..4 {
            let want = (pssm[i] / 2.0).max(log[i]);
            assert!((wide[i] - want).abs() <= 1e-6 * want, "{wide:?}");
        }
        assert_eq!((wide[0], wide[4]), (0.1, 120.0));
        assert_eq!(wide_view_splits(0.1, 120.0, 4, 0.6, 1.0e30), log);
    }

    #[test]
    fn unused_entries_repeat_far() {
        let s = pssm_splits(0.5, 200.0, 2, 0.6);
        assert_eq!(s[0], 0.5);
        assert_eq!(&s[2..], &[200.0, 200.0, 200.0]);
        assert!(s[0] < s[1] && s[1] < s[2]);
    }

    #[test]
    fn bad_inputs_are_sanitised() {
        for (n, f, c, l) in [
            (0.0, 100.0, 4, 0.5),
            (-3.0, 100.0, 4, 0.5),
            (f32::NAN, f32::NAN, 0, f32::NAN),
            (10.0, 5.0, 9, 2.0),
            (10.0, 10.0, 4, -1.0),
            (1.0, f32::INFINITY, 4, 0.5),
            (f32::MAX, f32::MAX, 4, 0.5),
            (1e-30, 1e30, 4, 1.0),
        ] {
            let s = pssm_splits(n, f, c, l);
            let count = c.clamp(1, MAX_CASCADES);
            assert!(s.iter().all(|v| v.is_finite() && *v > 0.0), "{s:?}");
            for w in s[..=count].windows(2) {
                assert!(w[0] < w[1], "{n} {f} {c} {l}: {s:?}");
            }
        }
    }
}
