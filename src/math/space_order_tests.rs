//! Tests of the casters' space order: Morton codes, and culling over the space-ordered chunks
//! finding every sphere the exact test finds, in draw order, after moves and appends too.

use glam::{Mat3, Vec3};

use super::*;
use crate::math::culling::cull_casters;

#[test]
fn morton_codes_interleave_axes_and_stay_in_range() {
    let b = Aabb::new(Vec3::ZERO, Vec3::splat(1023.0));
    assert_eq!(morton_code(&b, Vec3::ZERO), 0);
    assert_eq!(morton_code(&b, Vec3::new(1.0, 0.0, 0.0)), 0b001);
    assert_eq!(morton_code(&b, Vec3::new(0.0, 1.0, 0.0)), 0b010);
    assert_eq!(morton_code(&b, Vec3::new(0.0, 0.0, 1.0)), 0b100);
    assert_eq!(morton_code(&b, Vec3::splat(1023.0)), (1 << 30) - 1);
    // Outside the bounds clamps; a degenerate box does not divide by zero.
    assert_eq!(morton_code(&b, Vec3::splat(-5.0)), 0);
    let flat = Aabb::new(Vec3::ZERO, Vec3::new(10.0, 0.0, 10.0));
    assert!(morton_code(&flat, Vec3::new(5.0, 0.0, 5.0)) > 0);
}

/// A deterministic pseudo-random number in [0, 1).
fn unit(state: &mut u64) -> f32 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*state >> 40) as f32 / (1u64 << 24) as f32
}

/// `n` small spheres over a 400 m square, in an order unrelated to their place (as a field of
/// many meshes' copies is in draw order).
fn scattered(n: usize, seed: u64) -> (Vec<Vec3>, Vec<f32>) {
    let mut s = seed;
    let centers = (0..n)
        .map(|_| {
            Vec3::new(
                unit(&mut s) * 400.0 - 200.0,
                unit(&mut s) * 2.0,
                unit(&mut s) * 400.0 - 200.0,
            )
        })
        .collect();
    let radii = (0..n).map(|_| 0.2 + unit(&mut s)).collect();
    (centers, radii)
}

/// Up to four boxes seen by a sun straight down (light x = world x, light y = world −z):
/// strips a few metres wide, as a moving clipmap level uncovers.
fn strips(rects: &[(f32, f32, f32, f32)]) -> CascadeSet {
    let mut set = CascadeSet {
        count: rects.len(),
        light_rotation: Mat3::from_cols(Vec3::X, Vec3::NEG_Z, Vec3::Y).transpose(),
        clipmap: true,
        ..CascadeSet::default()
    };
    for (c, &(x0, y0, x1, y1)) in set.cascades.iter_mut().zip(rects) {
        c.light_min = Vec3::new(x0, y0, -10.0);
        c.light_max = Vec3::new(x1, y1, 10.0);
    }
    set
}

/// Checks that the hits of `space` over `set` are sorted by caster and give each sphere
/// exactly the bits the exact test gives it (the chunked decisions may add a bit within their
/// padding of a box; none of these spheres lies that close); returns how many spheres the
/// exact test found.
fn check(space: &SpaceOrder, set: &CascadeSet, centers: &[Vec3], radii: &[f32]) -> usize {
    let mut exact = vec![0u8; centers.len()];
    cull_casters(set, centers, radii, &mut exact);
    let mut hits = Vec::new();
    space.cull_sorted(set, &mut hits);
    assert!(hits.windows(2).all(|w| w[0].0 < w[1].0), "hits out of draw order");
    let mut found = vec![0u8; centers.len()];
    for &(i, bits) in &hits {
        found[i as usize] = bits;
    }
    for (i, (&e, &f)) in exact.iter().zip(&found).enumerate() {
        assert_eq!(e, f, "sphere {i}: exact {e:#b}, space order {f:#b}");
    }
    exact.iter().filter(|&&e| e != 0).count()
}

#[test]
fn strips_find_every_sphere_the_exact_test_finds_in_draw_order() {
    let (centers, radii) = scattered(20_000, 7);
    let space = SpaceOrder::build(&centers, &radii);
    assert_eq!(space.len(), 20_000);
    let set = strips(&[
        (-60.0, -20.0, -55.0, 40.0),
        (10.0, 3.0, 90.0, 6.0),
        (-200.0, -200.0, 200.0, 200.0),
    ]);
    let found = check(&space, &set, &centers, &radii);
    assert_eq!(found, 20_000, "the whole-scene box found {found} spheres");
    let narrow = strips(&[(-60.0, -20.0, -55.0, 40.0)]);
    let found = check(&space, &narrow, &centers, &radii);
    // Measured: 49.
    assert!(
        (17..=150).contains(&found),
        "a 5 m × 60 m strip found {found} of 20 000 spheres"
    );
}

#[test]
fn moved_and_appended_spheres_are_found_where_they_are_now() {
    let (mut centers, mut radii) = scattered(5_000, 11);
    let mut space = SpaceOrder::build(&centers, &radii);
    // Every 7th sphere jumps into the strip; new spheres land in it too.
    let moved: Vec<u32> = (0..5_000).step_by(7).collect();
    for &i in &moved {
        centers[i as usize] = Vec3::new(-57.0, 1.0, -10.0 - (i % 25) as f32);
    }
    space.refit(moved.iter().copied(), &centers, &radii);
    centers.extend((0..300).map(|i| Vec3::new(-58.0, 1.0, -(i as f32) * 0.1)));
    radii.extend(std::iter::repeat_n(0.5, 300));
    space.extend(&centers, &radii);
    assert_eq!(space.len(), 5_300);
    let set = strips(&[(-60.0, -20.0, -55.0, 40.0)]);
    let found = check(&space, &set, &centers, &radii);
    assert!(
        found >= moved.len() + 300,
        "found {found}: fewer than the moved and appended spheres"
    );
}

#[test]
fn spheres_that_are_not_finite_are_still_ordered_and_culled() {
    let (mut centers, radii) = scattered(1_000, 3);
    centers[10] = Vec3::NAN;
    centers[500] = Vec3::new(f32::INFINITY, 0.0, 0.0);
    let space = SpaceOrder::build(&centers, &radii);
    assert_eq!(space.len(), 1_000);
    check(&space, &strips(&[(-60.0, -20.0, -55.0, 40.0)]), &centers, &radii);
    let mut empty = Vec::new();
    SpaceOrder::default().cull_sorted(&strips(&[(0.0, 0.0, 1.0, 1.0)]), &mut empty);
    assert!(empty.is_empty());
}
