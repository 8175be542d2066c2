//! Receiver bounds: which part of a cascade can receive a shadow. A caster can only matter
//! to a cascade if its shadow can land on a visible receiver in that cascade's slice, so
//! the cascade's cull box shrinks to the light-space bounds of those receivers (grown by
//! the filter's reach): casters under an empty sky, or beyond the farthest receiver along
//! the light, are not drawn. The shadow map's projection is not changed.

use glam::{Mat3, Mat4, Vec3};

use crate::math::aabb::Aabb;

/// One cascade's slice, for [`receiver_bounds`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slice {
    /// View depths whose receivers the cascade serves (including the blend band that also
    /// samples it).
    pub near: f32,
    /// Far end of that range.
    pub far: f32,
    /// World box of the slice's frustum corners.
    pub world: Aabb,
}

/// Grows each slice's light-space receiver bounds in `out` (one per slice, reset first) by
/// every receiver `(centre, radius, id)` whose bounding sphere's view depth range meets the
/// slice's: its world box `world_box(id)` (a ground plane is flat, its sphere is not; a group
/// of receivers on the ground is flat too), clipped to the slice's box, in light space.
pub fn receiver_bounds(
    light_rotation: &Mat3,
    view_from_world: &Mat4,
    slices: &[Slice],
    receivers: impl Iterator<Item = (Vec3, f32, usize)>,
    world_box: impl Fn(usize) -> Aabb,
    out: &mut [Aabb],
) {
    out.iter_mut().for_each(|b| *b = Aabb::EMPTY);
    let depth_row = view_from_world.row(2);
    let light_from_world = Mat4::from_mat3(*light_rotation);
    for (center, radius, id) in receivers {
        if !(center.is_finite() && radius.is_finite()) {
            continue;
        }
        let depth = -(depth_row.truncate().dot(center) + depth_row.w);
        let whole = world_box(id);
        for (slice, bound) in slices.iter().zip(out.iter_mut()) {
            if depth + radius < slice.near || depth - radius > slice.far {
                continue;
            }
            let clipped = Aabb {
                min: whole.min.max(slice.world.min),
                max: whole.max.min(slice.world.max),
            };
            if clipped.is_empty() {
                continue;
            }
            *bound = bound.union(clipped.transformed(&light_from_world));
        }
    }
}

/// The cull box `(min, max)` of a cascade (light space, `z` max towards the light) shrunk to
/// the receivers' bounds grown by `reach` on every side; the box of no caster when nothing
/// receives.
pub fn shrink_to_receivers(min: Vec3, max: Vec3, receivers: &Aabb, reach: f32) -> (Vec3, Vec3) {
    if receivers.is_empty() {
        return (Vec3::INFINITY, Vec3::NEG_INFINITY);
    }
    let lo = Vec3::new(
        min.x.max(receivers.min.x - reach),
        min.y.max(receivers.min.y - reach),
        // Casters wholly beyond the farthest receiver (away from the light) shadow nothing.
        min.z.max(receivers.min.z - reach),
    );
    let hi = Vec3::new(
        max.x.min(receivers.max.x + reach),
        max.y.min(receivers.max.y + reach),
        max.z,
    );
    if lo.x > hi.x || lo.y > hi.y || lo.z > hi.z {
        return (Vec3::INFINITY, Vec3::NEG_INFINITY);
    }
    (lo, hi)
}

