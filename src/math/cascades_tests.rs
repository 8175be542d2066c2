//! Unit tests of [`super`]: boxes fitted, projected, snapped and kept finite.

use super::*;
use crate::math::frustum::slice_corners;
use crate::math::light_space::light_from_world;
use crate::math::projection::ortho_reverse_z;
use glam::Quat;

fn input(fit: CascadeFit) -> CascadeInput {
    CascadeInput {
        camera: CameraView {
            world_from_view: Mat4::from_rotation_translation(
                Quat::from_euler(glam::EulerRot::YXZ, 0.6, -0.2, 0.0),
                Vec3::new(12.0, 1.8, -40.0),
            ),
            fov_y: 1.0,
            aspect: 16.0 / 9.0,
            near: 0.1,
            far: 1000.0,
        },
        light_direction: Vec3::new(0.3, -0.8, 0.5),
        scene_bounds: Aabb::new(Vec3::new(-200.0, -5.0, -200.0), Vec3::new(200.0, 60.0, 200.0)),
        receiver_bounds: Aabb::EMPTY,
        count: 4,
        split_lambda: 0.6,
        max_distance: 150.0,
        resolution: 2048,
        fit,
        angular_diameter: 0.0093,
        blend_width: 0.0,
        snap_cells: 0,
        scroll: false,
        seen: None,
    }
}

fn project(m: Mat4, p: Vec3) -> Vec3 {
    (m * p.extend(1.0)).truncate()
}

#[test]
fn slices_fit_inside_their_boxes() {
    for fit in [CascadeFit::Tight, CascadeFit::Stable] {
        let inp = input(fit);
        let set = compute_cascades(&inp);
        assert_eq!(set.count, 4);
        assert_eq!(set.splits[0], 0.1);
        assert_eq!(set.splits[4], 150.0);
        for (i, c) in set.active().iter().enumerate() {
            assert_eq!((c.near, c.far), (set.splits[i], set.splits[i + 1]));
            for p in slice_corners(&inp.camera, c.near, c.far) {
                let q = project(c.clip_from_world, p);
                assert!(q.x.abs() <= 1.0 + 1e-5 && q.y.abs() <= 1.0 + 1e-5, "{i} {q}");
                assert!(q.z >= -1e-5 && q.z <= 1.0 + 1e-5, "{i} {q}");
                let l = set.light_rotation * p;
                assert!(l.cmpge(c.light_min - 1e-4).all() && l.cmple(c.light_max + 1e-4).all());
            }
        }
    }
}

#[test]
fn matrix_is_ortho_times_light_view_of_the_box() {
    let set = compute_cascades(&input(CascadeFit::Tight));
    for c in set.active() {
        let (lo, hi) = (c.light_min, c.light_max);
        // The light looks down −Z, so near distance = −z_max and far distance = −z_min.
        let want =
            ortho_reverse_z(lo.x, hi.x, lo.y, hi.y, -hi.z, -lo.z) * light_from_world(set.light_rotation, Vec3::ZERO);
        for p in [Vec3::new(3.0, 2.0, 1.0), Vec3::new(-50.0, 10.0, -80.0)] {
            let a = project(c.clip_from_world, p);
            let b = project(want, p);
            assert!(a.abs_diff_eq(b, 1e-4), "{a} vs {b}");
        }
    }
}

