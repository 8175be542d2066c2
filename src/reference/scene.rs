//! [`ReferenceScene`]: the casters' triangles in world space and a BVH over them (obvhs's
//! compressed wide BVH8), answering "does anything opaque lie along this ray?".

use std::collections::HashMap;
use std::fmt;
use std::sync::Arc;
use std::time::Duration;

use glam::{Vec2, Vec3};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::Ray;

use super::triangle::{MaskTexels, MaskedTri, OPAQUE, Tri};
use super::{AlphaMask, Caster};

/// The triangles of every caster in world space plus a BVH over them, ready for
/// [`sun_visibility`](super::sun_visibility).
///
/// Triangles are two-sided, as the shadow maps render both faces. Building takes the meshes
/// by reference and keeps its own copy, so the meshes may be dropped afterwards.
#[derive(Default)]
pub struct ReferenceScene {
    /// Triangles in the BVH's primitive order (a triangle the builder split into several boxes
    /// appears once per box).
    tris: Vec<Tri>,
    /// Texture coordinates of the masked triangles, indexed by [`Tri::masked`].
    masked: Vec<MaskedTri>,
    /// Thresholded masks, indexed by [`MaskedTri::mask`].
    masks: Vec<MaskTexels>,
    /// `None` for a scene without triangles (obvhs wants at least one).
    bvh: Option<CwBvh>,
    /// Number of distinct triangles kept.
    triangle_count: usize,
}

impl fmt::Debug for ReferenceScene {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ReferenceScene")
            .field("triangle_count", &self.triangle_count)
            .field("masked_triangles", &self.masked.len())
            .field("masks", &self.masks.len())
            .field("bvh_nodes", &self.bvh.as_ref().map_or(0, |b| b.nodes.len()))
            .finish()
    }
}

/// A triangle collected from a caster, before BVH ordering.
struct Staged {
    corners: [Vec3; 3],
    /// Index into the masked table or [`OPAQUE`].
    masked: u32,
}

