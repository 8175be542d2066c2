//! The camera: its view and projection, the world-space corners of a depth slice of its
//! frustum, and frustum planes extracted from a clip matrix for culling.

use glam::{DMat4, DVec3, DVec4, Mat4, Vec3};

use crate::math::aabb::Aabb;
use crate::math::projection::perspective_reverse_z;

/// Smallest vertical field of view (radians) the camera helpers use; smaller or NaN values
/// are raised to it.
pub const MIN_FOV_Y: f32 = 1.0e-5;
/// Largest vertical field of view (radians) the camera helpers use (π − 1e-4, so that
/// `tan(fov_y / 2)` stays below 2·10⁴).
pub const MAX_FOV_Y: f32 = std::f32::consts::PI - 1.0e-4;
/// Smallest aspect ratio the camera helpers use; NaN becomes 1.
pub const MIN_ASPECT: f32 = 1.0e-4;
/// Largest aspect ratio the camera helpers use.
pub const MAX_ASPECT: f32 = 1.0e4;
/// Largest magnitude of a camera position coordinate the cascade helpers use (larger ones
/// are clamped), so every bound derived from it stays representable in f32.
pub const MAX_CAMERA_COORDINATE: f64 = 1.0e30;

/// A perspective camera: where it is and how it projects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraView {
    /// The camera's rigid transform; the camera looks along its local −Z, +Y is up.
    pub world_from_view: Mat4,
    /// Vertical field of view in radians.
    pub fov_y: f32,
    /// Width / height.
    pub aspect: f32,
    /// Near plane distance (positive).
    pub near: f32,
    /// Far plane distance (positive, greater than `near`).
    pub far: f32,
}

/// The camera's orthonormal world-space frame, in f64.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CameraBasis {
    /// Camera position (zero if the transform's translation is not finite, clamped to
    /// [`MAX_CAMERA_COORDINATE`]).
    pub position: DVec3,
    /// World direction of view-space +X.
    pub right: DVec3,
    /// World direction of view-space +Y.
    pub up: DVec3,
    /// World direction of view-space −Z.
    pub forward: DVec3,
    /// `tan(fov_y / 2)` after clamping the field of view.
    pub tan_half_y: f64,
    /// `tan(fov_y / 2) · aspect` after clamping.
    pub tan_half_x: f64,
}

impl CameraBasis {
    /// World-space offsets from the camera position of the four corners of the view
    /// rectangle at view depth `depth`, in the order bottom-left, bottom-right, top-right,
    /// top-left.
    pub fn rect_offsets(&self, depth: f64) -> [DVec3; 4] {
        let c = self.forward * depth;
        let r = self.right * (self.tan_half_x * depth);
        let u = self.up * (self.tan_half_y * depth);
        [c - r - u, c + r - u, c + r + u, c - r + u]
    }

    /// Offsets from the camera position of the eight corners of the slice between view
    /// depths `near` and `far`: the near rectangle, then the far rectangle.
    pub fn slice_offsets(&self, near: f64, far: f64) -> [DVec3; 8] {
        let n = self.rect_offsets(near);
        let f = self.rect_offsets(far);
        [n[0], n[1], n[2], n[3], f[0], f[1], f[2], f[3]]
    }
}

impl CameraView {
    /// `view_from_world`: the inverse of [`world_from_view`](Self::world_from_view).
    pub fn view_from_world(&self) -> Mat4 {
        // NOTE: inverted in f64 so a camera far from the origin keeps its rotation exact.
        self.world_from_view.as_dmat4().inverse().as_mat4()
    }

    /// The reverse-Z perspective projection (`clip_from_view`), with the field of view and
    /// aspect clamped into [`MIN_FOV_Y`]`..=`[`MAX_FOV_Y`] and
    /// [`MIN_ASPECT`]`..=`[`MAX_ASPECT`].
    pub fn clip_from_view(&self) -> Mat4 {
        perspective_reverse_z(
            sanitize_fov(self.fov_y),
            sanitize_aspect(self.aspect),
            self.near,
            self.far,
        )
    }

    /// `clip_from_world = clip_from_view · view_from_world`, multiplied in f64.
    pub fn clip_from_world(&self) -> Mat4 {
        let view_from_world: DMat4 = self.world_from_view.as_dmat4().inverse();
        (self.clip_from_view().as_dmat4() * view_from_world).as_mat4()
    }

