//! CPU mirror of the moment shadow tests (`shaders/shadows/moments.wgsl`): Chebyshev's upper
//! bound on the lit fraction from the first two moments of the occluders' depth, the variance
//! floor, and light-bleed reduction. Depth grows away from the light.

use glam::{Vec2, Vec3};

/// Smallest coverage the covered-moment bounds divide by (EVSM2's
/// [`evsm2_covered_visibility`](crate::math::evsm::evsm2_covered_visibility), VSM's); below it
/// the footprint counts as empty (lit).
pub const MIN_COVERAGE: f32 = 1.0e-4;

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

/// What one texel of a spot or point light's moments holds: `(o·z, o·z², o)` for the
/// normalised distance `z`, with `o` 1 where a caster was drawn and 0 in an empty texel. The
/// three filter linearly, so a filtered footprint keeps its occupied share.
pub fn covered_moments(depth: f32, occupied: bool) -> Vec3 {
    let o = if occupied { 1.0 } else { 0.0 };
    Vec3::new(o * depth, o * depth * depth, o)
}

/// VSM from filtered covered moments ([`covered_moments`]): the footprint's empty share is
/// lit, its occupied share gets Chebyshev's bound of the occupied texels' own moments (with
/// light-bleed reduction). Without coverage an empty texel stands for the farthest distance,
/// and a footprint reaching past a caster's edge over a receiver that casts nothing reads as
/// lit long before the caster's share falls to half.
pub fn vsm_covered_visibility(moments: Vec3, depth: f32, min_variance: f32, bleed: f32) -> f32 {
    let coverage = moments.z.clamp(0.0, 1.0);
    if coverage < MIN_COVERAGE {
        return 1.0;
    }
    let occupied = Vec2::new(moments.x, moments.y) / coverage;
    1.0 - coverage + coverage * moments_visibility(occupied, depth, min_variance, bleed)
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

    #[test]
    fn covered_moments_light_the_empty_share_of_a_footprint() {
        // Half a footprint over a caster 0.1 nearer the light, half empty (a receiver that
        // casts nothing): the receiver is half lit.
        let footprint = (covered_moments(0.3, true) + covered_moments(0.0, false)) * 0.5;
        let lit = vsm_covered_visibility(footprint, 0.4, FLOOR, 0.0);
        assert!((lit - 0.5).abs() < 1e-3, "half-covered footprint gives {lit}, not 0.5");
        // The same footprint without coverage (the empty texel as the farthest distance, 1)
        // is lit: its mean lies behind the receiver.
        let uncovered = moments_of(&[0.3, 1.0], &[1.0, 1.0]);
        assert_eq!(moments_visibility(uncovered, 0.4, FLOOR, 0.0), 1.0);
        // Fully covered it matches plain VSM; an empty footprint is lit.
        let full = covered_moments(0.3, true);
        let plain = moments_visibility(moments_of(&[0.3], &[1.0]), 0.4, FLOOR, 0.2);
        assert_eq!(vsm_covered_visibility(full, 0.4, FLOOR, 0.2), plain);
        assert_eq!(
            vsm_covered_visibility(covered_moments(0.0, false), 0.4, FLOOR, 0.2),
            1.0
        );
    }
}