/// The cull box `(min, max)` from [`shrink_to_receivers`] widened to whole cells of `grid`
/// (`x`, `y` cell sizes, `z` the depth step; [`Cascade::hold_grid`]) and cut back to the
/// cascade's `bounds`, so it changes only when the receivers' bounds cross a cell, not every
/// time they move. Unchanged where `grid` is zero or the box is empty.
///
/// [`Cascade::hold_grid`]: crate::math::cascades::Cascade::hold_grid
pub fn snap_to_grid((min, max): (Vec3, Vec3), grid: Vec3, bounds: (Vec3, Vec3)) -> (Vec3, Vec3) {
    if grid.cmple(Vec3::ZERO).any() || !grid.is_finite() || min.cmpgt(max).any() {
        return (min, max);
    }
    let lo = ((min / grid).floor() * grid).max(bounds.0);
    let hi = ((max / grid).ceil() * grid).min(bounds.1);
    // NOTE: the side towards the light stays the box's (see shrink_to_receivers).
    (lo.min(min), Vec3::new(hi.x, hi.y, max.z).max(max))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slice(near: f32, far: f32, world: Aabb) -> Slice {
        Slice { near, far, world }
    }

    #[test]
    fn receivers_fall_in_the_slices_their_depth_meets() {
        // Camera at the origin looking down -Z: view depth = -z.
        let view = Mat4::IDENTITY;
        let world = Aabb {
            min: Vec3::splat(-100.0),
            max: Vec3::splat(100.0),
        };
        let slices = [slice(0.0, 10.0, world), slice(10.0, 50.0, world)];
        let mut out = [Aabb::EMPTY; 2];
        let spheres = [(Vec3::new(1.0, 0.0, -5.0), 0.5), (Vec3::new(-3.0, 2.0, -30.0), 1.0)];
        let boxes = |i: usize| Aabb {
            min: spheres[i].0 - Vec3::splat(spheres[i].1),
            max: spheres[i].0 + Vec3::splat(spheres[i].1),
        };
        let receivers = spheres.into_iter().enumerate().map(|(i, (c, r))| (c, r, i));
        receiver_bounds(&Mat3::IDENTITY, &view, &slices, receivers, boxes, &mut out);
        assert_eq!(out[0].min, Vec3::new(0.5, -0.5, -5.5));
        assert_eq!(out[1].max, Vec3::new(-2.0, 3.0, -29.0));
        // A receiver straddling the split counts in both.
        receiver_bounds(
            &Mat3::IDENTITY,
            &view,
            &slices,
            [(Vec3::new(0.0, 0.0, -10.0), 1.0, 0)].into_iter(),
            |_| Aabb {
                min: Vec3::new(-1.0, -1.0, -11.0),
                max: Vec3::new(1.0, 1.0, -9.0),
            },
            &mut out,
        );
        assert!(!out[0].is_empty() && !out[1].is_empty());
    }

    #[test]
    fn a_huge_receiver_is_clipped_to_the_slice() {
        let world = Aabb {
            min: Vec3::new(-10.0, -1.0, -20.0),
            max: Vec3::new(10.0, 30.0, 0.0),
        };
        let mut out = [Aabb::EMPTY];
        // A 500 m ground plane under the slice: its box, not its sphere, is clipped.
        let plane = Aabb {
            min: Vec3::new(-250.0, 0.0, -250.0),
            max: Vec3::new(250.0, 0.0, 250.0),
        };
        receiver_bounds(
            &Mat3::IDENTITY,
            &Mat4::IDENTITY,
            &[slice(0.0, 20.0, world)],
            [(Vec3::new(0.0, 0.0, -10.0), 250.0, 0)].into_iter(),
            |_| plane,
            &mut out,
        );
        assert_eq!(
            out[0],
            Aabb {
                min: Vec3::new(-10.0, 0.0, -20.0),
                max: Vec3::new(10.0, 0.0, 0.0),
            }
        );
    }

    #[test]
    fn the_cull_box_widens_to_the_grid_and_holds_within_a_cell() {
        let bounds = (Vec3::new(-50.0, -50.0, -100.0), Vec3::new(50.0, 50.0, 100.0));
        let grid = Vec3::new(4.0, 2.0, 8.0);
        let a = snap_to_grid((Vec3::new(-5.0, 9.0, -21.0), Vec3::new(6.0, 21.0, 100.0)), grid, bounds);
        assert_eq!(a, (Vec3::new(-8.0, 8.0, -24.0), Vec3::new(8.0, 22.0, 100.0)));
        // Moved within the cells: the same box.
        let b = snap_to_grid((Vec3::new(-7.5, 8.5, -23.0), Vec3::new(7.9, 21.5, 100.0)), grid, bounds);
        assert_eq!(a, b);
        // Never past the cascade's box, never smaller than what it widens.
        let c = snap_to_grid(
            (Vec3::new(-49.0, 9.0, -99.0), Vec3::new(49.5, 21.0, 100.0)),
            grid,
            bounds,
        );
        assert_eq!(c.0, Vec3::new(-50.0, 8.0, -100.0));
        assert_eq!(c.1.x, 50.0);
        // No grid, or nothing to cull: unchanged.
        let empty = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        assert_eq!(snap_to_grid(empty, grid, bounds), empty);
        let d = (Vec3::new(-5.0, 9.0, -21.0), Vec3::new(6.0, 21.0, 100.0));
        assert_eq!(snap_to_grid(d, Vec3::ZERO, bounds), d);
    }

    #[test]
    fn the_cull_box_shrinks_to_the_receivers_and_empties_without_them() {
        let (min, max) = (Vec3::new(-50.0, -50.0, -100.0), Vec3::new(50.0, 50.0, 100.0));
        let receivers = Aabb {
            min: Vec3::new(-5.0, 10.0, -20.0),
            max: Vec3::new(5.0, 20.0, 0.0),
        };
        let (lo, hi) = shrink_to_receivers(min, max, &receivers, 1.0);
        assert_eq!(lo, Vec3::new(-6.0, 9.0, -21.0));
        // Towards the light the box is kept: casters above the receivers shadow them.
        assert_eq!(hi, Vec3::new(6.0, 21.0, 100.0));
        let (lo, hi) = shrink_to_receivers(min, max, &Aabb::EMPTY, 1.0);
        assert!(lo.x > hi.x);
    }
}
