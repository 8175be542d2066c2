//! Screen-space LOD for the camera view: a run of visible instances (one draw key, one
//! culling chunk) is drawn with the coarsest level of its mesh ([`ShadowLods`]) whose
//! geometric error stays under [`CameraLod::max_error_pixels`] on screen, for the run's
//! largest instance at the run's nearest depth — so a sphere 3 pixels wide is not drawn with
//! 1 024 triangles, and the run stays one instanced draw.

use bevy_ecs::resource::Resource;
use glam::Vec3;

use crate::ecs::assets::MeshHandle;
use crate::ecs::shadow_lods::{MAX_ERROR_TEXELS, ShadowLod, ShadowLods};
use crate::math::aabb::Aabb;

/// How coarse a mesh the camera view may draw.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct CameraLod {
    /// Largest geometric error of a level on screen, in pixels (0 draws every mesh whole).
    /// Default 0.25: on the 100k field at 320×180 the camera draws 2.40 M of its 28.2 M
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

    /// The coarser levels of `mesh`, finest first (none for a mesh without levels).
    pub fn levels(&self, mesh: MeshHandle) -> &'a [ShadowLod] {
        self.lods.get(mesh)
    }

    /// The error allowed at unit view depth, in world units: a level of relative error `e`
    /// fits an instance of bounding radius `r` whose nearest view depth is `d` when
    /// `e · r ≤ d · error_per_depth`.
    pub fn error_per_depth(&self) -> f32 {
        self.error_per_depth
    }

    /// The mesh to draw instances of `mesh` with that lie in `bounds` and have bounding radii
    /// up to `radius` (a culling chunk's: its box and its largest member): the coarsest level
    /// whose error, for that radius at the box's nearest view depth, stays within the allowed
    /// pixels; `mesh` itself when the box reaches the camera's plane or is empty. (Where the
    /// GPU culls the view it picks per instance instead: `math::occlusion::level_for`.)
    pub fn mesh_for_chunk(&self, mesh: MeshHandle, bounds: &Aabb, radius: f32) -> MeshHandle {
        if self.lods.get(mesh).is_empty() || bounds.is_empty() {
            return mesh;
        }
        let depth = (bounds.center() - self.eye).dot(self.forward) - bounds.half_extents().dot(self.forward.abs());
        self.mesh_at(mesh, radius, depth)
    }

    /// The coarsest level of `mesh` for instances of bounding radius up to `radius` whose
    /// nearest view depth is `depth`; `mesh` for a depth at or before the camera's plane.
    fn mesh_at(&self, mesh: MeshHandle, radius: f32, depth: f32) -> MeshHandle {
        if depth.is_nan() || depth <= 0.0 || !radius.is_finite() {
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

    #[test]
    fn far_chunks_draw_coarser_levels_and_near_ones_the_mesh() {
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
        // A box of half-size `reach` around the point at `depth` straight ahead.
        let chunk = |depth: f32, reach: f32| {
            Aabb::new(
                Vec3::new(-reach, -reach, -depth - reach),
                Vec3::new(reach, reach, reach - depth),
            )
        };
        let pick = |depth: f32, reach: f32| view.mesh_for_chunk(MeshHandle(0), &chunk(depth, reach), 1.0).0;
        // Depth 1: 0.0005 m allowed, below both levels' errors (0.01, 0.1 m).
        assert_eq!(pick(2.0, 1.0), 0);
        // Depth 19: 0.0095 m allowed: neither; depth 199: 0.0995 m: the first level.
        assert_eq!(pick(20.0, 1.0), 0);
        assert_eq!(pick(200.0, 1.0), 1);
        // Depth 1999: the coarsest. A deeper box reaches nearer, with a finer level; one
        // reaching behind the camera draws the mesh.
        assert_eq!(pick(2000.0, 1.0), 2);
        assert_eq!(pick(2000.0, 1801.0), 1);
        assert_eq!(pick(2000.0, 2001.0), 0);
        // A larger radius needs a finer level; an empty box (a chunk with a member that is not
        // finite) draws the mesh.
        assert_eq!(view.mesh_for_chunk(MeshHandle(0), &chunk(2000.0, 1.0), 20.0).0, 1);
        assert_eq!(view.mesh_for_chunk(MeshHandle(0), &Aabb::EMPTY, 1.0).0, 0);
        // A mesh without levels draws itself.
        assert_eq!(
            view.mesh_for_chunk(MeshHandle(5), &chunk(200.0, 1.0), 1.0),
            MeshHandle(5)
        );
        // No error allowed, or no levels: no choice to make.
        let off = CameraLod { max_error_pixels: 0.0 };
        assert!(ViewLod::new(&lods, off, (Vec3::ZERO, Vec3::NEG_Z), fov, 1000).is_none());
        let none = ShadowLods::default();
        assert!(ViewLod::new(&none, CameraLod::default(), (Vec3::ZERO, Vec3::NEG_Z), fov, 1000).is_none());
    }
}
