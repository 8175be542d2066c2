//! Point-light shadow views: the six 90° faces of a cube around the light, in the order and
//! orientation of a cube-map texture (the Vulkan / WebGPU face selection), so a face rendered
//! with [`face_clip_from_world`] is what sampling the cube along the light-to-surface
//! direction reads. Depth is reverse-Z over `[near, range]` of the distance along the face's
//! axis ([`face_depth`]), which a shader recomputes from the direction's major axis.
//!
//! A cube-map face is a mirror image of a right-handed camera's view (its basis is
//! left-handed); casters are drawn two-sided, so the flipped winding does not matter.

use glam::{Mat3, Mat4, Vec2, Vec3};

use crate::math::frustum::Frustum;
use crate::math::projection::perspective_reverse_z;

/// Faces of a cube: +X, −X, +Y, −Y, +Z, −Z (cube-map layer order).
pub const FACES: usize = 6;

/// The axis of each face, in layer order.
pub const FACE_AXES: [Vec3; FACES] = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];

/// The face (cube-map layer) a direction from the light samples: its major axis; on an exact
/// tie, x before y before z.
pub fn face_of(direction: Vec3) -> usize {
    let a = direction.abs();
    if a.x >= a.y && a.x >= a.z {
        usize::from(direction.x < 0.0)
    } else if a.y >= a.z {
        2 + usize::from(direction.y < 0.0)
    } else {
        4 + usize::from(direction.z < 0.0)
    }
}

/// The view basis of `face`: right, up and forward (the face's axis) such that a point at
/// offset `r` from the light lands at NDC `(right·r, up·r) / (forward·r)`.
fn face_basis(face: usize) -> (Vec3, Vec3, Vec3) {
    match face {
        0 => (Vec3::NEG_Z, Vec3::Y, Vec3::X),
        1 => (Vec3::Z, Vec3::Y, Vec3::NEG_X),
        2 => (Vec3::X, Vec3::NEG_Z, Vec3::Y),
        3 => (Vec3::X, Vec3::Z, Vec3::NEG_Y),
        4 => (Vec3::X, Vec3::Y, Vec3::Z),
        _ => (Vec3::NEG_X, Vec3::Y, Vec3::NEG_Z),
    }
}

/// Light clip space of `face` from world (reverse-Z, depth 1 at `near`, 0 at `range` along
/// the face's axis), for a light at `position`. Requires `0 < near < range`.
pub fn face_clip_from_world(position: Vec3, face: usize, near: f32, range: f32) -> Mat4 {
    let (right, up, forward) = face_basis(face);
    // View space looks down −Z: rows right, up, −forward.
    let rotation = Mat3::from_cols(right, up, -forward).transpose();
    let view = Mat4::from_mat3(rotation) * Mat4::from_translation(-position);
    perspective_reverse_z(std::f32::consts::FRAC_PI_2, 1.0, near, range) * view
}

/// The depth a receiver at distance `axis` along its face's axis compares against (what
/// [`face_clip_from_world`] gives it): `near·(range − axis) / (axis·(range − near))`.
pub fn face_depth(axis: f32, near: f32, range: f32) -> f32 {
    near * (range - axis) / (axis * (range - near))
}

/// The face and texture coordinates a direction samples, by the cube-map face-selection
/// table (major axis `ma`, `u = (sc/|ma| + 1)/2`, `v = (tc/|ma| + 1)/2`).
pub fn face_uv(direction: Vec3) -> (usize, Vec2) {
    let d = direction;
    let face = face_of(d);
    let (sc, tc, ma) = match face {
        0 => (-d.z, -d.y, d.x),
        1 => (d.z, -d.y, -d.x),
        2 => (d.x, d.z, d.y),
        3 => (d.x, -d.z, -d.y),
        4 => (d.x, -d.y, d.z),
        _ => (-d.x, -d.y, -d.z),
    };
    (face, Vec2::new(sc / ma + 1.0, tc / ma + 1.0) * 0.5)
}

/// The frustum of `face` (for culling its casters): the four side planes through the light,
/// and the near and far (`range`) planes along the axis.
pub fn face_frustum(position: Vec3, face: usize, near: f32, range: f32) -> Frustum {
    Frustum::from_clip_from_world(face_clip_from_world(position, face, near, range))
}

/// World size of a face texel at distance `axis` along the face's axis, for a face of
/// `resolution` texels (the 90° face spans `2·axis`).
pub fn texel_size_at(axis: f32, resolution: u32) -> f32 {
    2.0 * axis / resolution.max(1) as f32
}

/// The six shadow views of a point light, computed once per frame for a shadowed light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointView {
    /// Light clip space from world of each face, in cube-map layer order.
    pub faces: [Mat4; FACES],
    /// The cull volume of each face.
    pub frusta: [Frustum; FACES],
    /// Near plane distance along a face's axis, metres.
    pub near: f32,
    /// Far plane distance (the light's range), metres.
    pub range: f32,
    /// World size of one texel per metre of distance along a face's axis (`2 / resolution`).
    pub texel_per_metre: f32,
}