    /// The camera's world position (translation of `world_from_view`).
    pub fn position(&self) -> Vec3 {
        self.world_from_view.w_axis.truncate()
    }

    /// The unit world direction the camera looks along (its local −Z).
    pub fn forward(&self) -> Vec3 {
        self.basis().forward.as_vec3()
    }

    /// The orthonormalised camera frame in f64 (Gram–Schmidt on the transform's axes, so
    /// scale or slight skew in `world_from_view` is ignored; degenerate axes fall back to
    /// any valid frame).
    pub(crate) fn basis(&self) -> CameraBasis {
        let m = self.world_from_view.as_dmat4();
        let position = m.w_axis.truncate();
        // NOTE: clamped so that bounds a box width away from it still round to distinct
        // finite f32 values; no real scene comes near the limit.
        let position = if position.is_finite() {
            position.clamp(
                DVec3::splat(-MAX_CAMERA_COORDINATE),
                DVec3::splat(MAX_CAMERA_COORDINATE),
            )
        } else {
            DVec3::ZERO
        };
        let forward = (-m.z_axis.truncate()).normalize_or(DVec3::NEG_Z);
        let x = m.x_axis.truncate();
        let right = (x - forward * x.dot(forward))
            .try_normalize()
            .unwrap_or_else(|| forward.any_orthonormal_vector());
        // Right-handed: right × up = back = −forward, so up = right × forward.
        let up = right.cross(forward);
        let tan_half_y = (0.5 * f64::from(sanitize_fov(self.fov_y))).tan();
        let tan_half_x = tan_half_y * f64::from(sanitize_aspect(self.aspect));
        CameraBasis {
            position,
            right,
            up,
            forward,
            tan_half_y,
            tan_half_x,
        }
    }
}

/// Clamps a field of view into the usable range (NaN becomes the minimum).
fn sanitize_fov(fov_y: f32) -> f32 {
    if fov_y.is_nan() {
        MIN_FOV_Y
    } else {
        fov_y.clamp(MIN_FOV_Y, MAX_FOV_Y)
    }
}

/// Clamps an aspect ratio into the usable range (NaN becomes 1).
fn sanitize_aspect(aspect: f32) -> f32 {
    if aspect.is_nan() {
        1.0
    } else {
        aspect.clamp(MIN_ASPECT, MAX_ASPECT)
    }
}

/// World-space corners of the part of the camera frustum between view depths `near` and
/// `far`, built from the camera's position and basis (no matrix inversion).
///
/// Order: near rectangle bottom-left, bottom-right, top-right, top-left, then the far
/// rectangle in the same order ("left"/"bottom" as seen by the camera).
pub fn slice_corners(camera: &CameraView, near: f32, far: f32) -> [Vec3; 8] {
    let b = camera.basis();
    b.slice_offsets(f64::from(near), f64::from(far))
        .map(|o| (b.position + o).as_vec3())
}

/// A plane `dot(normal, p) + d = 0` with unit `normal`; points with `dot(normal, p) + d >= 0`
/// are inside.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Plane {
    /// Unit normal pointing to the inside (zero for a degenerate plane).
    pub normal: Vec3,
    /// Offset: signed distance of the origin from the plane.
    pub d: f32,
}

impl Plane {
    /// Signed distance of `p` from the plane (positive inside).
    pub fn distance(&self, p: Vec3) -> f32 {
        self.normal.dot(p) + self.d
    }

    /// The plane `v.xyz · p + v.w >= 0`, normalised. A zero normal (e.g. the far plane of an
    /// infinite projection) becomes a plane every point is inside (`d >= 0`) or none is.
    fn from_f64(v: DVec4) -> Plane {
        let n = v.truncate();
        let len = n.length();
        if len > 0.0 && len.is_finite() {
            Plane {
                normal: (n / len).as_vec3(),
                d: (v.w / len) as f32,
            }
        } else {
            Plane {
                normal: Vec3::ZERO,
                d: if v.w >= 0.0 { 0.0 } else { f32::MIN },
            }
        }
    }
}

/// Six planes bounding a view volume; a point is inside when it is inside every plane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Frustum {
    /// Planes in the order `x >= −w`, `x <= w`, `y >= −w`, `y <= w`, `z >= 0`, `z <= w`
    /// (for reverse-Z, `z >= 0` is the far plane and `z <= w` the near plane).
    pub planes: [Plane; 6],
}

