//! CPU mirror of the exponential variance shadow maps' math (`shaders/shadows/moments.wgsl`):
//! the exponential warps of a depth that grows away from the light (0 at the light's side of
//! the view, 1 at its far side), the exponent each moment format can hold, and the EVSM2 and
//! EVSM4 tests built on [`chebyshev_upper_bound`].
//!
//! The warp `w = exp(c·d)` pushes a receiver behind its occluders far away from them in warped
//! space, so the bound collapses and the light bleeding of plain VSM mostly goes; its strength
//! `c` is bounded by the format, since the second moment reaches `exp(2c)`.

use glam::{Vec2, Vec4};

use crate::math::moments::{MIN_COVERAGE, chebyshev_upper_bound, reduce_light_bleeding};

/// The storage of warped moments.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MomentPrecision {
    /// 16-bit floats (largest finite value 65504): half the memory, a weak warp.
    Fp16,
    /// 32-bit floats: a strong warp; filtering them needs `FLOAT32_FILTERABLE`.
    Fp32,
}

/// Largest finite 16-bit float.
pub const FP16_MAX: f32 = 65504.0;

impl MomentPrecision {
    /// The largest value the format holds.
    pub fn max_value(self) -> f32 {
        match self {
            MomentPrecision::Fp16 => FP16_MAX,
            MomentPrecision::Fp32 => f32::MAX,
        }
    }

    /// The warp exponent used with this format: the largest `c` whose second moment at the
    /// farthest depth, `exp(2c)`, stays at most half the format's largest value (so filtering
    /// and blurring, which only average, never overflow). 16 bits: 5.2 (the seed's ≈ 5.54
    /// leaves no margin: exp(11.08) = 65 000); 32 bits: capped at 42 (the seed's 40–42).
    pub fn exponent(self) -> f32 {
        let limit = 0.5 * (0.5 * self.max_value()).ln();
        limit.min(42.0)
    }

    /// EVSM4's negative warp exponent with this format. Its moments stay within ±1, so range
    /// is no limit; precision is: 16 bits keep `exp(−2c)` a normal number (c ≤ 4.8), and 32
    /// bits use 10 (a larger one flattens `−exp(−c·d)` to 0 over the far half of a cascade).
    pub fn negative_exponent(self) -> f32 {
        match self {
            MomentPrecision::Fp16 => 4.8,
            MomentPrecision::Fp32 => 10.0,
        }
    }
}

/// A cascade's warp exponent for a warp of `max_exponent` over the deepest cascade's depth
/// range `deepest`: `max_exponent · range / deepest` (see [`cascade_exponents`]).
pub fn cascade_exponent(range: f32, deepest: f32, max_exponent: f32) -> f32 {
    if deepest > 0.0 && range.is_finite() && range > 0.0 {
        max_exponent * (range / deepest).min(1.0)
    } else {
        max_exponent
    }
}

/// Each cascade's warp exponent, so the warp is the same in world units in every cascade: a
/// cascade's depth `d` (0..1) spans `depth_ranges[i]` metres, so `exp(c_i·d)` is
/// `exp(k·z)` in metres `z` with `c_i = k·depth_ranges[i]`. `k` is the largest the format
/// allows for the deepest cascade (`max_exponent` there); shallower cascades get smaller
/// exponents. Non-finite or non-positive ranges get `max_exponent`.
pub fn cascade_exponents(depth_ranges: &[f32], max_exponent: f32) -> Vec<f32> {
    let deepest = depth_ranges
        .iter()
        .copied()
        .filter(|r| r.is_finite() && *r > 0.0)
        .fold(0.0, f32::max);
    depth_ranges
        .iter()
        .map(|&r| cascade_exponent(r, deepest, max_exponent))
        .collect()
}

