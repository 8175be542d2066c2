//! Mip chains for base-colour textures, built on the CPU when a texture is uploaded: every
//! level down to 1×1, each a box filter of the level above in linear light (the texels are
//! sRGB), so a minified texture neither shimmers nor darkens.
//!
//! For an alpha-masked material ([`MaskedAlpha`]) two things change. Colour is averaged
//! weighted by alpha, so the (often black) colour of cut-out texels does not bleed into the
//! leaf's edge. And the alpha of each level is scaled so that the fraction of its texels that
//! pass the alpha test is the fraction of the full-size image's (alpha-coverage preservation,
//! Castaño 2010): box-filtered alpha drifts towards its mean, so without it thin leaflets fall
//! below the cutoff and a distant fern (or its shadow) thins out to nothing.

use crate::ecs::assets::ImageData;

/// How a masked material tests the texture's alpha, for [`mip_chain`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaskedAlpha {
    /// The material's cutoff: texels whose alpha (times `factor`) is below it are cut out.
    pub cutoff: f32,
    /// The material's base-colour alpha, which the shaders multiply the texture's alpha by.
    pub factor: f32,
}

impl MaskedAlpha {
    /// The smallest 8-bit texture alpha that passes the test, or None when none does (or
    /// every texel does: then there is no coverage to keep).
    fn threshold(self) -> Option<u32> {
        let usable = |v: f32| v.is_finite() && v > 0.0;
        if !usable(self.factor) || !usable(self.cutoff) {
            return None;
        }
        let cutoff = self.cutoff / self.factor;
        // NOTE: a texel passes when `v / 255 >= cutoff`, in the shaders' f32 arithmetic.
        (1..=255u32).find(|&v| v as f32 / 255.0 >= cutoff)
    }
}