impl Frustum {
    /// Gribb–Hartmann plane extraction for wgpu's clip volume `−w <= x, y <= w`,
    /// `0 <= z <= w`. Works for ordinary and reverse-Z, perspective and orthographic
    /// matrices.
    pub fn from_clip_from_world(m: Mat4) -> Frustum {
        // NOTE: rows combined and normalised in f64; the d terms of a camera far from the
        // origin are large and would lose the sums' low bits in f32.
        let m = m.as_dmat4();
        let (r0, r1, r2, r3) = (m.row(0), m.row(1), m.row(2), m.row(3));
        Frustum {
            planes: [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2].map(Plane::from_f64),
        }
    }

    /// True when `p` is inside (or on) every plane.
    pub fn contains_point(&self, p: Vec3) -> bool {
        self.planes.iter().all(|pl| pl.distance(p) >= 0.0)
    }

    /// This frustum with every plane moved `margin` outwards (a degenerate plane is left
    /// as it is). Whatever meets a frustum whose corners all lie in it
    /// ([`contains_points`](Self::contains_points)) meets it too.
    pub fn dilated(&self, margin: f32) -> Frustum {
        Frustum {
            planes: self.planes.map(|p| match p.normal == Vec3::ZERO {
                true => p,
                false => Plane { d: p.d + margin, ..p },
            }),
        }
    }

    /// True when every point of `points` is inside (or on) every plane: for the eight
    /// corners of a bounded frustum, that the whole frustum is inside this one (both are
    /// convex).
    pub fn contains_points(&self, points: &[Vec3]) -> bool {
        points.iter().all(|&p| p.is_finite() && self.contains_point(p))
    }

    /// Conservative sphere test: false only when the sphere is entirely outside some plane.
    /// A non-finite centre or radius gives false; a negative radius counts as zero.
    pub fn intersects_sphere(&self, center: Vec3, radius: f32) -> bool {
        if !(center.is_finite() && radius.is_finite()) {
            return false;
        }
        let r = radius.max(0.0);
        self.planes.iter().all(|pl| pl.distance(center) >= -r)
    }

