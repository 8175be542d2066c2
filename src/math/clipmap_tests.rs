use glam::{I64Vec2, Vec2, Vec3};

use super::*;

/// A small deterministic generator for the property tests.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next()
    }
}

fn input(camera: Vec3) -> ClipmapInput {
    ClipmapInput {
        camera_position: camera,
        light_direction: Vec3::new(-0.4, -1.0, -0.3),
        levels: 6,
        level0_extent: 32.0,
        resolution: 1024,
        casters: Aabb {
            min: Vec3::new(-500.0, 0.0, -500.0),
            max: Vec3::new(500.0, 40.0, 500.0),
        },
    }
}

#[test]
fn levels_double_and_nest_around_the_camera() {
    let camera = Vec3::new(13.7, 1.8, -250.3);
    let set = compute_clipmap(&input(camera));
    assert_eq!(set.count, 6);
    let eye = light_xy(&set, camera);
    for (i, level) in set.active().iter().enumerate() {
        assert_eq!(level.extent, 32.0 * (1 << i) as f32);
        assert_eq!(level.texel, level.extent / 1024.0);
        let centre = (level.min() + level.max()) * 0.5;
        assert!(
            (centre - eye).abs().max_element() <= 0.5 * level.texel + 1e-3,
            "level {i}"
        );
        if let Some(outer) = set.active().get(i + 1) {
            assert!(level.min().cmpge(outer.min()).all() && level.max().cmple(outer.max()).all());
        }
    }
}

#[test]
fn camera_moves_shift_windows_by_whole_texels_and_keep_the_depth_range() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let base = compute_clipmap(&input(Vec3::ZERO));
    let mut checked = 0;
    for _ in 0..500 {
        let camera = Vec3::new(rng.range(-400.0, 400.0), rng.range(0.5, 30.0), rng.range(-400.0, 400.0));
        let set = compute_clipmap(&input(camera));
        for (level, first) in set.active().iter().zip(base.active()) {
            // Same texel size and depth: the grid is fixed; only the window's start moves.
            assert_eq!(
                (level.texel, level.z_min, level.depth),
                (first.texel, first.z_min, first.depth)
            );
            // The same grid texel maps to the same clip x, y in every frame up to the
            // window's whole-texel shift.
            let shift = (level.first_texel - first.first_texel).as_vec2();
            let p = grid_point(&set, level, level.first_texel + I64Vec2::new(7, 9), 0.0);
            let clip = level.clip_from_world.project_point3(p).truncate();
            let before = first.clip_from_world.project_point3(p).truncate();
            let expected = before - shift * 2.0 / 1024.0;
            assert!((clip - expected).abs().max_element() < 1e-3, "{clip} vs {expected}");
            checked += 1;
        }
    }
    assert_eq!(checked, 3000);
}

#[test]
fn the_window_and_the_depth_range_map_to_the_edges_of_clip_space() {
    let set = compute_clipmap(&input(Vec3::new(5.0, 2.0, 5.0)));
    let casters = input(Vec3::ZERO).casters;
    for level in set.active() {
        let corner = grid_point(&set, level, level.first_texel, level.z_min);
        let far = grid_point(
            &set,
            level,
            level.first_texel + I64Vec2::splat(1024),
            level.z_min + level.depth,
        );
        let a = level.clip_from_world.project_point3(corner);
        let b = level.clip_from_world.project_point3(far);
        assert!((a - Vec3::new(-1.0, -1.0, 0.0)).abs().max_element() < 1e-4, "{a}");
        assert!((b - Vec3::new(1.0, 1.0, 1.0)).abs().max_element() < 1e-4, "{b}");
        for c in casters.corners() {
            let depth = level.clip_from_world.project_point3(c).z;
            assert!((0.0..=1.0).contains(&depth), "caster corner {c} at depth {depth}");
        }
    }
}

#[test]
fn a_receiver_samples_the_finest_level_that_holds_it() {
    let camera = Vec3::new(0.3, 1.7, 0.2);
    let set = compute_clipmap(&input(camera));
    let eye = light_xy(&set, camera);
    assert_eq!(select_level(&set, eye, 2.0, 0.1), Some((0, 0.0)));
    // Just inside level 2's window, far outside level 1's: level 2, blending into 3.
    let edge = set.levels[2].max().x - 3.0 * set.levels[2].texel;
    let (level, blend) = select_level(&set, Vec2::new(edge, eye.y), 2.0, 0.1).unwrap();
    assert_eq!(level, 2);
    assert!(blend > 0.9, "{blend}");
    // Outside every level.
    assert_eq!(select_level(&set, eye + Vec2::splat(5000.0), 2.0, 0.1), None);
    // Random points: the level chosen holds the point with the margin, the one below does not.
    let mut rng = Rng(42);
    for _ in 0..1000 {
        let p = eye + Vec2::new(rng.range(-1100.0, 1100.0), rng.range(-1100.0, 1100.0));
        let Some((i, blend)) = select_level(&set, p, 2.0, 0.1) else {
            let last = &set.levels[set.count - 1];
            assert!(p.cmplt(last.min() + 2.0 * last.texel).any() || p.cmpgt(last.max() - 2.0 * last.texel).any());
            continue;
        };
        let l = &set.levels[i];
        assert!(p.cmpge(l.min() + 2.0 * l.texel).all() && p.cmple(l.max() - 2.0 * l.texel).all());
        assert!((0.0..=1.0).contains(&blend));
        if i > 0 {
            let below = &set.levels[i - 1];
            let inside =
                p.cmpge(below.min() + 2.0 * below.texel).all() && p.cmple(below.max() - 2.0 * below.texel).all();
            assert!(!inside, "{p} fits level {} but got {i}", i - 1);
        }
    }
}