/// The views of a point light at `position` reaching `range`, with faces of `resolution`
/// texels; None when no view can be made (a non-finite position, `near >= range`, or a zero
/// resolution).
pub fn point_view(position: Vec3, near: f32, range: f32, resolution: u32) -> Option<PointView> {
    let valid =
        position.is_finite() && near.is_finite() && range.is_finite() && 0.0 < near && near < range && resolution > 0;
    if !valid {
        return None;
    }
    let faces = std::array::from_fn(|f| face_clip_from_world(position, f, near, range));
    Some(PointView {
        frusta: faces.map(Frustum::from_clip_from_world),
        faces,
        near,
        range,
        texel_per_metre: texel_size_at(1.0, resolution),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::projection::ndc_to_uv;

    /// Deterministic directions over the sphere.
    fn directions() -> Vec<Vec3> {
        let mut s = 7u32;
        let mut next = || {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (s >> 8) as f32 / (1 << 24) as f32 * 2.0 - 1.0
        };
        (0..2000)
            .map(|_| Vec3::new(next(), next(), next()))
            .filter(|d| d.length() > 0.05)
            .map(Vec3::normalize)
            .collect()
    }

    #[test]
    fn a_rendered_face_lands_where_the_cube_map_samples_it() {
        let light = Vec3::new(3.0, 1.5, -2.0);
        let (near, range) = (0.05, 25.0);
        for d in directions() {
            for distance in [0.5, 4.0, 20.0] {
                let (face, uv) = face_uv(d);
                let clip = face_clip_from_world(light, face, near, range) * (light + d * distance).extend(1.0);
                assert!(clip.w > 0.0, "{d} behind face {face}");
                let ndc = clip.truncate() / clip.w;
                let rendered = ndc_to_uv(ndc.truncate());
                assert!(
                    (rendered - uv).abs().max_element() < 1e-4,
                    "{d} at {distance}: rendered at {rendered}, sampled at {uv} (face {face})"
                );
                assert!(ndc.x.abs() <= 1.0 + 1e-5 && ndc.y.abs() <= 1.0 + 1e-5);
                let axis = d.abs().max_element() * distance;
                assert!((ndc.z - face_depth(axis, near, range)).abs() < 1e-5, "{d}: depth");
            }
        }
    }

    #[test]
    fn depth_is_reverse_z_over_the_range() {
        let (near, range) = (0.1, 10.0);
        assert!((face_depth(near, near, range) - 1.0).abs() < 1e-6);
        assert!(face_depth(range, near, range).abs() < 1e-6);
        assert!(face_depth(1.0, near, range) > face_depth(2.0, near, range));
    }

    #[test]
    fn each_face_frustum_holds_the_directions_of_its_face_within_the_range() {
        let light = Vec3::new(-1.0, 2.0, 0.5);
        let (near, range) = (0.05, 12.0);
        let frusta: Vec<Frustum> = (0..FACES).map(|f| face_frustum(light, f, near, range)).collect();
        for d in directions() {
            let face = face_of(d);
            // Away from the face edges, so rounding cannot move a point across them.
            let (_, uv) = face_uv(d);
            if (uv - Vec2::splat(0.5)).abs().max_element() > 0.49 {
                continue;
            }
            let inside = light + d * 6.0;
            assert!(frusta[face].contains_point(inside), "{d} not in face {face}");
            let others = (0..FACES)
                .filter(|&f| f != face && frusta[f].contains_point(inside))
                .count();
            assert_eq!(others, 0, "{d} in another face too");
            // The far plane is across the face's axis: past the range along it.
            let beyond = light + d * (range * 1.5 / d.abs().max_element());
            assert!(!frusta[face].contains_point(beyond), "past the range");
        }
        assert_eq!(face_of(Vec3::new(1.0, 1.0, 1.0)), 0, "ties go to x");
        assert_eq!(face_of(Vec3::new(0.0, -1.0, 1.0)), 3, "then y");
        assert!((texel_size_at(5.0, 1024) - 10.0 / 1024.0).abs() < 1e-7);
    }

    #[test]
    fn a_point_view_has_every_face_or_none() {
        let view = point_view(Vec3::ONE, 0.05, 10.0, 512).expect("valid light");
        for (f, axis) in FACE_AXES.iter().enumerate() {
            assert_eq!(view.faces[f], face_clip_from_world(Vec3::ONE, f, 0.05, 10.0));
            assert!(view.frusta[f].contains_point(Vec3::ONE + *axis * 5.0));
        }
        assert!((view.texel_per_metre - 2.0 / 512.0).abs() < 1e-9);
        assert!(point_view(Vec3::NAN, 0.05, 10.0, 512).is_none());
        assert!(point_view(Vec3::ONE, 0.05, 0.05, 512).is_none());
        assert!(point_view(Vec3::ONE, 0.05, f32::INFINITY, 512).is_none());
        assert!(point_view(Vec3::ONE, 0.05, 10.0, 0).is_none());
    }
}
