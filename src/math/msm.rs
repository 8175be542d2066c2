//! CPU mirror of moment shadow mapping (`shaders/shadows/msm.wgsl`; Peters & Klein 2015,
//! "Moment Shadow Mapping"): the four moments (z, z², z³, z⁴) of a depth, the paper's
//! optimised quantisation that makes them fit 16-bit channels, and the Hamburger 4MSM bound
//! (the paper's Algorithm 2) on the lit fraction of a receiver from filtered moments. Depth
//! grows away from the light in `[0, 1]`. f32 throughout, like the GPU.

use glam::{Mat4, Vec4};

/// The moment bias for moments stored in 16-bit channels with [`quantize`]: the paper's (and
/// MJP's) 3·10⁻⁵, made for `Rgba16Unorm` (steps of 1.5·10⁻⁵). Below it, a receiver exactly at
/// a lone occluder's depth is no longer reliably lit. `Rgba16Float` rounds far coarser near 1
/// (steps of 4.9·10⁻⁴), which a bias cannot undo: lit stays lit, but the shadow behind an
/// occluder darkens over ~0.05 of the depth range instead of ~0.02 (see the tests).
pub const MSM_BIAS_16: f32 = 3e-5;

/// The moment bias for raw moments stored and filtered as 32-bit floats, 3·10⁻⁶: about the
/// least that keeps f32 rounding from showing. Over random mixtures of 1–4 depths (receivers
/// 0.01 or more from each), this function in f32 strays from an f64 evaluation by more than
/// 0.05 in 6 of 2·10⁵ look-ups (at most 0.08), against 57 at 10⁻⁶ (up to 0.2). Moments passed
/// through [`quantize`] in f32 lose more (its round trip errs by up to 4.4·10⁻⁶) and want
/// 10⁻⁵ for the same. The visibility 0.005 behind a lone occluder is 0.03 (0.23 with
/// [`MSM_BIAS_16`]).
pub const MSM_BIAS_32: f32 = 3e-6;

/// Below this the variance `b₂ − b₁²` is taken as a single depth at the mean.
const MIN_VARIANCE: f32 = 1e-10;
/// Floor on the third Cholesky pivot. Raising it is the same as raising the fourth moment, so
/// floored moments stay valid; it covers depths only at 0 and 1 (whose biased moments have a
/// singular Hankel matrix) and the rounding of 16-bit storage.
const MIN_PIVOT: f32 = 3e-8;
/// Floor on the quadratic's leading coefficient, relative to the others: a zero there (the
/// receiver on a node of the two-depth reconstruction) puts a root at infinity.
const MIN_LEADING: f32 = 1e-6;

/// The quantisation matrix's columns (column `i` weighs moment `i`); the paper's values.
const QUANTIZE: [[f32; 4]; 4] = [
    [-2.0722466, 13.794886, 0.105877705, 9.792406],
    [32.237038, -59.4684, -1.9077467, -33.76521],
    [-68.571075, 82.03597, 9.349655, 47.94561],
    [39.370327, -35.364902, -6.654349, -23.972805],
];
/// The inverse of [`QUANTIZE`], columns likewise (weights of stored channel `i`).
const DEQUANTIZE: [[f32; 4]; 4] = [
    [0.22277442, 0.15496792, 0.1451989, 0.16312744],
    [0.07719728, 0.13946295, 0.21202022, 0.25914323],
    [0.7926987, 0.7963416, 0.7258694, 0.65390927],
    [0.031941757, -0.17228232, -0.27580148, -0.33761317],
];
/// Added to the first quantised channel so every stored value lies in `[0, 1]`.
const QUANTIZE_OFFSET: f32 = 0.035955884;

/// The four moments `(z, z², z³, z⁴)` of a depth `z` in `[0, 1]`.
pub fn msm_moments(depth: f32) -> Vec4 {
    let square = depth * depth;
    Vec4::new(depth, square, square * depth, square * square)
}

/// The paper's optimised quantisation: stored = Q·moments + (0.035955884801, 0, 0, 0) with
/// Q's rows (−2.07224649, 32.23703778, −68.571074599, 39.3703274134), (13.7948857237,
/// −59.4683975703, 82.0359750338, −35.364903257), (0.105877704, −1.9077466311, 9.3496555107,
/// −6.6543490743), (9.7924062118, −33.7652110555, 47.9456096605, −23.9728048165). The moments
/// of depths in `[0, 1]` are nearly collinear; Q spreads them over the whole of `[0, 1]` in
/// every channel, so 16-bit rounding no longer swamps their differences (the Hankel matrix's
/// pivots) and 64 bits a texel suffice.
pub fn quantize(moments: Vec4) -> Vec4 {
    Mat4::from_cols_array_2d(&QUANTIZE) * moments + Vec4::new(QUANTIZE_OFFSET, 0.0, 0.0, 0.0)
}

