//! Fixed cases of the math layer that a property test once found: kept as plain tests so they
//! run every time, whatever seed the property tests draw.

use glam::{Mat4, Vec4};
use penumbra::math::frustum::{CameraView, Frustum, slice_corners};

/// The case that made `frustum_keeps_interior_and_drops_exterior` fail once: a narrow view
/// with a 1.9 cm near plane, 1 km from the origin, and a point 6 µm from a side plane — closer
/// than f32 can place it there.
#[test]
fn frustum_keeps_a_point_by_its_edge_far_from_the_origin() {
    let cam = CameraView {
        world_from_view: Mat4::from_cols(
            Vec4::new(0.051356256, 0.78030264, -0.62328994, 0.0),
            Vec4::new(0.29735136, 0.58385986, 0.7554402, 0.0),
            Vec4::new(0.95338595, -0.22413266, -0.20203912, 0.0),
            Vec4::new(851.6982, 548.60284, -335.8526, 1.0),
        ),
        fov_y: 0.15166657,
        aspect: 0.12204229,
        near: 0.01858158,
        far: 0.058760118,
    };
    let (x, y, t) = (0.9334402f32, 0.70535207f32, 0.01f32);
    let frustum = Frustum::from_clip_from_world(cam.clip_from_world());
    let near = cam.near + (cam.far - cam.near) * t * 0.5;
    let c = slice_corners(&cam, near, near);
    let inside = c[0]
        .lerp(c[1], x * 0.5 + 0.5)
        .lerp(c[3].lerp(c[2], x * 0.5 + 0.5), y * 0.5 + 0.5);
    let rounding = 8.0 * f32::EPSILON * inside.abs().max_element();
    assert!(rounding > 1e-3 * near, "the case is below f32's resolution there");
    assert!(frustum.intersects_sphere(inside, rounding));
}
