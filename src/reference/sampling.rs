//! Sample directions over the sun's disc: a per-point Owen-scrambled Sobol (0,2)-sequence,
//! mapped area-preservingly onto the spherical cap the sun covers.
//!
//! Every power-of-two prefix of the 2-D Sobol sequence is a (0,m,2)-net (one point in every
//! elementary interval of area 2^-m), and Owen scrambling keeps that while making each point's
//! stream an independent randomisation, so estimates are unbiased and their error falls faster
//! than plain Monte Carlo (about N^-3/4 for a shadow edge crossing the disc instead of N^-1/2).

use glam::{Vec2, Vec3};

/// The sun's disc seen from the scene: an orthonormal frame around the direction towards the
/// sun and the size of the spherical cap.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SunCap {
    /// Unit vector towards the sun's centre.
    axis: Vec3,
    /// First unit vector perpendicular to `axis`.
    tangent: Vec3,
    /// Second unit vector perpendicular to `axis` and `tangent`.
    bitangent: Vec3,
    /// `1 - cos(half angle)`, computed without cancellation; 0 for a point sun.
    height: f32,
}

impl SunCap {
    /// The cap around `-light_direction` with the given full angular diameter in radians.
    ///
    /// `None` when `light_direction` is zero or not finite. A non-finite or zero diameter is a
    /// point sun; a negative one counts as its magnitude; the half angle is clamped to π (the
    /// whole sphere).
    pub(crate) fn new(light_direction: Vec3, angular_diameter: f32) -> Option<Self> {
        // Scaled first so that huge or tiny (but valid) directions do not overflow or underflow.
        let scale = light_direction.abs().max_element();
        let axis = (-light_direction / scale).try_normalize()?;
        let half = if angular_diameter.is_finite() {
            (angular_diameter.abs() * 0.5).min(std::f32::consts::PI)
        } else {
            0.0
        };
        let (tangent, bitangent) = axis.any_orthonormal_pair();
        let s = (half * 0.5).sin();
        Some(Self {
            axis,
            tangent,
            bitangent,
            height: 2.0 * s * s,
        })
    }

    /// True when the cap is a single direction (every sample is [`SunCap::axis`]).
    pub(crate) fn is_point(&self) -> bool {
        self.height == 0.0
    }

    /// Unit vector towards the sun's centre.
    #[cfg(test)]
    pub(crate) fn axis(&self) -> Vec3 {
        self.axis
    }

    /// The direction for a point `u` of the unit square; uniform `u` gives directions uniform
    /// over the cap's solid angle.
    ///
    /// The square goes onto the unit disc with Shirley and Chiu's concentric map (area
    /// preserving, and it keeps strata compact), then the disc onto the cap so that the
    /// fraction of the disc's area within radius r, r², is the fraction of the cap's solid
    /// angle within polar angle θ: `1 − cos θ = r² (1 − cos α)`.
    #[inline]
    pub(crate) fn direction(&self, u: Vec2) -> Vec3 {
        let a = 2.0 * u.x - 1.0;
        let b = 2.0 * u.y - 1.0;
        // (x, y) on the unit disc.
        let (x, y) = if a == 0.0 && b == 0.0 {
            (0.0, 0.0)
        } else if a * a > b * b {
            let phi = std::f32::consts::FRAC_PI_4 * (b / a);
            (a * phi.cos(), a * phi.sin())
        } else {
            let phi = std::f32::consts::FRAC_PI_2 - std::f32::consts::FRAC_PI_4 * (a / b);
            (b * phi.cos(), b * phi.sin())
        };
        let r2 = (x * x + y * y).min(1.0);
        let one_minus_cos = r2 * self.height;
        let cos_theta = 1.0 - one_minus_cos;
        // sin θ / r, so that (x, y) * k has length sin θ without dividing by r.
        let k = (self.height * (2.0 - one_minus_cos)).max(0.0).sqrt();
        self.tangent * (x * k) + self.bitangent * (y * k) + self.axis * cos_theta
    }
}

/// The per-point stream of 2-D points: Sobol dimensions 0 and 1, each Owen-scrambled with its
/// own seed derived from the run's seed and the point's index.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PointSequence {
    seed_x: u32,
    seed_y: u32,
}