#[test]
fn near_plane_reaches_the_scene_casters() {
    let inp = input(CascadeFit::Tight);
    let set = compute_cascades(&inp);
    let top = inp
        .scene_bounds
        .corners()
        .map(|p| (set.light_rotation * p).z)
        .into_iter()
        .fold(f32::MIN, f32::max);
    for c in set.active() {
        assert!(c.light_max.z >= top - 1e-3, "{} < {top}", c.light_max.z);
    }
    // The slice's corners lie in the receiver span [receiver_start, 1] of the box's depth.
    for (c, i) in set.active().iter().zip(0..) {
        assert!(c.receiver_start > 0.0 && c.receiver_start < 1.0, "{c:?}");
        for p in slice_corners(&inp.camera, c.near, c.far) {
            let d = 1.0 - project(c.clip_from_world, p).z;
            assert!(d >= c.receiver_start - 1e-5 && d <= 1.0 + 1e-5, "cascade {i}: {d}");
        }
    }
    // Without scene bounds the box is only as deep as the slice.
    let bare = compute_cascades(&CascadeInput {
        scene_bounds: Aabb::EMPTY,
        ..inp
    });
    for (a, b) in bare.active().iter().zip(set.active()) {
        // The receivers start at its light side, raised by under a depth step.
        assert!(a.receiver_start * a.depth_range <= a.hold_grid.z, "{a:?}");
        assert!(a.depth_range < b.depth_range);
        // Both far sides are the slice's, each snapped down by less than its depth step.
        let step = a.hold_grid.z.max(b.hold_grid.z);
        assert!((a.light_min.z - b.light_min.z).abs() <= step, "{a:?} {b:?}");
    }
}

#[test]
fn derived_values_follow_their_formulas() {
    let inp = input(CascadeFit::Tight);
    let set = compute_cascades(&inp);
    for c in set.active() {
        let wx = c.light_max.x - c.light_min.x;
        let wy = c.light_max.y - c.light_min.y;
        assert!((c.texel_world_size - wx / 2048.0).abs() <= 1e-5 * wx);
        assert!((c.depth_range - (c.light_max.z - c.light_min.z)).abs() <= 1e-4);
        let s = 2.0 * (inp.angular_diameter * 0.5).tan();
        assert!((c.light_size_uv - s / wx).abs() <= 1e-5 * c.light_size_uv);
        assert!((c.pcss_scale - c.depth_range * s / wx).abs() <= 1e-5 * c.pcss_scale);
        assert!((c.uv_scale_y - wx / wy).abs() <= 1e-5);
        // Texel size from the matrix's first row, as in the seed: 2·(1/res)/|row0|.
        let row0 = c.clip_from_world.row(0).truncate().length();
        assert!((2.0 / 2048.0 / row0 - c.texel_world_size).abs() <= 1e-5 * wx);
    }
}

#[test]
fn stable_boxes_are_square_and_unused_cascades_default() {
    let set = compute_cascades(&CascadeInput {
        count: 2,
        ..input(CascadeFit::Stable)
    });
    assert_eq!(set.count, 2);
    for c in set.active() {
        assert_eq!(c.uv_scale_y, 1.0);
    }
    assert_eq!(set.cascades[2], Cascade::default());
    assert_eq!(set.splits[2..], [150.0; 3]);
    assert_eq!(set.far_splits(), Vec4::new(set.splits[1], 150.0, 150.0, 150.0));
}

#[test]
fn snapping_moves_by_whole_texels() {
    let inp = input(CascadeFit::Tight);
    let a = compute_cascades(&inp);
    let mut moved = inp;
    let t = a.cascades[0].texel_world_size;
    moved.camera.world_from_view.w_axis += Vec4::new(0.37 * t, -0.21 * t, 0.44 * t, 0.0);
    let b = compute_cascades(&moved);
    let p = Vec3::new(20.0, 0.0, -60.0);
    for (ca, cb) in a.active().iter().zip(b.active()) {
        let ua = project(ca.clip_from_world, p).truncate().as_dvec2() * 1024.0;
        let ub = project(cb.clip_from_world, p).truncate().as_dvec2() * 1024.0;
        let d = ub - ua;
        assert!((d - d.round()).abs().max_element() < 1e-3, "{d}");
    }
}