/// The inverse of [`quantize`]: the moments back from the stored (filtered) values.
pub fn dequantize(stored: Vec4) -> Vec4 {
    Mat4::from_cols_array_2d(&DEQUANTIZE) * (stored - Vec4::new(QUANTIZE_OFFSET, 0.0, 0.0, 0.0))
}

/// The lit fraction (1 lit, 0 shadowed) of a receiver at `depth` from filtered, dequantised
/// moments: the Hamburger 4MSM bound (Algorithm 2 of the paper). The moments are first mixed
/// with (0.5, 0.5, 0.5, 0.5) by `moment_bias` ([`MSM_BIAS_16`] or [`MSM_BIAS_32`]), the moments
/// of half the footprint at 0 and half at 1, which keeps their Hankel matrix invertible.
/// Degenerate moments (one depth, or depths only at 0 and 1) give the share of the footprint
/// not in front of the receiver. Never NaN for inputs within ±10⁶ (tested); larger ones can
/// overflow f32.
pub fn hamburger_visibility(moments: Vec4, depth: f32, moment_bias: f32) -> f32 {
    let b = moments.lerp(Vec4::splat(0.5), moment_bias);
    let z0 = depth;
    if b.y - b.x * b.x <= MIN_VARIANCE {
        return if z0 <= b.x { 1.0 } else { 0.0 };
    }
    let (z2, z3) = nodes(b, z0);
    // The shadow intensity: the bound's weight on the nodes in front of the receiver.
    let shadow = if z0 <= z2 {
        0.0
    } else if z0 <= z3 {
        (z0 * z3 - b.x * (z0 + z3) + b.y) / ((z3 - z2) * (z0 - z2)).max(1e-30)
    } else {
        1.0 - (z2 * z3 - b.x * (z2 + z3) + b.y) / ((z0 - z2) * (z0 - z3)).max(1e-30)
    };
    (1.0 - shadow).clamp(0.0, 1.0)
}