impl PointSequence {
    /// The stream of point `index` for the run seeded with `seed`. Depends on nothing else, so
    /// results do not depend on how points are spread over threads.
    pub(crate) fn new(seed: u64, index: u64) -> Self {
        let key = mix64(mix64(seed ^ 0x5851_f42d_4c95_7f2d).wrapping_add(index.wrapping_mul(0x9e37_79b9_7f4a_7c15)));
        Self {
            seed_x: key as u32,
            seed_y: (key >> 32) as u32,
        }
    }

    /// Sample `i` of the stream, in `[0, 1)²`.
    #[inline]
    pub(crate) fn sample(&self, i: u32) -> Vec2 {
        // Sobol dimension 0 is the van der Corput sequence, reverse_bits(i); a nested uniform
        // scramble of it is reverse_bits(owen(reverse_bits(reverse_bits(i)))).
        let x = owen_hash(i, self.seed_x).reverse_bits();
        let y = owen_hash(sobol_dim1(i).reverse_bits(), self.seed_y).reverse_bits();
        Vec2::new(to_unit(x), to_unit(y))
    }
}

/// The top 24 bits of `x` as a float in `[0, 1)`.
#[inline]
fn to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Sobol dimension 1 (direction numbers `v_0 = 1/2`, `v_{k+1} = v_k ^ (v_k >> 1)`), as a 32-bit
/// fixed-point fraction.
#[inline]
fn sobol_dim1(mut i: u32) -> u32 {
    let mut v = 1u32 << 31;
    let mut x = 0;
    while i != 0 {
        if i & 1 != 0 {
            x ^= v;
        }
        i >>= 1;
        v ^= v >> 1;
    }
    x
}

/// A hash in which bit k of the result depends only on bits 0..=k of `x`: applied to a
/// bit-reversed fraction it is an Owen (nested uniform) scramble. Laine and Karras' construction
/// with Vegdahl's constants ("Building a Better LK Hash", 2021).
#[inline]
fn owen_hash(mut x: u32, seed: u32) -> u32 {
    x ^= x.wrapping_mul(0x3d20_adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x0552_6c56);
    x ^= x.wrapping_mul(0x53a2_2864);
    x
}