    /// Conservative box test (p-vertex): false only when the box is entirely outside some
    /// plane. An empty or non-finite box gives false.
    pub fn intersects_aabb(&self, aabb: &Aabb) -> bool {
        if aabb.is_empty() || !aabb.is_finite() {
            return false;
        }
        self.planes.iter().all(|pl| {
            // The corner furthest along the plane normal.
            let p = Vec3::select(pl.normal.cmpge(Vec3::ZERO), aabb.max, aabb.min);
            pl.distance(p) >= 0.0
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn camera() -> CameraView {
        CameraView {
            world_from_view: Mat4::from_rotation_translation(
                Quat::from_euler(glam::EulerRot::YXZ, 0.8, -0.3, 0.1),
                Vec3::new(5.0, 2.0, -3.0),
            ),
            fov_y: 1.0,
            aspect: 16.0 / 9.0,
            near: 0.1,
            far: 100.0,
        }
    }

    #[test]
    fn view_and_clip_matrices_agree_with_the_basis() {
        let cam = camera();
        let v = cam.view_from_world();
        assert!((v * cam.world_from_view).abs_diff_eq(Mat4::IDENTITY, 1e-5));
        let p = cam.position() + cam.forward() * 10.0;
        assert!(v.transform_point3(p).abs_diff_eq(Vec3::new(0.0, 0.0, -10.0), 1e-4));
        let clip = cam.clip_from_world() * p.extend(1.0);
        assert!(
            (clip.truncate() / clip.w)
                .truncate()
                .abs_diff_eq(glam::Vec2::ZERO, 1e-5)
        );
    }

    #[test]
    fn a_dilated_frustum_holds_the_frustum_moved_less_than_its_margin() {
        let cam = camera();
        let frustum = Frustum::from_clip_from_world(cam.clip_from_world());
        let held = frustum.dilated(0.5);
        let corners = |c: &CameraView| slice_corners(c, c.near, c.far);
        assert!(held.contains_points(&corners(&cam)));
        assert!(!frustum.dilated(-0.01).contains_points(&corners(&cam)));
        let moved_by = |step: Vec3| {
            let mut moved = cam;
            moved.world_from_view.w_axis += step.extend(0.0);
            moved
        };
        // Moved 0.4 m along any axis: each plane's distance changes by at most 0.4.
        for step in [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Z, Vec3::ONE.normalize()] {
            assert!(held.contains_points(&corners(&moved_by(step * 0.4))), "moved by {step}");
        }
        // 0.6 m forwards the far corners leave, 0.6 m back the near ones.
        for step in [cam.forward(), -cam.forward()] {
            assert!(
                !held.contains_points(&corners(&moved_by(step * 0.6))),
                "moved by {step}"
            );
        }
        // Turned 1°: the far corners (about 140 m away) move about 2.4 m, past the margin.
        let mut turned = cam;
        turned.world_from_view *= Mat4::from_rotation_y(1f32.to_radians());
        assert!(!held.contains_points(&corners(&turned)));
        assert!(frustum.dilated(3.0).contains_points(&corners(&turned)));
        assert!(!held.contains_points(&[Vec3::NAN]));
    }

    #[test]
    fn slice_corners_project_to_clip_corners() {
        let cam = camera();
        let m = cam.clip_from_world();
        let c = slice_corners(&cam, 2.0, 30.0);
        let want = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        for (i, p) in c.iter().enumerate() {
            let h = m * p.extend(1.0);
            let ndc = h.truncate() / h.w;
            let (x, y) = want[i % 4];
            assert!((ndc.x - x).abs() < 1e-4 && (ndc.y - y).abs() < 1e-4, "{i}: {ndc}");
            let depth = cam.view_from_world().transform_point3(*p).z;
            let want_depth = if i < 4 { -2.0 } else { -30.0 };
            assert!((depth - want_depth).abs() < 1e-4);
        }
    }

    #[test]
    fn frustum_contains_interior_and_rejects_exterior() {
        let cam = camera();
        let f = Frustum::from_clip_from_world(cam.clip_from_world());
        let c = slice_corners(&cam, 1.0, 50.0);
        let centroid = c.iter().copied().sum::<Vec3>() / 8.0;
        assert!(f.contains_point(centroid));
        for p in c {
            // Slightly inside each corner.
            assert!(f.contains_point(p + (centroid - p) * 0.01));
            assert!(!f.contains_point(p + (p - centroid) * 0.05));
        }
        assert!(f.intersects_sphere(centroid, 0.5));
        assert!(!f.intersects_sphere(cam.position() - cam.forward() * 10.0, 1.0));
        assert!(!f.intersects_sphere(cam.position() + cam.forward() * 1000.0, 10.0));
        assert!(f.intersects_sphere(cam.position() + cam.forward() * 1000.0, 950.0));
        assert!(!f.intersects_sphere(centroid, f32::NAN));
        assert!(!f.intersects_sphere(centroid, f32::INFINITY));
        assert!(f.intersects_aabb(&Aabb::new(centroid - 0.1, centroid + 0.1)));
        let behind = cam.position() - cam.forward() * 10.0;
        assert!(!f.intersects_aabb(&Aabb::new(behind - 1.0, behind + 1.0)));
        assert!(!f.intersects_aabb(&Aabb::EMPTY));
        // A huge box around the camera intersects.
        assert!(f.intersects_aabb(&Aabb::new(Vec3::splat(-1e4), Vec3::splat(1e4))));
    }

    #[test]
    fn planes_are_unit_and_work_for_orthographic_reverse_z() {
        let m = crate::math::projection::ortho_reverse_z(-1.0, 1.0, -2.0, 2.0, 1.0, 9.0);
        let f = Frustum::from_clip_from_world(m);
        for p in f.planes {
            assert!((p.normal.length() - 1.0).abs() < 1e-6);
        }
        assert!(f.contains_point(Vec3::new(0.0, 0.0, -5.0)));
        assert!(!f.contains_point(Vec3::new(0.0, 0.0, -0.5)));
        assert!(!f.contains_point(Vec3::new(0.0, 0.0, -9.5)));
        assert!(!f.contains_point(Vec3::new(1.5, 0.0, -5.0)));
        assert!(!f.contains_point(Vec3::new(0.0, -2.5, -5.0)));
    }

    #[test]
    fn degenerate_camera_still_gives_a_finite_frame() {
        let cam = CameraView {
            world_from_view: Mat4::ZERO,
            fov_y: f32::NAN,
            aspect: 0.0,
            near: 0.1,
            far: 10.0,
        };
        let b = cam.basis();
        assert!((b.right.cross(b.up) + b.forward).length() < 1e-12);
        assert!(slice_corners(&cam, 0.1, 10.0).iter().all(|p| p.is_finite()));
        assert!(cam.clip_from_view().is_finite());
    }
}
