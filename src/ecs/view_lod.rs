//! Screen-space LOD for the camera view: a run of visible instances (one draw key, one
//! culling chunk) is drawn with the coarsest level of its mesh ([`ShadowLods`]) whose
//! geometric error stays under [`CameraLod::max_error_pixels`] on screen, for the run's
//! largest instance at the run's nearest depth — so a sphere 3 pixels wide is not drawn with
//! 1 024 triangles, and the run stays one instanced draw.

use bevy_ecs::resource::Resource;
use glam::Vec3;

use crate::ecs::assets::MeshHandle;
use crate::ecs::shadow_lods::{MAX_ERROR_TEXELS, ShadowLods};

/// How coarse a mesh the camera view may draw.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct CameraLod {
    /// Largest geometric error of a level on screen, in pixels (0 draws every mesh whole).
    /// Default 0.25: on the 100k field at 320×180 the camera draws 2.30 M of its 28.2 M
    /// triangles (`cargo test --test camera_lod -- --nocapture`).
    pub max_error_pixels: f32,
}

impl Default for CameraLod {
    fn default() -> Self {
        CameraLod { max_error_pixels: 0.25 }
    }
}

/// The camera's side of the choice: where it is, where it looks and how wide a pixel is.
#[derive(Clone, Copy, Debug)]
pub struct ViewLod<'a> {
    lods: &'a ShadowLods,
    eye: Vec3,
    forward: Vec3,
    /// The error allowed at unit view depth, world units.
    error_per_depth: f32,
}

impl<'a> ViewLod<'a> {
    /// The choice for a camera at `eye` looking along `forward` (unit length), `fov_y`
    /// radians tall over `height` pixels; None when no mesh has a level or `settings` allows
    /// no error.
    pub fn new(
        lods: &'a ShadowLods,
        settings: CameraLod,
        (eye, forward): (Vec3, Vec3),
        fov_y: f32,
        height: u32,
    ) -> Option<ViewLod<'a>> {
        let pixel_per_depth = 2.0 * (0.5 * fov_y).tan() / height.max(1) as f32;
        let error_per_depth = settings.max_error_pixels * pixel_per_depth;
        (!lods.is_empty() && error_per_depth.is_finite() && error_per_depth > 0.0).then_some(ViewLod {
            lods,
            eye,
            forward,
            error_per_depth,
        })
    }

    /// The mesh to draw the instances `run` of `mesh` with (bounding spheres `centers` and
    /// `radii`, indexed by instance): the coarsest level whose error, for the largest of them
    /// at the nearest view depth any of them reaches, stays within the allowed pixels; `mesh`
    /// itself when one of them reaches the camera's plane.
    pub fn mesh_for_run(&self, mesh: MeshHandle, run: &[u32], centers: &[Vec3], radii: &[f32]) -> MeshHandle {
        if self.lods.get(mesh).is_empty() {
            return mesh;
        }
        let (mut radius, mut depth) = (0.0f32, f32::INFINITY);
        for &i in run {
            let (c, r) = (centers[i as usize], radii[i as usize]);
            radius = radius.max(r);
            depth = depth.min((c - self.eye).dot(self.forward) - r);
        }
        if depth.is_nan() || depth <= 0.0 {
            return mesh;
        }
        // NOTE: `pick` allows MAX_ERROR_TEXELS of its texel; the texel given is scaled so the
        // budget is the allowed error at this depth.
        let texel = depth * self.error_per_depth / MAX_ERROR_TEXELS;
        self.lods.pick(mesh, radius, texel)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ecs::shadow_lods::ShadowLod;

    #[test]
    fn far_runs_draw_coarser_levels_and_near_ones_the_mesh() {
        let mut lods = ShadowLods::default();
        let level = |mesh, relative_error| ShadowLod {
            mesh: MeshHandle(mesh),
            relative_error,
        };
        lods.set(MeshHandle(0), vec![level(1, 0.01), level(2, 0.1)]);
        // 90° tall over 1000 pixels: a pixel is 0.002 m per metre of depth; 0.25 px allowed.
        let fov = std::f32::consts::FRAC_PI_2;
        let view = ViewLod::new(&lods, CameraLod::default(), (Vec3::ZERO, Vec3::NEG_Z), fov, 1000)
            .expect("levels and an error budget");
        let centers = [2.0, 20.0, 200.0, -5.0, 2000.0].map(|d| Vec3::new(0.0, 0.0, -d));
        let radii = [1.0; 5];
        let pick = |run: &[u32]| view.mesh_for_run(MeshHandle(0), run, &centers, &radii).0;
        // Depth 1: 0.0005 m allowed, below both levels' errors (0.01, 0.1 m).
        assert_eq!(pick(&[0]), 0);
        // Depth 19: 0.0095 m allowed: neither; depth 199: 0.0995 m: the first level.
        assert_eq!(pick(&[1]), 0);
        assert_eq!(pick(&[2]), 1);
        // Depth 1999: the coarsest. A run takes its nearest member's level; one behind the
        // camera draws the mesh.
        assert_eq!(pick(&[4]), 2);
        assert_eq!(pick(&[4, 2]), 1);
        assert_eq!(pick(&[4, 3]), 0);
        // A mesh without levels draws itself.
        assert_eq!(view.mesh_for_run(MeshHandle(5), &[2], &centers, &radii), MeshHandle(5));
        // No error allowed, or no levels: no choice to make.
        let off = CameraLod { max_error_pixels: 0.0 };
        assert!(ViewLod::new(&lods, off, (Vec3::ZERO, Vec3::NEG_Z), fov, 1000).is_none());
        let none = ShadowLods::default();
        assert!(ViewLod::new(&none, CameraLod::default(), (Vec3::ZERO, Vec3::NEG_Z), fov, 1000).is_none());
    }
}