impl ReferenceScene {
    /// Transforms every caster's triangles to world space and builds the BVH over them.
    ///
    /// Skips, without failing: casters whose `world_from_local` has a non-finite element,
    /// triangles with an index out of range or a world-space corner that is non-finite or more
    /// than 1e12 m from the origin (obvhs's builder overflows there), and degenerate
    /// triangles (zero area, or the sine of every corner angle below about 1e-6). A mask that
    /// stops rays at every texel is dropped (the caster is opaque); masks shared through the
    /// same [`Arc`] are thresholded once. `world_from_local` is taken as affine (its bottom
    /// row is ignored).
    pub fn build<'a>(casters: impl IntoIterator<Item = Caster<'a>>) -> ReferenceScene {
        let mut staged: Vec<Staged> = Vec::new();
        let mut masked: Vec<MaskedTri> = Vec::new();
        let mut masks: Vec<MaskTexels> = Vec::new();
        // Mask table index per distinct `Arc`, or `None` for a mask that is all opaque.
        let mut mask_ids: HashMap<*const AlphaMask, Option<u32>> = HashMap::new();

        for caster in casters {
            let m = caster.world_from_local;
            if !m.is_finite() {
                continue;
            }
            let mask_id = caster.mask.as_ref().and_then(|mask| {
                *mask_ids.entry(Arc::as_ptr(mask)).or_insert_with(|| {
                    let texels = MaskTexels::new(mask);
                    if texels.all_opaque() {
                        None
                    } else {
                        masks.push(texels);
                        Some(masks.len() as u32 - 1)
                    }
                })
            });
            let world: Vec<Vec3> = caster
                .mesh
                .vertices
                .iter()
                .map(|v| m.transform_point3(Vec3::from(v.position)))
                .collect();
            for tri in caster.mesh.indices.chunks_exact(3) {
                let Some(corners) = corners(&world, tri) else {
                    continue;
                };
                let masked_index = match mask_id {
                    None => OPAQUE,
                    Some(mask) => {
                        let uv = [tri[0], tri[1], tri[2]].map(|i| Vec2::from(caster.mesh.vertices[i as usize].uv));
                        masked.push(MaskedTri {
                            uv0: uv[0],
                            duv1: uv[1] - uv[0],
                            duv2: uv[2] - uv[0],
                            mask,
                        });
                        masked.len() as u32 - 1
                    }
                };
                staged.push(Staged {
                    corners,
                    masked: masked_index,
                });
            }
        }

        if staged.is_empty() {
            return ReferenceScene::default();
        }
        let bvh_tris: Vec<obvhs::triangle::Triangle> = staged
            .iter()
            .map(|s| obvhs::triangle::Triangle {
                v0: s.corners[0].to_array().into(),
                v1: s.corners[1].to_array().into(),
                v2: s.corners[2].to_array().into(),
            })
            .collect();
        // Spatial pre-splits cut the boxes of large triangles (ground planes) so that rays
        // near them test fewer boxes; the build is still fast.
        let params = BvhBuildParams {
            pre_split: true,
            ..BvhBuildParams::medium_build()
        };
        let bvh = build_cwbvh_from_tris(&bvh_tris, params, &mut Duration::default());
        let tris = bvh
            .primitive_indices
            .iter()
            .map(|&i| {
                let s = &staged[i as usize];
                let [a, b, c] = s.corners;
                Tri {
                    v0: a,
                    e1: b - a,
                    e2: c - a,
                    masked: s.masked,
                }
            })
            .collect();
        ReferenceScene {
            tris,
            masked,
            masks,
            bvh: Some(bvh),
            triangle_count: staged.len(),
        }
    }

    /// Number of triangles kept (after skipping degenerate and non-finite ones).
    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// True when the ray `origin + t·dir`, `t > 0`, hits a triangle at a point its mask (if any)
    /// does not let through. `dir` need not be unit but must be finite and non-zero; `origin`
    /// must be finite.
    ///
    /// NOTE: obvhs's CWBVH node test clamps the near distance to 1e-4 (in units of `dir`), so
    /// a triangle whose leaf box lies entirely within that distance of `origin` is not seen.
    #[cfg(test)]
    pub(crate) fn occluded(&self, origin: Vec3, dir: Vec3) -> bool {
        self.occluded_within(origin, dir, f32::INFINITY)
    }

    /// Like [`occluded`](Self::occluded), counting only hits at `t < t_max` (a light at a
    /// finite distance: casters behind it do not shadow).
    pub(crate) fn occluded_within(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let Some(bvh) = &self.bvh else {
            return false;
        };
        // NOTE: obvhs inverts a zero direction component to ±1/EPSILON by its sign bit but
        // picks the box planes by `component < 0.0`, so a -0.0 component makes the box test
        // miss everything. Canonicalise to +0.0.
        let dir = Vec3::select(dir.cmpeq(Vec3::ZERO), Vec3::ZERO, dir);
        let ray = Ray::new(origin.to_array().into(), dir.to_array().into(), 0.0, t_max);
        // `ray_traverse_miss` stops at the first primitive whose distance is below the ray's
        // `tmax`; reporting a let-through hit as infinitely far makes it an any-hit query with
        // our own alpha test.
        let missed = bvh.ray_traverse_miss(ray, |_, id| {
            if self.blocks(id, origin, dir, t_max) {
                0.0
            } else {
                f32::INFINITY
            }
        });
        !missed
    }

    /// Whether triangle `id` (in BVH order) stops the ray.
    #[inline(always)]
    fn blocks(&self, id: usize, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let tri = &self.tris[id];
        let Some(bary) = tri.intersect(origin, dir, t_max) else {
            return false;
        };
        if tri.masked == OPAQUE {
            return true;
        }
        let m = &self.masked[tri.masked as usize];
        self.masks[m.mask as usize].opaque_at(m.uv(bary))
    }
}

/// Largest world coordinate accepted, in metres. obvhs sums box surface areas in f32 while
/// building; corners near 1e19 overflow them to infinity and its builder then panics, so
/// anything past this counts as non-finite.
const MAX_COORDINATE: f32 = 1e12;