#[test]
fn degenerate_inputs_stay_finite() {
    let mut inp = input(CascadeFit::Tight);
    inp.light_direction = Vec3::ZERO;
    inp.camera.fov_y = 0.0;
    inp.camera.aspect = 0.0;
    inp.camera.near = 0.0;
    inp.camera.far = 0.0;
    inp.resolution = 0;
    inp.count = 0;
    inp.angular_diameter = f32::NAN;
    inp.scene_bounds = Aabb::new(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX));
    let mut far_away = inp;
    far_away.camera.near = 1e38;
    far_away.camera.far = f32::MAX;
    far_away.camera.fov_y = std::f32::consts::PI;
    far_away.camera.aspect = f32::MAX;
    far_away.max_distance = f32::MAX;
    far_away.camera.world_from_view.w_axis = Vec4::new(f32::MAX, -f32::MAX, f32::MAX, 1.0);
    far_away.light_direction = Vec3::new(1.0, 1.0, 1.0);
    for fit in [CascadeFit::Tight, CascadeFit::Stable] {
        for base in [inp, far_away] {
            let set = compute_cascades(&CascadeInput { fit, ..base });
            assert_eq!(set.count, 1);
            let c = set.cascades[0];
            assert!(c.clip_from_world.is_finite() && c.light_min.is_finite(), "{c:?}");
            assert!(c.light_max.is_finite(), "{c:?}");
            assert!(c.texel_world_size > 0.0 && c.depth_range > 0.0, "{c:?}");
            assert!(c.light_max.cmpgt(c.light_min).all(), "{c:?}");
        }
    }
}

/// How many of `frames` steps of `step` metres along the camera's view change each
/// cascade's matrix, with `snap_cells` cells; each frame's slices are checked to lie inside
/// their boxes.
fn walk_changes(fit: CascadeFit, snap_cells: u32, frames: usize, step: f32) -> [usize; MAX_CASCADES] {
    let mut inp = input(fit);
    inp.snap_cells = snap_cells;
    let forward = -inp.camera.world_from_view.z_axis.truncate() * step;
    let mut last = compute_cascades(&inp);
    let mut changes = [0; MAX_CASCADES];
    for _ in 0..frames {
        inp.camera.world_from_view.w_axis += forward.extend(0.0);
        let set = compute_cascades(&inp);
        for (i, c) in set.active().iter().enumerate() {
            changes[i] += usize::from(c.clip_from_world != last.cascades[i].clip_from_world);
            for p in slice_corners(&inp.camera, c.near, c.far) {
                let q = project(c.clip_from_world, p);
                assert!(q.x.abs() <= 1.0 + 1e-5 && q.y.abs() <= 1.0 + 1e-5, "{i} {q}");
                assert!(q.z >= -1e-5 && q.z <= 1.0 + 1e-5, "{i} {q}");
            }
        }
        last = set;
    }
    changes
}

#[test]
fn boxes_hold_while_the_camera_walks_within_a_cell() {
    for fit in [CascadeFit::Tight, CascadeFit::Stable] {
        let free = walk_changes(fit, 0, 100, 0.37);
        let cells = walk_changes(fit, 16, 100, 0.37);
        println!("{fit:?}: matrices changed in 100 frames, free cells {free:?}, 16 cells {cells:?}");
        // A box moves once per cell crossed (laterally or in depth), so the widest cascade
        // moves least; 16 cells (a 16th of a box) move it a few times in 37 m.
        assert!(free.iter().sum::<usize>() < 300, "{free:?}");
        assert!(cells[0] < 100 && cells[3] <= 12, "{cells:?}");
        assert!(cells[3] <= cells[0] && free[3] <= free[0], "{cells:?} {free:?}");
        assert!(
            cells.iter().sum::<usize>() < free.iter().sum::<usize>(),
            "{cells:?} {free:?}"
        );
    }
}

#[test]
fn a_held_box_reports_its_grid() {
    let mut inp = input(CascadeFit::Tight);
    for (cells, fewest) in [(0, 1.0), (16, 128.0)] {
        inp.snap_cells = cells;
        for c in compute_cascades(&inp).active() {
            // A cell is whole texels, at least 2048 / 16 = 128 with 16 cells; the box starts
            // on one.
            let texels = c.hold_grid.x / c.texel_world_size;
            assert!(
                texels >= fewest - 1e-3 && (texels - texels.round()).abs() < 1e-3,
                "{texels}"
            );
            assert!(c.hold_grid.z > 0.0);
            let start = c.light_min.x / c.hold_grid.x;
            assert!((start - start.round()).abs() < 1e-3, "{start}");
        }
    }
}

