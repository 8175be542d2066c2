//! Property tests of the Poisson-disk sets behind PCF and PCSS: spread in the unit disc at
//! their nominal distance, and deterministic per seed.

use penumbra::math::poisson::{min_pairwise_distance, poisson_disk, poisson_disk_with_distance};
use proptest::prelude::any;
use proptest::{prop_assert, prop_assert_eq, proptest};

proptest! {
    #[test]
    fn poisson_sets_are_spread_in_the_disc_and_deterministic(n in 1usize..80, seed in any::<u64>()) {
        let (points, d) = poisson_disk_with_distance(n, seed);
        prop_assert_eq!(points.len(), n);
        prop_assert!(points.iter().all(|p| p.length() <= 1.0));
        prop_assert!(min_pairwise_distance(&points) >= d);
        if n >= 2 {
            prop_assert_eq!(d, 0.7 / (n as f32).sqrt());
        }
        prop_assert_eq!(poisson_disk(n, seed), points);
    }
}

#[test]
fn standard_sets_keep_their_nominal_distance() {
    for (name, n, seed) in penumbra::math::poisson::STANDARD_SETS {
        let points = poisson_disk(n, seed);
        let d = min_pairwise_distance(&points);
        assert!(d >= 0.7 / (n as f32).sqrt(), "{name}: {d}");
        assert!(points.iter().all(|p| p.length() <= 1.0), "{name}");
    }
}
