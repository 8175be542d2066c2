//! What the camera saw, for the depth-bounds (SDSM) cascade fit: the view-depth range of the
//! pixels a frame covered and, per band of view depth, the world box of those pixels. The GPU
//! reduces a frame's depth buffer into the words [`SeenDepths::from_words`] decodes; a later
//! frame fits its cascades to them (one or more frames late, so every bound is grown by a
//! guard band before use).

use glam::Vec3;

use crate::math::aabb::Aabb;

/// Bands of view depth the seen world boxes are kept in, spaced logarithmically between the
/// camera's near and far planes.
pub const DEPTH_BANDS: usize = 32;

/// Words of the reduction's buffer: the header (band near, band far, depth min, depth max)
/// and six per band (min x, y, z, max x, y, z).
pub const SEEN_WORDS: usize = 4 + 6 * DEPTH_BANDS;

/// Share of the nearest and farthest depths seen, and of a seen box's extent (or its far
/// depth), added on each side before a frame fits to them: the camera moves between the
/// frame that saw and the frame that fits.
pub const SEEN_GUARD: f32 = 0.1;

/// The view depths and world boxes one frame's covered pixels spanned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeenDepths {
    /// View depth of the nearest covered pixel.
    pub near: f32,
    /// View depth of the farthest covered pixel.
    pub far: f32,
    /// View depth where band 0 starts (the camera's near plane).
    pub band_near: f32,
    /// View depth where the last band ends (the camera's far plane).
    pub band_far: f32,
    /// The world box of the covered pixels in each band (empty where none fell).
    pub bands: [Aabb; DEPTH_BANDS],
}

/// A float's bits mapped so that unsigned order is the float's order (what the GPU's atomic
/// min and max compare).
pub fn ordered_bits(value: f32) -> u32 {
    let bits = value.to_bits();
    if bits & 0x8000_0000 != 0 {
        !bits
    } else {
        bits | 0x8000_0000
    }
}

/// The inverse of [`ordered_bits`].
pub fn from_ordered_bits(bits: u32) -> f32 {
    if bits & 0x8000_0000 != 0 {
        f32::from_bits(bits & 0x7fff_ffff)
    } else {
        f32::from_bits(!bits)
    }
}

/// The band of view depth `depth` between `near` and `far` (clamped into the bands), as the
/// reduction shader computes it.
pub fn band_of(depth: f32, near: f32, far: f32) -> usize {
    let t = (depth / near).ln() / (far / near).ln();
    let band = (t * DEPTH_BANDS as f32).floor();
    if band.is_nan() {
        return 0;
    }
    band.clamp(0.0, (DEPTH_BANDS - 1) as f32) as usize
}

/// View depth where band `band` starts (`band = DEPTH_BANDS` gives where the last ends).
pub fn band_start(band: usize, near: f32, far: f32) -> f32 {
    near * (far / near).powf(band as f32 / DEPTH_BANDS as f32)
}

/// The words the reduction starts from each frame: the band limits, and every minimum at its
/// largest and maximum at its smallest value.
pub fn initial_words(band_near: f32, band_far: f32) -> [u32; SEEN_WORDS] {
    let mut words = [0u32; SEEN_WORDS];
    words[0] = band_near.to_bits();
    words[1] = band_far.to_bits();
    words[2] = u32::MAX;
    words[3] = 0;
    for band in words[4..].chunks_exact_mut(6) {
        band[..3].fill(u32::MAX);
        band[3..].fill(0);
    }
    words
}

impl SeenDepths {
    /// Decodes the reduction's words; None when no pixel was covered, the words are too few,
    /// or a decoded bound is not finite.
    pub fn from_words(words: &[u32]) -> Option<Self> {
        if words.len() < SEEN_WORDS || words[2] == u32::MAX {
            return None;
        }
        let (band_near, band_far) = (f32::from_bits(words[0]), f32::from_bits(words[1]));
        let (near, far) = (from_ordered_bits(words[2]), from_ordered_bits(words[3]));
        let finite = [band_near, band_far, near, far].iter().all(|v| v.is_finite());
        let ordered = near <= far && band_near > 0.0 && band_near < band_far;
        if !(finite && ordered) {
            return None;
        }
        let mut bands = [Aabb::EMPTY; DEPTH_BANDS];
        for (out, w) in bands.iter_mut().zip(words[4..SEEN_WORDS].chunks_exact(6)) {
            if w[0] == u32::MAX {
                continue;
            }
            let v = |i: usize| from_ordered_bits(w[i]);
            let b = Aabb::new(Vec3::new(v(0), v(1), v(2)), Vec3::new(v(3), v(4), v(5)));
            if !b.is_finite() || b.is_empty() {
                return None;
            }
            *out = b;
        }
        Some(Self {
            near,
            far,
            band_near,
            band_far,
            bands,
        })
    }

    /// The view depths to fit the splits between: the seen range grown by [`SEEN_GUARD`] of
    /// the nearest depth towards the camera and of the farthest away from it.
    pub fn guarded_range(&self) -> (f32, f32) {
        (self.near * (1.0 - SEEN_GUARD), self.far * (1.0 + SEEN_GUARD))
    }