#[test]
fn a_moving_window_exposes_only_the_strips_it_did_not_cover() {
    let n = 64;
    let old = GridRect {
        min: I64Vec2::new(-32, -32),
        max: I64Vec2::new(32, 32),
    };
    for (dx, dy) in [(0, 0), (3, 0), (0, -5), (4, 7), (-63, 2), (64, 0), (200, -300)] {
        let new = GridRect {
            min: old.min + I64Vec2::new(dx, dy),
            max: old.max + I64Vec2::new(dx, dy),
        };
        let mut strips = Vec::new();
        exposed_strips(&old, &new, &mut strips);
        let area: u64 = strips.iter().map(GridRect::area).sum();
        let expected = new.area() - old.intersect(&new).area();
        assert_eq!(area, expected, "move ({dx}, {dy})");
        for (i, s) in strips.iter().enumerate() {
            assert_eq!(s.intersect(&old).area(), 0, "strip {i} redraws kept texels");
            assert_eq!(s.intersect(&new).area(), s.area(), "strip {i} leaves the window");
            for t in &strips[i + 1..] {
                assert_eq!(s.intersect(t).area(), 0, "strips overlap");
            }
        }
        if dx.abs() < n && dy.abs() < n {
            assert_eq!(area as i64, n * dx.abs() + n * dy.abs() - dx.abs() * dy.abs());
        }
    }
}

#[test]
fn as_cascades_each_level_keeps_its_window_texel_and_depth() {
    let set = compute_clipmap(&input(Vec3::new(3.0, 2.0, 1.0)));
    let cascades = clipmap_cascades(&set, 0.0093);
    assert!(cascades.clipmap);
    assert_eq!(cascades.count, set.count);
    for (c, level) in cascades.active().iter().zip(set.active()) {
        assert_eq!(c.clip_from_world, level.clip_from_world);
        assert_eq!(c.texel_world_size, level.texel);
        assert!(c.light_min.truncate().cmple(level.min()).all() && c.light_max.truncate().cmpge(level.max()).all());
        assert!(c.pcss_scale > 0.0 && c.light_size_uv > 0.0);
    }
    let last = set.active().last().unwrap();
    assert!(cascades.end >= last.extent * 0.5 * 2f32.sqrt());
}

#[test]
fn wrapped_parts_cover_a_rect_once_where_its_window_lies_in_the_layer() {
    let side = 16u32;
    let rects = [
        TexelRect {
            x0: 0,
            y0: 0,
            x1: 16,
            y1: 16,
        },
        TexelRect {
            x0: 3,
            y0: 10,
            x1: 9,
            y1: 16,
        },
        TexelRect {
            x0: 15,
            y0: 0,
            x1: 16,
            y1: 1,
        },
        TexelRect {
            x0: 4,
            y0: 4,
            x1: 4,
            y1: 9,
        },
    ];
    for rect in rects {
        for origin in [[0, 0], [5, 0], [0, 11], [7, 13], [15, 15]] {
            let mut hits = vec![0u32; (side * side) as usize];
            let mut parts = 0;
            for ([vx, vy], part) in wrapped_parts(rect, origin, side) {
                parts += 1;
                assert!(part.x1 <= side && part.y1 <= side && part.area() > 0, "{part:?}");
                for y in part.y0..part.y1 {
                    for x in part.x0..part.x1 {
                        // The window texel drawn at this layer texel with this viewport.
                        let (wx, wy) = (i64::from(x) - vx, i64::from(y) - vy);
                        assert!((0..16).contains(&wx) && (0..16).contains(&wy), "{origin:?} {part:?}");
                        let (wx, wy) = (wx as u32, wy as u32);
                        assert!(rect.x0 <= wx && wx < rect.x1 && rect.y0 <= wy && wy < rect.y1);
                        // It is the layer texel the window texel wraps to.
                        assert_eq!((x, y), ((wx + origin[0]) % side, (wy + origin[1]) % side));
                        hits[(y * side + x) as usize] += 1;
                    }
                }
            }
            assert!(parts <= 4);
            let covered: u64 = hits.iter().map(|&h| u64::from(h)).sum();
            assert_eq!(covered, rect.area(), "{rect:?} at {origin:?}");
            assert!(
                hits.iter().all(|&h| h <= 1),
                "{rect:?} at {origin:?}: a texel drawn twice"
            );
        }
    }
}