/// SplitMix64's finaliser: a bijective 64-bit mix.
#[inline]
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Checks that `points` (2^m of them) form a (0,m,2)-net: every elementary interval of
    /// area 2^-m holds exactly one point.
    fn assert_net(points: &[Vec2]) {
        let m = points.len().trailing_zeros();
        assert_eq!(points.len(), 1 << m);
        for kx in 0..=m {
            let ky = m - kx;
            let mut seen = vec![0u32; 1 << m];
            for p in points {
                let ix = (p.x * (1u32 << kx) as f32) as usize;
                let iy = (p.y * (1u32 << ky) as f32) as usize;
                seen[ix + (iy << kx)] += 1;
            }
            assert!(
                seen.iter().all(|&c| c == 1),
                "not a net for {kx}x{ky} intervals: {seen:?}"
            );
        }
    }

    #[test]
    fn power_of_two_prefixes_are_nets() {
        for (seed, index) in [(1, 0), (1, 1), (7, 12345), (u64::MAX, u64::MAX)] {
            let seq = PointSequence::new(seed, index);
            let pts: Vec<Vec2> = (0..1024).map(|i| seq.sample(i)).collect();
            for m in [0, 2, 4, 8, 10] {
                assert_net(&pts[..1 << m]);
            }
            // The blocks after a prefix are nets too (adaptive sampling continues from there).
            assert_net(&pts[16..32]);
            assert!(
                pts.iter()
                    .all(|p| p.cmpge(Vec2::ZERO).all() && p.cmplt(Vec2::ONE).all())
            );
        }
    }

    #[test]
    fn streams_differ_between_points_and_seeds() {
        let a = PointSequence::new(1, 0).sample(3);
        assert_ne!(a, PointSequence::new(1, 1).sample(3));
        assert_ne!(a, PointSequence::new(2, 0).sample(3));
        assert_eq!(a, PointSequence::new(1, 0).sample(3));
    }

    #[test]
    fn scrambling_is_unbiased_on_average() {
        // The first sample of each stream is uniform over the square across streams.
        let n = 20_000;
        let mean = (0..n).map(|i| PointSequence::new(9, i).sample(0)).sum::<Vec2>() / n as f32;
        assert!((mean - Vec2::splat(0.5)).abs().max_element() < 0.01, "{mean}");
    }

    #[test]
    fn sobol_dim1_matches_known_values() {
        // 0, 1/2, 3/4, 1/4, 5/8, 1/8, 3/8, 7/8 (the second Sobol coordinate).
        let want = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (i, w) in want.into_iter().enumerate() {
            assert_eq!(sobol_dim1(i as u32) as f64 / 4_294_967_296.0, w, "index {i}");
        }
    }

    #[test]
    fn cap_directions_are_unit_and_inside_the_cap() {
        let half = 0.3f32;
        let cap = SunCap::new(Vec3::new(0.3, -1.0, 0.2), 2.0 * half).unwrap();
        assert!((cap.axis() - Vec3::new(-0.3, 1.0, -0.2).normalize()).length() < 1e-6);
        let seq = PointSequence::new(3, 4);
        let mut max_angle = 0.0f32;
        for i in 0..4096 {
            let d = cap.direction(seq.sample(i));
            assert!((d.length() - 1.0).abs() < 1e-5);
            let angle = d.dot(cap.axis()).clamp(-1.0, 1.0).acos();
            assert!(angle <= half + 1e-4, "{angle}");
            max_angle = max_angle.max(angle);
        }
        assert!(max_angle > half * 0.98, "samples should reach the rim: {max_angle}");
        // Corners and centre of the square.
        for u in [Vec2::ZERO, Vec2::ONE, Vec2::new(0.0, 1.0), Vec2::splat(0.5)] {
            assert!(cap.direction(u).dot(cap.axis()) >= half.cos() - 1e-5);
        }
    }

    #[test]
    fn cap_directions_are_uniform_in_solid_angle() {
        // A wide cap: the mean of cos θ over a uniform cap of half angle α is (1 + cos α) / 2,
        // and the mean direction lies on the axis; half the solid angle lies within
        // 1 − cos θ < (1 − cos α) / 2.
        let half = 1.2f32;
        let cap = SunCap::new(Vec3::new(0.0, 0.0, -2.0), 2.0 * half).unwrap();
        let n = 16_384;
        let mut mean = Vec3::ZERO;
        let mut inner = 0;
        for p in 0..16u64 {
            let seq = PointSequence::new(5, p);
            for i in 0..n / 16 {
                let d = cap.direction(seq.sample(i));
                mean += d;
                inner += usize::from(1.0 - d.z < (1.0 - half.cos()) * 0.5);
            }
        }
        mean /= n as f32;
        assert!((mean.z - (1.0 + half.cos()) * 0.5).abs() < 2e-3, "{mean}");
        assert!(mean.truncate().length() < 2e-3, "{mean}");
        assert!((inner as f32 / n as f32 - 0.5).abs() < 0.01);
    }

    #[test]
    fn cap_edge_cases() {
        assert!(SunCap::new(Vec3::ZERO, 0.1).is_none());
        assert!(SunCap::new(Vec3::new(f32::NAN, 1.0, 0.0), 0.1).is_none());
        assert!(SunCap::new(Vec3::new(f32::INFINITY, 1.0, 0.0), 0.1).is_none());
        for tiny_or_huge in [1e-40, 3e38] {
            let cap = SunCap::new(Vec3::new(0.0, -tiny_or_huge, tiny_or_huge), 0.1).unwrap();
            assert!((cap.axis() - Vec3::new(0.0, 1.0, -1.0).normalize()).length() < 1e-6);
        }
        let point = SunCap::new(Vec3::NEG_Y, 0.0).unwrap();
        assert!(point.is_point());
        assert_eq!(point.direction(Vec2::new(0.3, 0.9)), Vec3::Y);
        assert!(SunCap::new(Vec3::NEG_Y, f32::NAN).unwrap().is_point());
        // A whole-sphere "sun" reaches straight down.
        let all = SunCap::new(Vec3::NEG_Y, 100.0).unwrap();
        let d = all.direction(Vec2::new(1.0, 0.5));
        assert!((d + Vec3::Y).length() < 1e-3, "{d}");
    }
}
