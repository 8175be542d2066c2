//! Reverse-Z projection matrices for wgpu's `[0, 1]` depth range, and the NDC → texture-UV
//! mapping.
//!
//! Both projections are right-handed and look down view-space −Z; `near` and `far` are
//! positive distances along the view direction. The near plane maps to depth 1 and the far
//! plane to depth 0, so depth buffers are cleared to 0 and compared with `Greater`.

use glam::{DMat4, DVec4, Mat4, Vec2};

/// Orthographic reverse-Z projection of the view-space box `[left, right] × [bottom, top] ×
/// [−far, −near]`: x and y map to `[−1, 1]` (+y up), the plane `z = −near` to depth 1 and
/// `z = −far` to depth 0.
///
/// `near` may be negative or zero (the box may reach behind the eye); it must differ from
/// `far`, and `left != right`, `bottom != top`.
pub fn ortho_reverse_z(left: f32, right: f32, bottom: f32, top: f32, near: f32, far: f32) -> Mat4 {
    ortho_reverse_z_f64(
        f64::from(left),
        f64::from(right),
        f64::from(bottom),
        f64::from(top),
        f64::from(near),
        f64::from(far),
    )
    .as_mat4()
}

/// [`ortho_reverse_z`] in f64.
pub(crate) fn ortho_reverse_z_f64(left: f64, right: f64, bottom: f64, top: f64, near: f64, far: f64) -> DMat4 {
    let rw = 1.0 / (right - left);
    let rh = 1.0 / (top - bottom);
    // depth = a·z + b with a·(−near) + b = 1 and a·(−far) + b = 0.
    let rd = 1.0 / (far - near);
    DMat4::from_cols(
        DVec4::new(2.0 * rw, 0.0, 0.0, 0.0),
        DVec4::new(0.0, 2.0 * rh, 0.0, 0.0),
        DVec4::new(0.0, 0.0, rd, 0.0),
        DVec4::new(-(right + left) * rw, -(top + bottom) * rh, far * rd, 1.0),
    )
}

/// Perspective reverse-Z projection: vertical field of view `fov_y` (radians), `aspect` =
/// width / height, near plane (distance `near`) to depth 1, far plane (distance `far`) to
/// depth 0. Requires `0 < near < far` and `0 < fov_y < π`.
pub fn perspective_reverse_z(fov_y: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    let (n, f) = (f64::from(near), f64::from(far));
    let y = 1.0 / (0.5 * f64::from(fov_y)).tan();
    let x = y / f64::from(aspect);
    // depth = (A·z + B) / −z with depth(−n) = 1 and depth(−f) = 0.
    let a = n / (f - n);
    DMat4::from_cols(
        DVec4::new(x, 0.0, 0.0, 0.0),
        DVec4::new(0.0, y, 0.0, 0.0),
        DVec4::new(0.0, 0.0, a, -1.0),
        DVec4::new(0.0, 0.0, a * f, 0.0),
    )
    .as_mat4()
}

/// Texture coordinates of an NDC point: `u = x·0.5 + 0.5`, `v = 0.5 − y·0.5` (NDC +y is up,
/// texture v grows downwards, row 0 is the top row that NDC y = +1 rasterises to).
pub fn ndc_to_uv(ndc: Vec2) -> Vec2 {
    Vec2::new(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5)
}

/// Inverse of [`ndc_to_uv`].
pub fn uv_to_ndc(uv: Vec2) -> Vec2 {
    Vec2::new(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec3, Vec4};

    fn project(m: Mat4, p: Vec3) -> Vec3 {
        let c = m * p.extend(1.0);
        c.truncate() / c.w
    }

    #[test]
    fn ortho_maps_near_to_one_and_far_to_zero() {
        let m = ortho_reverse_z(-2.0, 6.0, -1.0, 3.0, 0.5, 10.5);
        let near = project(m, Vec3::new(-2.0, -1.0, -0.5));
        let far = project(m, Vec3::new(6.0, 3.0, -10.5));
        assert!(near.abs_diff_eq(Vec3::new(-1.0, -1.0, 1.0), 1e-6), "{near}");
        assert!(far.abs_diff_eq(Vec3::new(1.0, 1.0, 0.0), 1e-6), "{far}");
        let mid = project(m, Vec3::new(2.0, 1.0, -5.5));
        assert!(mid.abs_diff_eq(Vec3::new(0.0, 0.0, 0.5), 1e-6), "{mid}");
        assert_eq!((m * Vec4::new(1.0, 2.0, 3.0, 1.0)).w, 1.0);
    }

    #[test]
    fn ortho_allows_a_box_behind_the_eye() {
        let m = ortho_reverse_z(-1.0, 1.0, -1.0, 1.0, -5.0, 5.0);
        assert!((project(m, Vec3::new(0.0, 0.0, 5.0)).z - 1.0).abs() < 1e-6);
        assert!(project(m, Vec3::new(0.0, 0.0, -5.0)).z.abs() < 1e-6);
    }

    #[test]
    fn perspective_maps_near_to_one_and_far_to_zero() {
        let (fov, aspect, n, f) = (1.0_f32, 1.5, 0.1, 500.0);
        let m = perspective_reverse_z(fov, aspect, n, f);
        assert!((project(m, Vec3::new(0.0, 0.0, -n)).z - 1.0).abs() < 1e-6);
        assert!(project(m, Vec3::new(0.0, 0.0, -f)).z.abs() < 1e-6);
        // The top-right edge of the frustum at depth 7 lands on NDC (1, 1).
        let t = (fov * 0.5).tan() * 7.0;
        let edge = project(m, Vec3::new(t * aspect, t, -7.0));
        assert!(edge.truncate().abs_diff_eq(glam::Vec2::ONE, 1e-5), "{edge}");
        // Depth decreases with distance.
        assert!(project(m, Vec3::new(0.0, 0.0, -1.0)).z > project(m, Vec3::new(0.0, 0.0, -2.0)).z);
        // Same matrix as glam's with near and far swapped.
        let g = glam::camera::rh::proj::directx::perspective(fov, aspect, f, n);
        assert!(m.abs_diff_eq(g, 1e-5), "{m} vs {g}");
    }

    #[test]
    fn uv_convention() {
        assert_eq!(ndc_to_uv(Vec2::new(-1.0, 1.0)), Vec2::new(0.0, 0.0));
        assert_eq!(ndc_to_uv(Vec2::new(1.0, -1.0)), Vec2::new(1.0, 1.0));
        assert_eq!(ndc_to_uv(Vec2::ZERO), Vec2::splat(0.5));
        let p = Vec2::new(0.25, -0.625);
        assert_eq!(uv_to_ndc(ndc_to_uv(p)), p);
    }
}