/// The two nodes z₂ ≤ z₃ that, with the receiver's depth z₀, carry the Hamburger bound's
/// distribution for biased moments `b` (whose variance is above [`MIN_VARIANCE`]).
fn nodes(b: Vec4, z0: f32) -> (f32, f32) {
    // Cholesky decomposition B = L·D·Lᵀ of the Hankel matrix B = [[1, b₁, b₂], [b₁, b₂, b₃],
    // [b₂, b₃, b₄]]: L's lower entries b₁, b₂, l32 and D's pivots 1, d22, d33.
    let d22 = b.y - b.x * b.x;
    let l32_d22 = b.z - b.x * b.y;
    let l32 = l32_d22 / d22;
    let d33 = (b.w - b.y * b.y - l32 * l32_d22).max(MIN_PIVOT);
    // Solve B·c = (1, z₀, z₀²): forward substitution, the pivots, backward substitution.
    let y1 = z0 - b.x;
    let y2 = z0 * z0 - b.y - l32 * y1;
    let c3 = y2 / d33;
    let c2 = y1 / d22 - l32 * c3;
    let c1 = 1.0 - b.x * c2 - b.y * c3;
    // The roots of c₃·z² + c₂·z + c₁.
    let lead = c3.abs().max(MIN_LEADING * c1.abs().max(c2.abs())).max(1e-30);
    let c3 = if c3 < 0.0 { -lead } else { lead };
    let p = c2 / c3;
    let q = c1 / c3;
    let r = (0.25 * p * p - q).max(0.0).sqrt();
    (-0.5 * p - r, -0.5 * p + r)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn filtered(parts: &[(f32, f32)]) -> Vec4 {
        parts.iter().map(|&(depth, weight)| msm_moments(depth) * weight).sum()
    }

    /// `x` rounded to the nearest f16 (ties to even), as `Rgba16Float` stores it.
    fn round_f16(x: f32) -> f32 {
        if x.abs() < 6.1035156e-5 {
            return (x * 16_777_216.0).round() / 16_777_216.0; // f16 subnormals: steps of 2⁻²⁴
        }
        let bits = x.to_bits();
        f32::from_bits((bits + 0xfff + ((bits >> 13) & 1)) & !0x1fff)
    }

    /// `x` rounded as `Rgba16Unorm` stores it.
    fn round_unorm16(x: f32) -> f32 {
        (x.clamp(0.0, 1.0) * 65535.0).round() / 65535.0
    }

    /// Moments of `parts` as read back from 16-bit storage rounded by `round`.
    fn stored_16(parts: &[(f32, f32)], round: fn(f32) -> f32) -> Vec4 {
        dequantize(quantize(filtered(parts)).map(round))
    }

    #[test]
    fn dequantize_inverts_quantize_and_quantized_moments_fill_the_unit_range() {
        for k in 0..=1000 {
            let m = msm_moments(k as f32 / 1000.0);
            let q = quantize(m);
            // Measured in f32: worst round-trip error 4.4·10⁻⁶, values within [0, 1 + 5·10⁻⁷].
            assert!((dequantize(q) - m).abs().max_element() < 1e-5, "{m} -> {q}");
            assert!(q.min_element() > -1e-6 && q.max_element() < 1.0 + 1e-6, "{m} -> {q}");
        }
        let any = Vec4::new(0.3, -2.0, 7.5, 0.01);
        assert!((quantize(dequantize(any)) - any).abs().max_element() < 1e-4);
    }

    #[test]
    fn a_lone_occluder_shadows_what_is_behind_it_only() {
        for bias in [MSM_BIAS_16, MSM_BIAS_32] {
            let occluder = filtered(&[(0.3, 1.0)]);
            assert!(hamburger_visibility(occluder, 0.6, bias) < 0.05);
            assert!(hamburger_visibility(occluder, 0.29, bias) > 0.95);
        }
    }

    #[test]
    fn half_a_footprint_occluded_gives_half_the_light() {
        // Measured: 0.50003 with MSM_BIAS_16, 0.50001 with MSM_BIAS_32.
        for bias in [MSM_BIAS_16, MSM_BIAS_32] {
            let v = hamburger_visibility(filtered(&[(0.3, 0.5), (1.0, 0.5)]), 0.9, bias);
            assert!((v - 0.5).abs() < 0.01, "{v}");
        }
    }

    #[test]
    fn two_stacked_occluders_leak_almost_no_light() {
        // Half the footprint at 0.2, half at 0.5, the receiver at 0.8 behind both. Measured:
        // 7.9·10⁻⁵ with MSM_BIAS_16, 8.1·10⁻⁶ with MSM_BIAS_32 (plain VSM leaks 0.1 here).
        let stacked = filtered(&[(0.2, 0.5), (0.5, 0.5)]);
        assert!(hamburger_visibility(stacked, 0.8, MSM_BIAS_16) < 1e-4);
        assert!(hamburger_visibility(stacked, 0.8, MSM_BIAS_32) < 1e-5);
    }

    #[test]
    fn sixteen_bit_storage_keeps_lit_and_shadowed_apart() {
        for round in [round_f16, round_unorm16] {
            let occluder = stored_16(&[(0.3, 1.0)], round);
            assert!(hamburger_visibility(occluder, 0.6, MSM_BIAS_16) < 0.05);
            assert!(hamburger_visibility(occluder, 0.29, MSM_BIAS_16) > 0.95);
            // Over all depths: lit 0.02 in front, dark 0.05 behind. Measured worst cases:
            // 0.9997 and 0.020 for f16, 0.99998 and 0.0036 for unorm16.
            for k in 0..=100 {
                let d = k as f32 / 100.0;
                let m = stored_16(&[(d, 1.0)], round);
                if d >= 0.02 {
                    assert!(hamburger_visibility(m, d - 0.02, MSM_BIAS_16) > 0.99, "{d}");
                }
                if d <= 0.95 {
                    assert!(hamburger_visibility(m, d + 0.05, MSM_BIAS_16) < 0.05, "{d}");
                }
            }
        }
    }

    #[test]
    fn degenerate_moments_give_a_step_at_their_depth_and_never_nan() {
        for bias in [0.0, MSM_BIAS_32, MSM_BIAS_16] {
            for k in 0..=20 {
                let z = k as f32 / 20.0;
                for m in [
                    Vec4::ZERO,
                    Vec4::ONE,
                    Vec4::splat(0.5),
                    msm_moments(0.3),
                    msm_moments(z),
                ] {
                    assert!(!hamburger_visibility(m, z, bias).is_nan(), "{m} at {z}");
                }
                // Everything at the light (0) or at the far plane (1, a cleared map).
                assert!(hamburger_visibility(Vec4::ONE, z, bias) > 0.99);
                assert!(z == 0.0 || hamburger_visibility(Vec4::ZERO, z, bias) < 0.01);
            }
        }
        // Unbiased, one depth is an exact step: lit up to and at it, dark behind.
        let single = msm_moments(0.3);
        assert_eq!(hamburger_visibility(single, 0.3, 0.0), 1.0);
        assert_eq!(hamburger_visibility(single, 0.31, 0.0), 0.0);
        assert_eq!(hamburger_visibility(Vec4::ZERO, 0.0, 0.0), 1.0);
    }
}