    /// The world box of every pixel seen between view depths `near` and `far` (the bands
    /// that overlap them), grown on each side by [`SEEN_GUARD`] of its largest extent or of
    /// `far`, whichever is larger (a few pixels seen far away still leave room for the camera
    /// to move); empty where no pixel fell there.
    pub fn bounds_between(&self, near: f32, far: f32) -> Aabb {
        if near.partial_cmp(&far).is_none_or(|o| o == std::cmp::Ordering::Greater) {
            return Aabb::EMPTY;
        }
        let first = band_of(near, self.band_near, self.band_far);
        let last = band_of(far, self.band_near, self.band_far);
        let seen = self.bands[first..=last].iter().fold(Aabb::EMPTY, |a, &b| a.union(b));
        if seen.is_empty() {
            return seen;
        }
        let grow = Vec3::splat(SEEN_GUARD * (seen.max - seen.min).max_element().max(far));
        Aabb::new(seen.min - grow, seen.max + grow)
    }

    /// These depths seen from a render origin `shift` further along (world positions minus
    /// `shift`): what a frame whose floating origin moved by `shift` since this one fits to.
    pub fn shifted(&self, shift: Vec3) -> Self {
        let mut out = *self;
        for b in out.bands.iter_mut().filter(|b| !b.is_empty()) {
            *b = Aabb::new(b.min - shift, b.max - shift);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Words a reduction over `pixels` (view depth, world point) would leave.
    fn reduce(pixels: &[(f32, Vec3)], near: f32, far: f32) -> Vec<u32> {
        let mut w = initial_words(near, far).to_vec();
        for &(d, p) in pixels {
            w[2] = w[2].min(ordered_bits(d));
            w[3] = w[3].max(ordered_bits(d));
            let b = 4 + 6 * band_of(d, near, far);
            for (i, v) in p.to_array().into_iter().enumerate() {
                w[b + i] = w[b + i].min(ordered_bits(v));
                w[b + 3 + i] = w[b + 3 + i].max(ordered_bits(v));
            }
        }
        w
    }

    #[test]
    fn ordered_bits_keep_the_order_of_floats() {
        let values = [
            f32::NEG_INFINITY,
            -1e30,
            -2.5,
            -1e-30,
            -0.0,
            0.0,
            1e-30,
            0.5,
            3.0,
            1e30,
            f32::INFINITY,
        ];
        for pair in values.windows(2) {
            assert!(ordered_bits(pair[0]) <= ordered_bits(pair[1]), "{pair:?}");
        }
        for v in values {
            assert_eq!(from_ordered_bits(ordered_bits(v)).to_bits(), v.to_bits());
        }
    }

    #[test]
    fn no_covered_pixel_decodes_to_nothing() {
        assert_eq!(SeenDepths::from_words(&initial_words(0.1, 100.0)), None);
        assert_eq!(SeenDepths::from_words(&[0; 8]), None);
    }

    #[test]
    fn bands_split_the_view_logarithmically_and_cover_it() {
        let (near, far) = (0.1, 1000.0);
        assert_eq!(band_of(near, near, far), 0);
        assert_eq!(band_of(far, near, far), DEPTH_BANDS - 1);
        assert_eq!(band_of(1e9, near, far), DEPTH_BANDS - 1);
        assert_eq!(band_of(1e-9, near, far), 0);
        assert_eq!(band_of(f32::NAN, near, far), 0);
        for band in 0..DEPTH_BANDS {
            let mid = (band_start(band, near, far) * band_start(band + 1, near, far)).sqrt();
            assert_eq!(band_of(mid, near, far), band);
        }
        assert!((band_start(DEPTH_BANDS, near, far) - far).abs() < 1e-2);
    }

    #[test]
    fn decoded_bounds_hold_every_pixel_of_their_depths() {
        let pixels: Vec<(f32, Vec3)> = (0..200)
            .map(|i| {
                let d = 0.5 + 0.37 * i as f32;
                (d, Vec3::new(-3.0 + 0.05 * i as f32, (i % 7) as f32 - 2.0, -d))
            })
            .collect();
        let seen = SeenDepths::from_words(&reduce(&pixels, 0.1, 500.0)).expect("covered");
        assert_eq!((seen.near, seen.far), (0.5, pixels[199].0));
        for &(d, p) in &pixels {
            let b = seen.bounds_between(d, d);
            assert!(b.min.cmple(p).all() && p.cmple(b.max).all(), "{p} outside {b:?}");
        }
        // Nothing was seen nearer than 0.5.
        assert!(seen.bounds_between(0.1, 0.2).is_empty());
        let (lo, hi) = seen.guarded_range();
        assert!(lo < seen.near && hi > seen.far, "{lo} {hi}");
        let moved = seen.shifted(Vec3::new(1.0, 0.0, 0.0));
        let (a, b) = (seen.bounds_between(1.0, 50.0), moved.bounds_between(1.0, 50.0));
        assert_eq!(b.min.x, a.min.x - 1.0);
    }

    #[test]
    fn non_finite_words_are_refused() {
        let mut w = reduce(&[(2.0, Vec3::ONE)], 0.1, 100.0);
        w[4 + 6 * band_of(2.0, 0.1, 100.0)] = ordered_bits(f32::NAN);
        assert_eq!(SeenDepths::from_words(&w), None);
    }
}