/// Levels of a full chain for a `width`×`height` image: down to 1×1.
pub fn mip_levels(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

/// Size of level `level` of a `width`×`height` image: each side halved (rounded down), at
/// least 1.
pub fn mip_size(width: u32, height: u32, level: u32) -> (u32, u32) {
    let side = |s: u32| s.checked_shr(level).unwrap_or(0).max(1);
    (side(width), side(height))
}

/// An 8-bit sRGB value in linear light.
fn srgb_to_linear(value: u8) -> f32 {
    let c = f32::from(value) / 255.0;
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A linear value as 8-bit sRGB, rounded to nearest.
fn linear_to_srgb(value: f32) -> u8 {
    let c = value.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// A level in linear RGB and alpha, rows top to bottom.
struct Level {
    width: u32,
    height: u32,
    texels: Vec<[f32; 4]>,
}

/// For each destination index along one axis of `from` → `to` texels (`to` ≤ `from`), the
/// source texels its footprint covers and how much of each (the weights sum to `from / to`).
fn footprints(from: u32, to: u32) -> Vec<Vec<(usize, f32)>> {
    let ratio = from as f64 / to as f64;
    (0..to)
        .map(|d| {
            let (start, end) = (d as f64 * ratio, (d + 1) as f64 * ratio);
            let last = (end.ceil() as u32).min(from);
            (start.floor() as u32..last)
                .map(|i| {
                    let w = end.min(f64::from(i) + 1.0) - start.max(f64::from(i));
                    (i as usize, w as f32)
                })
                .filter(|&(_, w)| w > 0.0)
                .collect()
        })
        .collect()
}

/// The next level: each texel the area-weighted mean of the texels under it, colour weighted
/// by alpha when `alpha_weighted` (falling back to the plain mean where all of them are 0).
fn downsample(src: &Level, alpha_weighted: bool) -> Level {
    let (width, height) = mip_size(src.width, src.height, 1);
    let (xs, ys) = (footprints(src.width, width), footprints(src.height, height));
    let mut texels = Vec::with_capacity(width as usize * height as usize);
    for y in &ys {
        for x in &xs {
            let (mut plain, mut weighted, mut area, mut alpha) = ([0.0f32; 3], [0.0f32; 3], 0.0f32, 0.0f32);
            for &(sy, wy) in y {
                for &(sx, wx) in x {
                    let t = src.texels[sy * src.width as usize + sx];
                    let w = wx * wy;
                    for c in 0..3 {
                        plain[c] += w * t[c];
                        weighted[c] += w * t[3] * t[c];
                    }
                    area += w;
                    alpha += w * t[3];
                }
            }
            let rgb = if alpha_weighted && alpha > 0.0 {
                weighted.map(|c| c / alpha)
            } else {
                plain.map(|c| c / area)
            };
            texels.push([rgb[0], rgb[1], rgb[2], alpha / area]);
        }
    }
    Level { width, height, texels }
}

/// Fraction of `alphas` (0–255) at or above `threshold`.
pub fn coverage(alphas: impl Iterator<Item = u8>, threshold: u32) -> f32 {
    let (mut passed, mut total) = (0usize, 0usize);
    for a in alphas {
        passed += (u32::from(a) >= threshold) as usize;
        total += 1;
    }
    if total == 0 { 0.0 } else { passed as f32 / total as f32 }
}

/// The factor, nearest 1, to multiply `alphas` (0–1) by so that, rounded to 8 bits, the
/// fraction at or above `threshold` is as near `target` as whole texels (and ties) allow.
fn coverage_scale(alphas: &[f32], threshold: u32, target: f32) -> f32 {
    let mut sorted: Vec<f32> = alphas.to_vec();
    sorted.sort_by(|a, b| b.total_cmp(a));
    let keep = ((target * sorted.len() as f32).round() as usize).min(sorted.len());
    // NOTE: a scaled alpha rounds to `threshold` or more from `threshold - 0.5` up: aim a
    // little above that edge to pass, a little below to fail.
    let (pass, fail) = ((threshold as f32 - 0.49) / 255.0, (threshold as f32 - 0.51) / 255.0);
    // The `keep` largest must pass: at least `low`; the next must fail: below `high`.
    let low = match keep.checked_sub(1).map(|i| sorted[i]) {
        None => 0.0,
        Some(least) if least > 0.0 => pass / least,
        // More texels must pass than have any alpha: every non-zero one passes.
        Some(_) => 255.0,
    };
    let high = match sorted.get(keep) {
        Some(&next) if next > 0.0 => fail / next,
        _ => f32::INFINITY,
    };
    if 1.0 < low {
        low
    } else if 1.0 >= high {
        high
    } else {
        1.0
    }
}

/// `level` as 8-bit sRGB RGBA, its alpha multiplied by `alpha_scale`.
fn encode(level: &Level, alpha_scale: f32) -> ImageData {
    let rgba = level
        .texels
        .iter()
        .flat_map(|t| {
            let alpha = ((t[3] * alpha_scale).clamp(0.0, 1.0) * 255.0).round() as u8;
            [linear_to_srgb(t[0]), linear_to_srgb(t[1]), linear_to_srgb(t[2]), alpha]
        })
        .collect();
    ImageData {
        width: level.width,
        height: level.height,
        rgba,
    }
}

/// The full mip chain of `image` (an sRGB RGBA image whose byte count matches its size),
/// level 0 first and unchanged. With `masked`, colour is averaged weighted by alpha and each
/// level's alpha is scaled to keep the full-size image's alpha-test coverage.
pub fn mip_chain(image: &ImageData, masked: Option<MaskedAlpha>) -> Vec<ImageData> {
    let expected = image.width as usize * image.height as usize * 4;
    if image.width == 0 || image.height == 0 || image.rgba.len() != expected {
        return vec![image.clone()];
    }
    let threshold = masked.and_then(MaskedAlpha::threshold);
    let target = threshold.map(|t| coverage(image.rgba.chunks_exact(4).map(|p| p[3]), t));
    let mut level = Level {
        width: image.width,
        height: image.height,
        texels: image
            .rgba
            .chunks_exact(4)
            .map(|p| {
                [
                    srgb_to_linear(p[0]),
                    srgb_to_linear(p[1]),
                    srgb_to_linear(p[2]),
                    f32::from(p[3]) / 255.0,
                ]
            })
            .collect(),
    };
    let mut chain = vec![image.clone()];
    for _ in 1..mip_levels(image.width, image.height) {
        // NOTE: each level is filtered from the unscaled level above (Castaño): scaling is
        // only what is stored, so it does not compound down the chain.
        level = downsample(&level, masked.is_some());
        let scale = match (threshold, target) {
            (Some(t), Some(target)) => {
                let alphas: Vec<f32> = level.texels.iter().map(|t| t[3]).collect();
                coverage_scale(&alphas, t, target)
            }
            _ => 1.0,
        };
        chain.push(encode(&level, scale));
    }
    chain
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(width: u32, height: u32, texel: impl Fn(u32, u32) -> [u8; 4]) -> ImageData {
        let rgba = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .flat_map(|(x, y)| texel(x, y))
            .collect();
        ImageData { width, height, rgba }
    }

    #[test]
    fn a_chain_halves_each_side_down_to_one_texel() {
        assert_eq!(mip_levels(1, 1), 1);
        assert_eq!(mip_levels(64, 128), 8);
        assert_eq!(mip_levels(5, 3), 3);
        assert_eq!(mip_levels(0, 0), 1);
        assert_eq!(mip_size(64, 128, 0), (64, 128));
        assert_eq!(mip_size(64, 128, 7), (1, 1));
        assert_eq!(mip_size(5, 3, 1), (2, 1));
        assert_eq!(mip_size(5, 3, 40), (1, 1));
        let chain = mip_chain(&image(64, 128, |_, _| [9, 9, 9, 255]), None);
        let sizes: Vec<_> = chain.iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(
            sizes,
            [(64, 128), (32, 64), (16, 32), (8, 16), (4, 8), (2, 4), (1, 2), (1, 1)]
        );
        for level in &chain {
            assert_eq!(level.rgba.len(), (level.width * level.height * 4) as usize);
        }
        let odd = mip_chain(&image(5, 3, |_, _| [0; 4]), None);
        let sizes: Vec<_> = odd.iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, [(5, 3), (2, 1), (1, 1)]);
    }

    #[test]
    fn the_box_filter_averages_in_linear_light() {
        // Black and white columns: the mean is 50 % linear light, sRGB 188, not 128.
        let stripes = image(4, 2, |x, _| {
            if x % 2 == 0 {
                [0, 0, 0, 255]
            } else {
                [255, 255, 255, 255]
            }
        });
        let chain = mip_chain(&stripes, None);
        assert_eq!(chain[1].rgba, [188, 188, 188, 255, 188, 188, 188, 255]);
        assert_eq!(chain[2].rgba, [188, 188, 188, 255]);
        // Alpha is linear: 0 and 255 average to 128 (127.5 rounded).
        let alpha = image(2, 1, |x, _| [200, 100, 50, if x == 0 { 0 } else { 255 }]);
        assert_eq!(mip_chain(&alpha, None)[1].rgba[3], 128);
        // A uniform image stays itself at every level.
        let flat = mip_chain(&image(8, 8, |_, _| [10, 120, 240, 77]), None);
        assert!(
            flat.iter()
                .all(|l| l.rgba.chunks_exact(4).all(|p| p == [10, 120, 240, 77]))
        );
    }

    #[test]
    fn odd_sides_weigh_each_texel_by_the_area_it_covers() {
        // 3 texels into 1: all three count fully; 5 into 2: the middle one half to each.
        assert_eq!(footprints(3, 1), [vec![(0, 1.0), (1, 1.0), (2, 1.0)]]);
        assert_eq!(
            footprints(5, 2),
            [vec![(0, 1.0), (1, 1.0), (2, 0.5)], vec![(2, 0.5), (3, 1.0), (4, 1.0)]]
        );
        // Alpha 0, 0, 255 across three texels: one third.
        let row = image(3, 1, |x, _| [0, 0, 0, if x == 2 { 255 } else { 0 }]);
        assert_eq!(mip_chain(&row, None)[1].rgba[3], 85);
    }

    #[test]
    fn masked_colour_is_weighted_by_alpha() {
        // A green texel next to a transparent black one: the plain mean darkens the edge,
        // the alpha-weighted one keeps it green.
        let edge = image(2, 1, |x, _| if x == 0 { [0, 200, 0, 255] } else { [0, 0, 0, 0] });
        let masked = MaskedAlpha {
            cutoff: 0.5,
            factor: 1.0,
        };
        assert_eq!(mip_chain(&edge, Some(masked))[1].rgba[..3], [0, 200, 0]);
        assert!(mip_chain(&edge, None)[1].rgba[1] < 160);
    }

    /// A fern-like mask: thin diagonal strokes, 2 texels wide, 6 apart: 1/3 covered.
    fn strokes(side: u32) -> ImageData {
        image(side, side, |x, y| {
            let a = if (x + y) % 6 < 2 { 255 } else { 0 };
            [30, 160, 40, a]
        })
    }

    #[test]
    fn coverage_is_preserved_down_the_chain() {
        let masked = MaskedAlpha {
            cutoff: 0.5,
            factor: 1.0,
        };
        let threshold = masked.threshold().unwrap();
        assert_eq!(threshold, 128);
        let leaf = strokes(96);
        let full = coverage(leaf.rgba.chunks_exact(4).map(|p| p[3]), threshold);
        assert!((full - 1.0 / 3.0).abs() < 1e-3, "{full}");
        let preserved = mip_chain(&leaf, Some(masked));
        let plain = mip_chain(&leaf, None);
        for (level, (kept, lost)) in preserved.iter().zip(&plain).enumerate() {
            let texels = level_texels(kept);
            let c = coverage(kept.rgba.chunks_exact(4).map(|p| p[3]), threshold);
            // Whole texels: within one texel's share (or 2 %) of the full-size coverage.
            let tolerance = (1.0 / texels as f32).max(0.02);
            assert!(
                (c - full).abs() <= tolerance,
                "level {level} ({}×{}): coverage {c} against {full}",
                kept.width,
                kept.height
            );
            let unscaled = coverage(lost.rgba.chunks_exact(4).map(|p| p[3]), threshold);
            if level == 2 {
                // Box-filtered, the strokes average out below the cutoff and vanish.
                assert!(unscaled < 0.05, "level 2 without preservation: {unscaled}");
            }
        }
    }

    fn level_texels(level: &ImageData) -> usize {
        (level.width * level.height) as usize
    }

    #[test]
    fn coverage_follows_the_material_alpha_factor_and_edge_cases() {
        // With a factor of 0.5 a texture alpha of 255 only just passes a 0.5 cutoff.
        let halved = MaskedAlpha {
            cutoff: 0.5,
            factor: 0.5,
        };
        assert_eq!(halved.threshold(), Some(255));
        // Nothing can pass: nothing to preserve.
        let never = MaskedAlpha {
            cutoff: 0.9,
            factor: 0.5,
        };
        assert_eq!(never.threshold(), None);
        let zero = MaskedAlpha {
            cutoff: 0.5,
            factor: 0.0,
        };
        assert_eq!(zero.threshold(), None);
        // A fully transparent and a fully opaque mask stay so.
        for a in [0u8, 255] {
            let chain = mip_chain(
                &image(8, 8, |_, _| [1, 2, 3, a]),
                Some(MaskedAlpha {
                    cutoff: 0.5,
                    factor: 1.0,
                }),
            );
            assert!(
                chain.iter().all(|l| l.rgba.chunks_exact(4).all(|p| p[3] == a)),
                "alpha {a}"
            );
        }
        // A malformed image comes back alone, unfiltered.
        let broken = ImageData {
            width: 4,
            height: 4,
            rgba: vec![0; 3],
        };
        assert_eq!(mip_chain(&broken, None), std::slice::from_ref(&broken));
    }
}
