//! The light-space frame of a directional light: a rotation in which the light travels along
//! −Z (it "looks" down −Z like a camera), with x and y as the lateral axes.

use glam::{DMat3, DVec3, Mat3, Mat4, Vec3};

/// `|dot(direction, Y)|` above which the reference up vector switches from +Y to −Z.
pub const VERTICAL_THRESHOLD: f64 = 0.99;

/// The light-space rotation (`light_from_world`, rotation only) of a light travelling along
/// `direction`.
///
/// Rows are the light's world-space axes: `z = −direction`, `x = normalize(up_ref × z)`,
/// `y = z × x`, with `up_ref = +Y`, or `−Z` when `|direction.y| > 0.99`. So
/// `light_rotation(d) * d = −Z`, and for a light that is not vertical, light-space +y points
/// as far "up" (+Y) as possible. For the sun straight down, light x = world +X and light y =
/// world −Z, which is the limit of the +Y construction for a sun tilting towards −Z.
///
/// The direction is normalised; a zero, non-finite or denormal direction (a caller error)
/// is treated as straight down, so the result is always a finite orthonormal matrix.
pub fn light_rotation(direction: Vec3) -> Mat3 {
    light_rotation_f64(direction).as_mat3()
}

/// [`light_rotation`] in f64.
fn light_rotation_f64(direction: Vec3) -> DMat3 {
    // NOTE: normalised in f64 so that tiny (even denormal) or huge f32 directions keep their
    // full precision; only a zero or non-finite length falls back to straight down.
    let d = direction.as_dvec3().normalize_or(DVec3::NEG_Y);
    let z = -d;
    // NOTE: the cross product below has length sqrt(1 − dot(up_ref, z)²); the switch keeps
    // that at least sqrt(1 − 0.99²) ≈ 0.14, so normalising never amplifies rounding much.
    let up_ref = if d.y.abs() > VERTICAL_THRESHOLD {
        DVec3::NEG_Z
    } else {
        DVec3::Y
    };
    let x = up_ref.cross(z).normalize();
    let y = z.cross(x);
    // Rows x, y, z: light_from_world = transpose of the basis matrix.
    DMat3::from_cols(x, y, z).transpose()
}

/// The full light-space transform: `rotation` applied after moving `origin` to zero, i.e.
/// `light_from_world(r, o) * p = r * (p − o)`.
pub fn light_from_world(rotation: Mat3, origin: Vec3) -> Mat4 {
    let t = -(rotation.as_dmat3() * origin.as_dvec3());
    Mat4::from_mat3_translation(rotation, t.as_vec3())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_orthonormal(m: Mat3) {
        let p = m * m.transpose();
        assert!(p.abs_diff_eq(Mat3::IDENTITY, 1e-6), "{m}");
        assert!((m.determinant() - 1.0).abs() < 1e-6, "{m}");
    }

    #[test]
    fn maps_direction_to_minus_z_and_is_orthonormal() {
        for d in [
            Vec3::new(0.3, -1.0, 0.2),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(-0.2, 0.5, 0.9),
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.01, -1.0, 0.0),
            Vec3::new(0.0, -1.0, 0.1415),
            Vec3::new(1e-30, -3e-30, 0.0),
            Vec3::new(1e30, 2e30, -1e30),
        ] {
            let r = light_rotation(d);
            assert_orthonormal(r);
            let got = r * d.as_dvec3().normalize().as_vec3();
            assert!(got.abs_diff_eq(Vec3::NEG_Z, 1e-6), "{d}: {got}");
        }
    }

    #[test]
    fn degenerate_directions_fall_back_to_straight_down() {
        let down = light_rotation(Vec3::NEG_Y);
        for d in [Vec3::ZERO, Vec3::NAN, Vec3::new(f32::INFINITY, 0.0, 0.0)] {
            assert_eq!(light_rotation(d), down);
        }
        assert!((down * Vec3::NEG_Y).abs_diff_eq(Vec3::NEG_Z, 1e-7));
    }

    #[test]
    fn lateral_up_points_skywards_for_a_tilted_sun() {
        let r = light_rotation(Vec3::new(0.0, -0.5, -0.8));
        // Light y axis (second row) has a positive world Y component, x axis is horizontal.
        assert!(r.row(1).y > 0.0);
        assert!(r.row(0).y.abs() < 1e-7);
    }

    #[test]
    fn basis_is_continuous_at_the_vertical_switch_from_minus_z_side() {
        // Just either side of the threshold for a sun tilting towards −Z.
        let tilt = |c: f32| Vec3::new(0.0, -c, -(1.0 - c * c).sqrt());
        let a = light_rotation(tilt(0.98999));
        let b = light_rotation(tilt(0.99001));
        assert!(a.abs_diff_eq(b, 1e-3), "{a} vs {b}");
    }

    #[test]
    fn light_from_world_moves_origin_to_zero() {
        let r = light_rotation(Vec3::new(0.4, -0.8, 0.3));
        let o = Vec3::new(10.0, -4.0, 2.5);
        let m = light_from_world(r, o);
        assert!(m.transform_point3(o).abs_diff_eq(Vec3::ZERO, 1e-5));
        let p = Vec3::new(1.0, 2.0, 3.0);
        assert!(m.transform_point3(p).abs_diff_eq(r * (p - o), 1e-5));
    }
}