/// The blur radius in texels of a cascade whose texel is `texel_world_size` metres wide, for
/// a blur of `world_radius` metres (the same softness in every cascade), at most
/// `max_texels`; 0 for a non-finite or non-positive texel.
pub fn cascade_blur_texels(world_radius: f32, texel_world_size: f32, max_texels: f32) -> f32 {
    if !(texel_world_size.is_finite() && texel_world_size > 0.0 && world_radius.is_finite()) {
        return 0.0;
    }
    (world_radius.max(0.0) / texel_world_size).min(max_texels)
}

/// The positive warp of a depth `d` (0..1, growing away from the light): `exp(c·d)`.
pub fn positive_warp(depth: f32, c: f32) -> f32 {
    (c * depth).exp()
}

/// The negative warp of a depth: `−exp(−c·d)` (EVSM4's second pair).
pub fn negative_warp(depth: f32, c: f32) -> f32 {
    -(-c * depth).exp()
}

/// The two moments EVSM2 stores for one texel at `depth`: `(w, w²)` of the positive warp.
pub fn evsm2_moments(depth: f32, c: f32) -> Vec2 {
    let w = positive_warp(depth, c);
    Vec2::new(w, w * w)
}

/// The four moments EVSM4 stores: the positive warp's `(w, w²)`, then the negative warp's.
pub fn evsm4_moments(depth: f32, c_positive: f32, c_negative: f32) -> Vec4 {
    let p = positive_warp(depth, c_positive);
    let n = negative_warp(depth, c_negative);
    Vec4::new(p, p * p, n, n * n)
}

/// The moments EVSM2 stores for one texel at `depth`, with its coverage (`occupied`: a caster
/// was drawn there; an empty texel holds nothing): `(o·w, o·w², o)` for `o` 1 or 0, so that
/// filtering averages the occupied texels' moments and counts their share of the footprint.
pub fn evsm2_covered_moments(depth: f32, c: f32, occupied: bool) -> Vec4 {
    let o = if occupied { 1.0 } else { 0.0 };
    let w = positive_warp(depth, c);
    Vec4::new(o * w, o * w * w, o, 0.0)
}

/// EVSM2 from filtered covered moments ([`evsm2_covered_moments`]): the footprint's empty
/// share is lit, its occupied share gets the bound of the occupied texels' own moments (with
/// light-bleed reduction). Without coverage, an empty texel would stand for the farthest
/// depth, whose warp outweighs any occluder's, and light the rim of every umbra over a
/// receiver that casts nothing.
pub fn evsm2_covered_visibility(moments: Vec4, depth: f32, c: f32, min_variance: f32, bleed: f32) -> f32 {
    let coverage = moments.z.clamp(0.0, 1.0);
    if coverage < MIN_COVERAGE {
        return 1.0;
    }
    let occupied = Vec2::new(moments.x, moments.y) / coverage;
    let lit = evsm2_visibility(occupied, depth, c, min_variance, bleed);
    1.0 - coverage + coverage * lit
}

/// Chebyshev's bound in one warped space: the receiver warped by the same function, the
/// variance floor `min_variance` (in depth units squared) scaled by the warp's derivative
/// `slope` at the receiver, so it means the same depth spread at every distance.
fn warped_bound(moments: Vec2, warped: f32, slope: f32, min_variance: f32) -> f32 {
    chebyshev_upper_bound(moments, warped, min_variance * slope * slope)
}

/// EVSM2: the visibility of a receiver at `depth` from filtered positive-warp moments, with
/// the variance floor and light-bleed reduction.
pub fn evsm2_visibility(moments: Vec2, depth: f32, c: f32, min_variance: f32, bleed: f32) -> f32 {
    let w = positive_warp(depth, c);
    reduce_light_bleeding(warped_bound(moments, w, c * w, min_variance), bleed)
}

