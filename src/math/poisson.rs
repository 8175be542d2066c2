//! Deterministic Poisson-disk sample sets in the unit disc (dart throwing with a tiny seeded
//! PRNG).

use glam::Vec2;

/// Factor applied to the minimum distance each time a dart-throwing pass fails.
pub const RELAX_FACTOR: f32 = 0.95;

/// Consecutive rejected darts after which a pass counts as failed.
pub const MAX_CONSECUTIVE_REJECTIONS: u32 = 20_000;

/// The sets the renderer uses, uploaded by `render::gpu_types::PoissonTapsGpu`: `(name, sample
/// count, seed)`. The 25-tap seed was picked among 45–48 by PCSS Medium's penumbra error in
/// `penumbra bench` (see docs/benchmarks.md).
pub const STANDARD_SETS: [(&str, usize, u64); 5] = [
    ("BLOCKER_16", 16, 41),
    ("BLOCKER_32", 32, 42),
    ("FILTER_16", 16, 44),
    ("FILTER_25", 25, 47),
    ("FILTER_49", 49, 43),
];

/// SplitMix64 (Steele, Lea, Flood 2014): a 64-bit state, one add and a mixing function per
/// output. Tiny, fast, and identical on every platform.
struct SplitMix64(u64);

impl SplitMix64 {
    /// Next 64 random bits.
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[-1, 1)`, from the top 24 bits (exact in f32).
    fn next_signed(&mut self) -> f32 {
        let unit = (self.next_u64() >> 40) as f32 * (1.0 / (1u32 << 24) as f32);
        unit * 2.0 - 1.0
    }

    /// Uniform point in the closed unit disc (rejection from the square).
    fn next_in_disc(&mut self) -> Vec2 {
        loop {
            let p = Vec2::new(self.next_signed(), self.next_signed());
            if p.length_squared() <= 1.0 {
                return p;
            }
        }
    }
}

/// `n` points in the unit disc, pairwise at least `0.7 / sqrt(n)` apart (see
/// [`poisson_disk_with_distance`] for the rare relaxed case). Same `(n, seed)`, same points.
pub fn poisson_disk(n: usize, seed: u64) -> Vec<Vec2> {
    poisson_disk_with_distance(n, seed).0
}

/// [`poisson_disk`] and the minimum distance the points are guaranteed to keep
/// (`min_pairwise_distance(&points) >= distance`).
///
/// Dart throwing: uniform candidates in the disc are accepted when at least `distance` from
/// every accepted point, starting with `distance = 0.7 / sqrt(n)`. If
/// [`MAX_CONSECUTIVE_REJECTIONS`] darts in a row are rejected before `n` points are placed,
/// the pass restarts (continuing the same random stream, so the result stays
/// deterministic) with `distance` multiplied by [`RELAX_FACTOR`]. The returned distance is
/// the one of the successful pass; for the [`STANDARD_SETS`] no relaxation happens and it
/// is exactly `0.7 / sqrt(n)`. For fewer than two points the distance is `+∞`.
/// Cost is O(n²) distance checks, fine for kernel-sized sets.
pub fn poisson_disk_with_distance(n: usize, seed: u64) -> (Vec<Vec2>, f32) {
    dart_throw(n, seed, 0.7 / (n as f32).sqrt())
}

/// Dart throwing starting at minimum distance `distance`, relaxed until `n` points fit.
fn dart_throw(n: usize, seed: u64, mut distance: f32) -> (Vec<Vec2>, f32) {
    let mut rng = SplitMix64(seed);
    if n < 2 {
        return ((0..n).map(|_| rng.next_in_disc()).collect(), f32::INFINITY);
    }
    let mut points = Vec::with_capacity(n);
    loop {
        points.clear();
        let mut rejections = 0;
        while points.len() < n && rejections < MAX_CONSECUTIVE_REJECTIONS {
            let c = rng.next_in_disc();
            // NOTE: the same f32 `distance` computation as `min_pairwise_distance`, so the
            // documented guarantee holds bit for bit.
            if points.iter().all(|p: &Vec2| p.distance(c) >= distance) {
                points.push(c);
                rejections = 0;
            } else {
                rejections += 1;
            }
        }
        if points.len() == n {
            return (points, distance);
        }
        distance *= RELAX_FACTOR;
    }
}

/// The smallest distance between two of the points; `+∞` for fewer than two.
pub fn min_pairwise_distance(points: &[Vec2]) -> f32 {
    let mut best = f32::INFINITY;
    for (i, a) in points.iter().enumerate() {
        for b in &points[i + 1..] {
            best = best.min(a.distance(*b));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix_reference_values() {
        // First outputs for seed 1234567 from the reference implementation (Vigna, 2015).
        let mut r = SplitMix64(1_234_567);
        assert_eq!(r.next_u64(), 6_457_827_717_110_365_317);
        assert_eq!(r.next_u64(), 3_203_168_211_198_807_973);
    }

    #[test]
    fn sets_are_in_the_disc_and_spread() {
        for (_, n, seed) in STANDARD_SETS {
            let (pts, d) = poisson_disk_with_distance(n, seed);
            assert_eq!(pts.len(), n);
            assert!(pts.iter().all(|p| p.length() <= 1.0));
            assert_eq!(d, 0.7 / (n as f32).sqrt());
            assert!(min_pairwise_distance(&pts) >= d);
        }
    }

    #[test]
    fn deterministic_per_seed() {
        assert_eq!(poisson_disk(25, 7), poisson_disk(25, 7));
        assert_ne!(poisson_disk(25, 7), poisson_disk(25, 8));
        assert!(poisson_disk(0, 1).is_empty());
        assert_eq!(poisson_disk(1, 1).len(), 1);
    }

    #[test]
    fn impossible_distances_relax() {
        // At most 3 points of the unit disc can be 1.5 apart, so 10 forces relaxation.
        let (pts, d) = dart_throw(10, 3, 1.5);
        assert_eq!(pts.len(), 10);
        assert!(d < 1.5 * RELAX_FACTOR, "{d}");
        assert!(min_pairwise_distance(&pts) >= d);
        assert_eq!(dart_throw(10, 3, 1.5), (pts, d));
    }

    #[test]
    fn larger_sets_keep_the_nominal_distance() {
        let (pts, d) = poisson_disk_with_distance(400, 3);
        assert_eq!(pts.len(), 400);
        assert_eq!(d, 0.7 / 20.0);
        assert!(min_pairwise_distance(&pts) >= d);
    }

    #[test]
    fn min_pairwise_distance_basics() {
        assert_eq!(min_pairwise_distance(&[]), f32::INFINITY);
        let pts = [Vec2::ZERO, Vec2::new(3.0, 4.0), Vec2::new(0.0, 1.0)];
        assert_eq!(min_pairwise_distance(&pts), 1.0);
    }
}
