//! CPU mirror of the moment shadow tests (`shaders/shadows/moments.wgsl`): Chebyshev's upper
//! bound on the lit fraction from the first two moments of the occluders' depth, the variance
//! floor, and light-bleed reduction. Depth grows away from the light.

use glam::Vec2;

/// The first two moments `(E[z], E[z²])` of `depths` with weights `weights` (normalised here):
/// what a filtered moment map holds over a footprint.
pub fn moments_of(depths: &[f32], weights: &[f32]) -> Vec2 {
    let total: f32 = weights.iter().sum();
    if total <= 0.0 {
        return Vec2::ZERO;
    }
    depths
        .iter()
        .zip(weights)
        .fold(Vec2::ZERO, |m, (&z, &w)| m + Vec2::new(z, z * z) * (w / total))
}

/// Chebyshev's one-sided bound on the lit fraction for a receiver at `depth`: 1 when it is no
/// farther than the mean occluder, else σ² / (σ² + (depth − μ)²) with σ² floored at
/// `min_variance`.
pub fn chebyshev_upper_bound(moments: Vec2, depth: f32, min_variance: f32) -> f32 {
    let mean = moments.x;
    if depth <= mean {
        return 1.0;
    }
    let variance = (moments.y - mean * mean).max(min_variance);
    let d = depth - mean;
    variance / (variance + d * d)
}

/// Clips the bound's low tail (where light bleeding lives) to 0 and stretches the rest over
/// `[0, 1]`; `amount` is clamped to `[0, 0.999]`.
pub fn reduce_light_bleeding(p_max: f32, amount: f32) -> f32 {
    let a = amount.clamp(0.0, 0.999);
    ((p_max - a) / (1.0 - a)).clamp(0.0, 1.0)
}

/// The visibility of a receiver at `depth` from filtered moments.
pub fn moments_visibility(moments: Vec2, depth: f32, min_variance: f32, bleed: f32) -> f32 {
    reduce_light_bleeding(chebyshev_upper_bound(moments, depth, min_variance), bleed)
}

#[cfg(test)]
mod tests {
    use super::*;

    const FLOOR: f32 = 1e-5;

    #[test]
    fn a_receiver_in_front_of_its_occluders_is_lit_and_one_behind_a_flat_occluder_is_dark() {
        let flat = moments_of(&[0.4], &[1.0]);
        assert_eq!(chebyshev_upper_bound(flat, 0.3, FLOOR), 1.0);
        assert_eq!(chebyshev_upper_bound(flat, 0.4, FLOOR), 1.0);
        assert!(chebyshev_upper_bound(flat, 0.5, FLOOR) < 0.01);
    }

    #[test]
    fn the_bound_falls_with_the_receivers_distance_behind_the_occluders() {
        let edge = moments_of(&[0.3, 0.6], &[0.5, 0.5]);
        let mut last = 1.0;
        for k in 1..20 {
            let p = chebyshev_upper_bound(edge, 0.45 + k as f32 * 0.05, FLOOR);
            assert!(p < last, "not falling at step {k}: {p} after {last}");
            last = p;
        }
    }

    #[test]
    fn bleed_reduction_darkens_the_umbra_under_two_stacked_occluders() {
        // Half the footprint sees an occluder at 0.2, half one at 0.7; the receiver at 0.8
        // is behind both, so it is in full shadow, but the variance of the two occluders
        // makes the bound leak light (the classic light-bleeding case).
        let stacked = moments_of(&[0.2, 0.7], &[0.5, 0.5]);
        let leaked = chebyshev_upper_bound(stacked, 0.8, FLOOR);
        assert!(leaked > 0.3, "the plain bound should bleed here: {leaked}");
        assert_eq!(moments_visibility(stacked, 0.8, FLOOR, 0.7), 0.0);
        // Without bleeding (a receiver just behind a single occluder's edge) the reduction
        // keeps a soft, non-zero value where the bound is high.
        assert!(reduce_light_bleeding(0.9, 0.3) > 0.8);
        assert_eq!(reduce_light_bleeding(1.0, 0.999), 1.0);
        assert_eq!(
            reduce_light_bleeding(0.5, -1.0),
            0.5,
            "a negative amount is no reduction"
        );
    }

    #[test]
    fn the_variance_floor_keeps_a_flat_footprint_finite() {
        let flat = moments_of(&[0.5; 4], &[1.0; 4]);
        let p = chebyshev_upper_bound(flat, 0.5 + 1e-4, FLOOR);
        assert!(p.is_finite() && p > 0.0 && p < 1.0, "{p}");
        assert_eq!(moments_of(&[0.5], &[0.0]), Vec2::ZERO);
    }
}