/// The world-space corners of one triangle, or `None` when an index is out of range, a corner
/// is not finite (or beyond [`MAX_COORDINATE`]), or the triangle is degenerate.
fn corners(world: &[Vec3], tri: &[u32]) -> Option<[Vec3; 3]> {
    // NOTE: written so that NaN fails the test.
    let get = |i: u32| {
        world
            .get(i as usize)
            .copied()
            .filter(|p| p.abs().max_element() <= MAX_COORDINATE)
    };
    let (a, b, c) = (get(tri[0])?, get(tri[1])?, get(tri[2])?);
    let (e1, e2) = (b - a, c - a);
    let n = e1.cross(e2);
    // Cross product norm against the product of edge lengths: the sine of the corner angle.
    // f32 rounding alone gives sines near 1e-7; past 1e-6 the triangle has a real area. The
    // products are f64 so huge triangles do not overflow into a false "degenerate".
    let area2 = n.as_dvec3().length_squared();
    let scale = e1.as_dvec3().length_squared() * e2.as_dvec3().length_squared();
    (n.is_finite() && area2 > 1e-12 * scale && area2 > 0.0).then_some([a, b, c])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{MeshData, Vertex, plane};
    use glam::Mat4;

    fn caster(mesh: &MeshData, m: Mat4) -> Caster<'_> {
        Caster {
            mesh,
            world_from_local: m,
            mask: None,
        }
    }

    fn mesh(points: &[[f32; 3]], indices: &[u32]) -> MeshData {
        MeshData {
            vertices: points
                .iter()
                .map(|&p| Vertex {
                    position: p,
                    ..Default::default()
                })
                .collect(),
            indices: indices.to_vec(),
        }
    }

    #[test]
    fn skips_bad_input() {
        let good = [0.0, 0.0, 0.0];
        let m = mesh(
            &[
                good,
                [1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0],
                [f32::NAN, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [1e30, 1e30, 0.0],
            ],
            &[
                0, 1, 2, // kept
                0, 1, 3, // NaN corner
                0, 1, 4, // collinear
                0, 0, 2, // repeated corner
                0, 1, 9, // index out of range
                0, 1, 5, // beyond 1e12 m
                0, 1, // trailing partial triangle
            ],
        );
        let scene = ReferenceScene::build([caster(&m, Mat4::IDENTITY)]);
        assert_eq!(scene.triangle_count(), 1);
        let nan = ReferenceScene::build([caster(&m, Mat4::from_translation(Vec3::NAN))]);
        assert_eq!(nan.triangle_count(), 0);
        assert!(!nan.occluded(Vec3::new(0.2, -1.0, 0.2), Vec3::Y));
        // Large but accepted coordinates build and trace.
        let far = ReferenceScene::build([caster(&m, Mat4::from_scale(Vec3::splat(1e11)))]);
        assert_eq!(far.triangle_count(), 1);
        assert!(far.occluded(Vec3::new(2e10, -1.0, 2e10), Vec3::Y));
    }

    #[test]
    fn single_triangle_and_two_sided() {
        let m = mesh(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], &[0, 1, 2]);
        let scene = ReferenceScene::build([caster(&m, Mat4::from_translation(Vec3::Y * 2.0))]);
        assert!(scene.occluded(Vec3::new(0.2, 0.0, 0.2), Vec3::Y));
        assert!(scene.occluded(Vec3::new(0.2, 5.0, 0.2), Vec3::NEG_Y));
        assert!(!scene.occluded(Vec3::new(0.2, 3.0, 0.2), Vec3::Y));
        assert!(!scene.occluded(Vec3::new(0.8, 0.0, 0.8), Vec3::Y));
        // Negative zeros in the direction (as `-Vec3::NEG_Y` gives).
        assert!(scene.occluded(Vec3::new(0.2, 0.0, 0.2), Vec3::new(-0.0, 1.0, -0.0)));
        assert!(scene.occluded(Vec3::new(0.2, 5.0, 0.2), -Vec3::Y));
    }

    #[test]
    fn many_casters_find_the_right_triangles() {
        // A 10×10 grid of small quads at y = 1; rays up through quad centres hit, rays through
        // the gaps miss.
        let quad = plane(Vec2::splat(0.5));
        let transforms: Vec<Mat4> = (0..100)
            .map(|i| Mat4::from_translation(Vec3::new((i % 10) as f32, 1.0, (i / 10) as f32)))
            .collect();
        let scene = ReferenceScene::build(transforms.iter().map(|&t| caster(&quad, t)));
        assert_eq!(scene.triangle_count(), 200);
        for i in 0..10 {
            for j in 0..10 {
                let p = Vec3::new(i as f32, 0.0, j as f32);
                assert!(scene.occluded(p, Vec3::Y));
                assert!(!scene.occluded(p + Vec3::new(0.5, 0.0, 0.0), Vec3::Y));
                assert!(!scene.occluded(p, Vec3::NEG_Y));
            }
        }
    }

    #[test]
    fn shared_masks_are_thresholded_once_and_opaque_masks_dropped() {
        let quad = plane(Vec2::ONE);
        let clear = Arc::new(AlphaMask {
            width: 1,
            height: 1,
            alpha: vec![0],
            factor: 1.0,
            cutoff: 0.5,
        });
        let solid = Arc::new(AlphaMask {
            alpha: vec![255],
            ..(*clear).clone()
        });
        let with = |mask: &Arc<AlphaMask>, y: f32| Caster {
            mesh: &quad,
            world_from_local: Mat4::from_translation(Vec3::Y * y),
            mask: Some(Arc::clone(mask)),
        };
        let scene = ReferenceScene::build([with(&clear, 1.0), with(&clear, 2.0), with(&solid, 3.0)]);
        assert_eq!(scene.masks.len(), 1);
        assert_eq!(scene.masked.len(), 4);
        assert_eq!(scene.triangle_count(), 6);
        assert!(scene.occluded(Vec3::ZERO, Vec3::Y));
        assert!(!scene.occluded(Vec3::Y * 2.5, Vec3::NEG_Y));
        assert!(format!("{scene:?}").contains("triangle_count: 6"));
    }
}