#[test]
fn the_coarsest_depth_step_is_that_of_the_cascade_with_the_most_depth_per_texel() {
    let set = compute_cascades(&input(CascadeFit::Tight));
    let per_cascade: Vec<f32> = set
        .active()
        .iter()
        .map(|c| c.depth_range / 65_535.0 / c.texel_world_size)
        .collect();
    let coarsest = set.depth_step_in_texels(65_535.0);
    assert_eq!(per_cascade.len(), 4);
    assert!(
        per_cascade.iter().all(|&s| s > 0.0 && s <= coarsest),
        "{per_cascade:?} {coarsest}"
    );
    assert!(per_cascade.contains(&coarsest), "{per_cascade:?} {coarsest}");
    // A sun spanning 100 times the scene's depth steps 100 times as coarsely.
    let mut deep = input(CascadeFit::Tight);
    deep.scene_bounds = Aabb::new(
        Vec3::new(-20_000.0, -5.0, -20_000.0),
        Vec3::new(20_000.0, 60.0, 20_000.0),
    );
    let deep = compute_cascades(&deep).depth_step_in_texels(65_535.0);
    assert!(deep > 10.0 * coarsest, "{deep} against {coarsest}");
    assert_eq!(CascadeSet::default().depth_step_in_texels(65_535.0), 0.0);
}

#[test]
fn scrolling_boxes_step_their_depth_range_no_more_often_and_lie_on_their_grid() {
    let mut changed = [0usize; 2];
    let mut inp = input(CascadeFit::Tight);
    let forward = -inp.camera.world_from_view.z_axis.truncate() * 0.37;
    let mut last = [
        compute_cascades(&inp),
        compute_cascades(&CascadeInput { scroll: true, ..inp }),
    ];
    assert!(!last[0].scrolls && last[1].scrolls);
    for _ in 0..100 {
        inp.camera.world_from_view.w_axis += forward.extend(0.0);
        let sets = [
            compute_cascades(&inp),
            compute_cascades(&CascadeInput { scroll: true, ..inp }),
        ];
        for (k, set) in sets.iter().enumerate() {
            for (c, before) in set.active().iter().zip(last[k].active()) {
                changed[k] += usize::from(
                    TexelGrid::at_origin(c.clip_from_world) != TexelGrid::at_origin(before.clip_from_world),
                );
                // The matrix starts the box at its grid's first texel, exactly.
                let first = c.grid.first_texel.as_vec2();
                assert_eq!(c.clip_from_world.w_axis.x, -2.0 * first.x / 2048.0 - 1.0, "{c:?}");
                assert_eq!(c.clip_from_world.w_axis.y, -2.0 * first.y / 2048.0 - 1.0, "{c:?}");
                assert_eq!(c.grid.texel.x, c.texel_world_size);
            }
        }
        for (held, scrolling) in sets[0].active().iter().zip(sets[1].active()) {
            // A scrolling box steps its depth by its cell or a 64th of its width, the longer
            // (within a 64th of its range).
            let width =
                (scrolling.light_max.x - scrolling.light_min.x).min(scrolling.light_max.y - scrolling.light_min.y);
            let step = scrolling.hold_grid.z;
            assert!(step >= held.hold_grid.z * 0.999, "{step} against {}", held.hold_grid.z);
            assert!(
                step >= (width / 64.0).min(scrolling.depth_range / 66.0) * 0.999,
                "{step} {width}"
            );
        }
        last = sets;
    }
    println!(
        "boxes changed size or depth range {} times held, {} scrolling",
        changed[0], changed[1]
    );
    assert!(changed[1] <= changed[0], "{changed:?}");
}
