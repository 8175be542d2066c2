//! The render origin: a point near the camera, snapped to a coarse grid, that every position
//! handed to the GPU is made relative to. Far from the world origin (1e5–1e6 m) f32 world
//! coordinates still place objects to within a few centimetres, but products of large
//! coordinates with projection matrices do not; relative coordinates keep the GPU's
//! arithmetic on small numbers. Subtracting a grid-aligned origin from an f32 position is
//! exact, so nothing moves; the origin changes only when the camera crosses a cell.

use bevy_ecs::resource::Resource;
use bevy_ecs::system::{Query, ResMut};
use bevy_transform::components::GlobalTransform;
use glam::Vec3;

use crate::ecs::components::Camera3d;

/// Size of the origin grid in metres (a power of two, so grid points are exact in f32).
pub const ORIGIN_CELL: f32 = 1024.0;

/// The current render origin (world position that maps to (0, 0, 0) on the GPU).
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderOrigin(pub Vec3);

/// The grid point nearest to `p` (zero for non-finite input).
pub fn snap_origin(p: Vec3) -> Vec3 {
    if !p.is_finite() {
        return Vec3::ZERO;
    }
    (p / ORIGIN_CELL).round() * ORIGIN_CELL
}

/// Moves the origin to the grid point nearest the first camera.
pub fn update_render_origin(cameras: Query<(&Camera3d, &GlobalTransform)>, mut origin: ResMut<RenderOrigin>) {
    let Some((_, t)) = cameras.iter().find(|(_, t)| t.translation().is_finite()) else {
        return;
    };
    let snapped = snap_origin(t.translation());
    if origin.0 != snapped {
        origin.0 = snapped;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn origin_snaps_to_the_grid_and_subtraction_is_exact() {
        assert_eq!(
            snap_origin(Vec3::new(100.0, -600.0, 1.0e6)),
            Vec3::new(0.0, -1024.0, 1_000_448.0)
        );
        assert_eq!(snap_origin(Vec3::NAN), Vec3::ZERO);
        // A position 1e6 m out keeps its exact f32 value relative to the origin.
        let p = Vec3::new(1.0e6 + 0.0625, 3.5, -1.0e6 + 0.0625);
        let o = snap_origin(p);
        let relative = p - o;
        assert_eq!(relative + o, p);
        assert!(relative.abs().max_element() <= ORIGIN_CELL * 0.5);
    }
}