/// EVSM4: the smaller of the positive and negative warps' bounds (each catches the bleeding
/// the other lets through), then light-bleed reduction.
pub fn evsm4_visibility(
    moments: Vec4,
    depth: f32,
    c_positive: f32,
    c_negative: f32,
    min_variance: f32,
    bleed: f32,
) -> f32 {
    let p = positive_warp(depth, c_positive);
    let n = negative_warp(depth, c_negative);
    let positive = warped_bound(moments.truncate().truncate(), p, c_positive * p, min_variance);
    // NOTE: −exp(−c·d) grows with d, as the bound expects; its derivative is c·exp(−c·d).
    let negative = warped_bound(Vec2::new(moments.z, moments.w), n, -c_negative * n, min_variance);
    reduce_light_bleeding(positive.min(negative), bleed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::moments::moments_of;

    /// Filtered moments of `depths` (equal weights) under a warp.
    fn filtered(depths: &[f32], warp: impl Fn(f32) -> f32) -> Vec2 {
        let warped: Vec<f32> = depths.iter().map(|&d| warp(d)).collect();
        moments_of(&warped, &vec![1.0; depths.len()])
    }

    #[test]
    fn no_moment_overflows_its_format_at_the_chosen_exponent() {
        for precision in [MomentPrecision::Fp16, MomentPrecision::Fp32] {
            let c = precision.exponent();
            let m = evsm2_moments(1.0, c);
            assert!(
                m.y.is_finite() && m.y <= 0.5 * precision.max_value(),
                "{precision:?}: {m}"
            );
            // And not far below: the warp is as strong as the format allows.
            assert!(
                m.y >= 0.25 * precision.max_value().min(f32::MAX / 4.0) || c == 42.0,
                "{precision:?}"
            );
            let n = evsm4_moments(1.0, c, c);
            assert!(n.is_finite());
        }
        assert!((MomentPrecision::Fp16.exponent() - 5.2).abs() < 0.05);
        assert_eq!(MomentPrecision::Fp32.exponent(), 42.0);
        // EVSM4's negative pair: exp(−2c) stays a normal 16-bit float.
        let n16 = evsm4_moments(1.0, 5.2, MomentPrecision::Fp16.negative_exponent());
        assert!(n16.w >= 6.1e-5, "{n16}");
    }

    #[test]
    fn cascade_exponents_keep_the_warp_constant_in_metres_and_within_the_format() {
        let ranges = [40.0, 90.0, 250.0, 600.0];
        let c = cascade_exponents(&ranges, 42.0);
        assert_eq!(c[3], 42.0, "the deepest cascade uses the whole exponent");
        for (ci, r) in c.iter().zip(ranges) {
            assert!(*ci <= 42.0);
            // The same world distance warps alike: c_i / range_i is one constant.
            assert!((ci / r - 42.0 / 600.0).abs() < 1e-6);
            // And the second moment of any depth stays within the format.
            assert!(evsm2_moments(1.0, *ci).y <= f32::MAX);
        }
        assert_eq!(cascade_exponents(&[f32::NAN, 10.0], 5.2), [5.2, 5.2]);
        assert_eq!(cascade_exponents(&[], 5.2), Vec::<f32>::new());
    }

    #[test]
    fn cascade_blur_radii_keep_the_softness_constant_in_metres() {
        // A 5 cm blur: 4 texels of 1.25 cm, 1 texel of 5 cm, capped at 8.
        assert_eq!(cascade_blur_texels(0.05, 0.0125, 8.0), 4.0);
        assert_eq!(cascade_blur_texels(0.05, 0.05, 8.0), 1.0);
        assert_eq!(cascade_blur_texels(0.05, 0.001, 8.0), 8.0);
        assert_eq!(cascade_blur_texels(0.05, 0.0, 8.0), 0.0);
        assert_eq!(cascade_blur_texels(f32::NAN, 0.01, 8.0), 0.0);
    }

    #[test]
    fn a_receiver_in_front_is_lit_and_one_behind_a_flat_occluder_is_dark() {
        let c = MomentPrecision::Fp32.exponent();
        let flat = evsm2_moments(0.4, c);
        assert_eq!(evsm2_visibility(flat, 0.39, c, 1e-6, 0.0), 1.0);
        assert!(evsm2_visibility(flat, 0.45, c, 1e-6, 0.0) < 0.01);
    }

    #[test]
    fn the_warp_darkens_the_stacked_umbra_that_plain_vsm_bleeds_through() {
        // Half the footprint sees an occluder at 0.2, half one at 0.7; the receiver at 0.8.
        let depths = [0.2, 0.7];
        let plain = chebyshev_upper_bound(filtered(&depths, |d| d), 0.8, 1e-5);
        assert!(plain > 0.3, "plain VSM bleeds here: {plain}");
        for precision in [MomentPrecision::Fp16, MomentPrecision::Fp32] {
            let c = precision.exponent();
            let warped = evsm2_visibility(filtered(&depths, |d| positive_warp(d, c)), 0.8, c, 1e-5, 0.0);
            assert!(warped < plain, "{precision:?}: {warped} against {plain}");
        }
        let c = MomentPrecision::Fp32.exponent();
        let strong = evsm2_visibility(filtered(&depths, |d| positive_warp(d, c)), 0.8, c, 1e-5, 0.0);
        assert!(strong < 0.05, "a strong warp keeps the umbra dark: {strong}");
    }

    #[test]
    fn coverage_lights_the_empty_share_of_a_footprint_and_bounds_the_rest() {
        let c = MomentPrecision::Fp32.exponent();
        // A quarter of the footprint holds an occluder at 0.3; the rest is empty. A receiver
        // at 0.6 is lit by the empty three quarters alone.
        let texels = [(0.3, true), (1.0, false), (1.0, false), (1.0, false)];
        let m = texels
            .iter()
            .map(|&(d, o)| evsm2_covered_moments(d, c, o))
            .fold(Vec4::ZERO, |a, b| a + b)
            / 4.0;
        let v = evsm2_covered_visibility(m, 0.6, c, 1e-6, 0.0);
        assert!((v - 0.75).abs() < 1e-3, "{v}");
        // Without coverage the empty texels' far depth outweighs the occluder: lit.
        let plain = filtered(&[0.3, 1.0, 1.0, 1.0], |d| positive_warp(d, c));
        assert_eq!(evsm2_visibility(plain, 0.6, c, 1e-6, 0.0), 1.0);
        // Fully covered, it is plain EVSM2; fully empty, lit.
        let full = evsm2_covered_moments(0.4, c, true);
        let moments = Vec2::new(full.x, full.y);
        assert_eq!(
            evsm2_covered_visibility(full, 0.45, c, 1e-6, 0.0),
            evsm2_visibility(moments, 0.45, c, 1e-6, 0.0)
        );
        assert_eq!(
            evsm2_covered_visibility(evsm2_covered_moments(0.2, c, false), 0.9, c, 1e-6, 0.0),
            1.0
        );
    }

    #[test]
    fn evsm4_takes_the_smaller_of_the_two_warped_bounds() {
        let c = 20.0;
        for (depths, receiver) in [(&[0.2, 0.7][..], 0.8), (&[0.5, 0.52][..], 0.6), (&[0.1][..], 0.05)] {
            let p = filtered(depths, |d| positive_warp(d, c));
            let n = filtered(depths, |d| negative_warp(d, c));
            let both = evsm4_visibility(Vec4::new(p.x, p.y, n.x, n.y), receiver, c, c, 1e-5, 0.0);
            let positive = evsm2_visibility(p, receiver, c, 1e-5, 0.0);
            // The negative warp's bound, written out: its floor scales by c·exp(−c·d).
            let slope = c * (-c * receiver).exp();
            let negative = chebyshev_upper_bound(n, negative_warp(receiver, c), 1e-5 * slope * slope);
            assert!((both - positive.min(negative)).abs() < 1e-6, "{depths:?} at {receiver}");
            assert!((0.0..=1.0).contains(&both));
        }
        // Lit in front of a single occluder, under both warps.
        let m = evsm4_moments(0.5, c, c);
        assert_eq!(evsm4_visibility(m, 0.45, c, c, 1e-5, 0.0), 1.0);
    }
}
