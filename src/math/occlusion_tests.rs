use glam::{Mat4, Vec3};

use super::{CullCamera, Pyramid, hidden, level_count, level_for, sphere_rect};
use crate::math::projection::perspective_reverse_z;

/// A 60° camera at the origin looking down -z over a `w` × `h` screen.
fn camera(w: u32, h: u32) -> CullCamera {
    CullCamera {
        clip_from_view: perspective_reverse_z(60f32.to_radians(), w as f32 / h as f32, 0.1, 100.0),
        view_from_world: Mat4::IDENTITY,
        near: 0.1,
    }
}

/// The reverse-Z depth of view distance `d` for `camera`.
fn depth_at(camera: &CullCamera, d: f32) -> f32 {
    let clip = camera.clip_from_view * glam::Vec4::new(0.0, 0.0, -d, 1.0);
    clip.z / clip.w
}

/// A tiny deterministic generator (64-bit LCG).
struct Lcg(u64);

impl Lcg {
    fn unit(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

#[test]
fn levels_go_down_to_one_texel() {
    assert_eq!(level_count(1, 1), 1);
    assert_eq!(level_count(2, 1), 2);
    assert_eq!(level_count(1920, 1080), 11);
    let p = Pyramid::build(&vec![0.5; 13 * 7], 13, 7);
    let sizes: Vec<(u32, u32)> = p.levels.iter().map(|l| (l.0, l.1)).collect();
    assert_eq!(sizes, [(13, 7), (6, 3), (3, 1), (1, 1)]);
}

#[test]
fn every_texel_holds_the_farthest_pixel_under_it() {
    let (w, h) = (13u32, 7u32);
    let mut rng = Lcg(3);
    let depth: Vec<f32> = (0..w * h).map(|_| rng.unit()).collect();
    let p = Pyramid::build(&depth, w, h);
    for (k, (lw, lh, _)) in p.levels.iter().enumerate() {
        let step = 1u32 << k;
        for y in 0..*lh {
            for x in 0..*lw {
                // The pixels under texel (x, y): its square, and to the edge for the last ones.
                let xs = x * step..if x == lw - 1 { w } else { (x + 1) * step };
                let ys = y * step..if y == lh - 1 { h } else { (y + 1) * step };
                let depth = &depth;
                let expected = ys
                    .flat_map(|yy| xs.clone().map(move |xx| depth[(yy * w + xx) as usize]))
                    .fold(1.0f32, f32::min);
                assert_eq!(p.texel(k, x, y), expected, "level {k} texel ({x}, {y})");
            }
        }
    }
}

#[test]
fn a_sphere_behind_a_wall_is_hidden_and_one_in_front_or_beside_it_is_not() {
    let (w, h) = (64u32, 36u32);
    let cam = camera(w, h);
    let wall = depth_at(&cam, 10.0);
    let full = Pyramid::build(&vec![wall; (w * h) as usize], w, h);
    assert!(hidden(&full, &cam, Vec3::new(0.0, 0.0, -20.0), 1.0));
    assert!(!hidden(&full, &cam, Vec3::new(0.0, 0.0, -5.0), 1.0));
    // A sphere straddling the wall is kept.
    assert!(!hidden(&full, &cam, Vec3::new(0.0, 0.0, -10.5), 1.0));
    // The wall covers the left half only: a sphere behind its right half is seen.
    let half: Vec<f32> = (0..w * h).map(|i| if i % w < w / 2 { wall } else { 0.0 }).collect();
    let half = Pyramid::build(&half, w, h);
    assert!(hidden(&half, &cam, Vec3::new(-4.0, 0.0, -20.0), 0.5));
    assert!(!hidden(&half, &cam, Vec3::new(4.0, 0.0, -20.0), 0.5));
    // Reaching the near plane, never hidden.
    assert!(!hidden(&full, &cam, Vec3::new(0.0, 0.0, -0.5), 1.0));
}

#[test]
fn a_hidden_sphere_is_behind_every_pixel_under_it() {
    // Random blocky depth buffers and spheres: whenever the test says hidden, every pixel of
    // the sphere's screen rectangle is nearer than the sphere's nearest point.
    let (w, h) = (48u32, 27u32);
    let cam = camera(w, h);
    let mut rng = Lcg(11);
    let mut judged = 0;
    for _ in 0..200 {
        let blocks: Vec<f32> = (0..16).map(|_| depth_at(&cam, 2.0 + 30.0 * rng.unit())).collect();
        let depth: Vec<f32> = (0..w * h)
            .map(|i| blocks[(((i % w) * 4 / w) + 4 * ((i / w) * 4 / h)) as usize])
            .collect();
        let pyramid = Pyramid::build(&depth, w, h);
        for _ in 0..50 {
            let centre = Vec3::new(
                rng.unit() * 30.0 - 15.0,
                rng.unit() * 16.0 - 8.0,
                -1.0 - 40.0 * rng.unit(),
            );
            let r = 0.1 + 2.0 * rng.unit();
            if !hidden(&pyramid, &cam, centre, r) {
                continue;
            }
            judged += 1;
            let (p0, p1, nearest) =
                sphere_rect(&cam, centre, r, glam::Vec2::new(w as f32, h as f32)).expect("in front");
            for y in p0.y as u32..(p1.y.ceil() as u32).min(h) {
                for x in p0.x as u32..(p1.x.ceil() as u32).min(w) {
                    assert!(
                        nearest < depth[(y * w + x) as usize],
                        "pixel ({x}, {y}) in front of a hidden sphere"
                    );
                }
            }
        }
    }
    assert!(judged > 500, "only {judged} hidden spheres judged");
}

#[test]
fn the_level_is_the_coarsest_whose_error_fits_the_spheres_depth() {
    let view = (Vec3::ZERO, Vec3::NEG_Z);
    let errors = [0.01, 0.1];
    // Budget 0.002 m per metre of depth, radius 1: depth 4 allows 0.008 (whole mesh), 9 allows
    // 0.018 (level 1), 99 allows 0.198 (level 2).
    let at = |depth: f32| level_for(&errors, view, 0.002, Vec3::new(0.0, 0.0, -depth - 1.0), 1.0);
    assert_eq!([at(4.0), at(9.0), at(99.0)], [0, 1, 2]);
    // Reaching the camera's plane, not finite, or without levels: the whole mesh.
    assert_eq!(level_for(&errors, view, 0.002, Vec3::new(0.0, 0.0, -0.5), 1.0), 0);
    assert_eq!(level_for(&errors, view, 0.002, Vec3::NAN, 1.0), 0);
    assert_eq!(level_for(&[], view, 0.002, Vec3::new(0.0, 0.0, -1000.0), 1.0), 0);
}
