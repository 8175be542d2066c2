//! Bounding-sphere culling of shadow casters: against all cascade boxes at once (in the
//! shared light frame), and against the camera frustum.

use glam::{Mat3, Vec3};

use crate::math::cascades::CascadeSet;
use crate::math::cascades::MAX_SUN_VIEWS;
use crate::math::frustum::Frustum;

/// Relative padding added to each caster's radius in [`cull_casters`], times the L1 norm of
/// its light-space centre: covers the f32 rounding of the rotation (a few ulps), so a caster
/// is never culled by rounding alone.
pub const CULL_PADDING: f32 = 1.0 / (1 << 20) as f32;

// NOTE: one mask bit per cascade.
const _: () = assert!(MAX_SUN_VIEWS <= 8, "cascade masks are u8");

/// Casters per culling batch: the per-lane loops below are written so the compiler keeps
/// a batch in SIMD registers (two SSE or one AVX register per quantity).
const LANES: usize = 8;

/// The cascade boxes as plain arrays. Unused cascades hold an empty box (`min = +∞`,
/// `max = −∞`), which no sphere reaches.
pub(crate) struct CascadeBoxes {
    /// Per-cascade `light_min` (x, y, z).
    pub(crate) min: [[f32; 3]; MAX_SUN_VIEWS],
    /// Per-cascade `light_max` (x, y; z, the near side, is never tested).
    pub(crate) max: [[f32; 2]; MAX_SUN_VIEWS],
    /// Bits of the active cascades.
    pub(crate) active: u8,
    /// Number of active cascades (the first ones).
    pub(crate) count: usize,
}

impl CascadeBoxes {
    /// Gathers the boxes of `set`.
    pub(crate) fn new(set: &CascadeSet) -> Self {
        let count = set.count.min(MAX_SUN_VIEWS);
        let mut min = [[f32::INFINITY; 3]; MAX_SUN_VIEWS];
        let mut max = [[f32::NEG_INFINITY; 2]; MAX_SUN_VIEWS];
        for (k, c) in set.cascades.iter().enumerate().take(count) {
            min[k] = c.light_min.to_array();
            max[k] = [c.light_max.x, c.light_max.y];
        }
        Self {
            min,
            max,
            active: ((1u32 << count) - 1) as u8,
            count,
        }
    }
}

/// `a` if greater than `b`, else `b`.
// NOTE: a plain compare-select compiles to one `maxps`; `f32::max` adds NaN fix-ups that
// slow the loop down, and NaN lanes are discarded by the validity mask anyway.
#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// Cascade masks of one batch of casters; `rows` are the rows of the light rotation.
#[inline(always)]
fn cull_batch(
    boxes: &CascadeBoxes,
    rows: &[[f32; 3]; 3],
    centers: &[Vec3; LANES],
    radii: &[f32; LANES],
) -> [u8; LANES] {
    let mut px = [0.0f32; LANES];
    let mut py = [0.0f32; LANES];
    let mut pz = [0.0f32; LANES];
    let mut rr = [0.0f32; LANES];
    let mut valid = [0u8; LANES];
    for j in 0..LANES {
        let c = centers[j];
        px[j] = rows[0][0] * c.x + rows[0][1] * c.y + rows[0][2] * c.z;
        py[j] = rows[1][0] * c.x + rows[1][1] * c.y + rows[1][2] * c.z;
        pz[j] = rows[2][0] * c.x + rows[2][1] * c.y + rows[2][2] * c.z;
        let r = max(radii[j], 0.0) + CULL_PADDING * (px[j].abs() + py[j].abs() + pz[j].abs());
        rr[j] = r * r;
        // NOTE: non-short-circuit `&` keeps this a branch-free select.
        let finite = px[j].is_finite() & py[j].is_finite() & pz[j].is_finite();
        valid[j] = if finite & radii[j].is_finite() { boxes.active } else { 0 };
    }
    let mut masks = [0u8; LANES];
    for k in 0..MAX_SUN_VIEWS {
        let [min_x, min_y, min_z] = boxes.min[k];
        let [max_x, max_y] = boxes.max[k];
        for j in 0..LANES {
            // Distance from the centre to the box; the z slab is open towards the light.
            let dx = max(max(min_x - px[j], px[j] - max_x), 0.0);
            let dy = max(max(min_y - py[j], py[j] - max_y), 0.0);
            let dz = max(min_z - pz[j], 0.0);
            let hit = dx * dx + dy * dy + dz * dz <= rr[j];
            masks[j] |= u8::from(hit) << k;
        }
    }
    std::array::from_fn(|j| masks[j] & valid[j])
}

/// For each caster `i` (bounding sphere `centers[i]`, `radii[i]`), sets bit `c` of
/// `masks[i]` when the sphere overlaps cascade `c`'s box, for `c < set.count`; other bits
/// are cleared.
///
/// The test is exact sphere-vs-box in the shared light frame (`set.light_rotation`), with
/// the box's near side (towards the light) open: casters between the light and a cascade
/// always cast (depth clamping flattens them onto the near plane). Non-finite centres or
/// radii (and centres whose rotated coordinates overflow f32) give 0; a negative radius
/// counts as 0. Radii are padded by [`CULL_PADDING`] times the centre's light-space L1
/// norm.
///
/// Processes `min(centers.len(), radii.len(), masks.len())` casters (the lengths should be
/// equal). Allocation-free: each centre is rotated once, then tested against the four
/// boxes, in batches of 8 the compiler vectorises.
pub fn cull_casters(set: &CascadeSet, centers: &[Vec3], radii: &[f32], masks: &mut [u8]) {
    debug_assert_eq!(centers.len(), radii.len());
    debug_assert_eq!(centers.len(), masks.len());
    let n = centers.len().min(radii.len()).min(masks.len());
    let boxes = CascadeBoxes::new(set);
    let rows = set.light_rotation.transpose().to_cols_array_2d();

    let (center_batches, center_tail) = centers[..n].as_chunks::<LANES>();
    let (radius_batches, radius_tail) = radii[..n].as_chunks::<LANES>();
    let (mask_batches, mask_tail) = masks[..n].as_chunks_mut::<LANES>();
    for ((c, r), m) in center_batches.iter().zip(radius_batches).zip(mask_batches) {
        *m = cull_batch(&boxes, &rows, c, r);
    }
    // The tail goes through the same kernel, padded with NaN radii (mask 0).
    let mut c = [Vec3::ZERO; LANES];
    let mut r = [f32::NAN; LANES];
    c[..center_tail.len()].copy_from_slice(center_tail);
    r[..radius_tail.len()].copy_from_slice(radius_tail);
    let m = cull_batch(&boxes, &rows, &c, &r);
    mask_tail.copy_from_slice(&m[..mask_tail.len()]);
}

/// Whether one caster's sphere (`center`, `radius`) reaches the light-space box `min..max`
/// (the box's near side, towards the light, open) in the frame `light_rotation` (light space
/// from world): [`cull_casters`]' test for one sphere and one box, the CPU mirror of
/// `shaders/shadow_cull.wgsl`. A sphere that is not finite reaches nothing.
pub fn sphere_reaches_light_box(light_rotation: &Mat3, min: Vec3, max: Vec3, center: Vec3, radius: f32) -> bool {
    let p = *light_rotation * center;
    let r = radius.max(0.0) + CULL_PADDING * (p.x.abs() + p.y.abs() + p.z.abs());
    let dx = (min.x - p.x).max(p.x - max.x).max(0.0);
    let dy = (min.y - p.y).max(p.y - max.y).max(0.0);
    let dz = (min.z - p.z).max(0.0);
    p.is_finite() && radius.is_finite() && dx * dx + dy * dy + dz * dz <= r * r
}

/// Visibility bits of one batch of `LANES` spheres against the six frustum planes.
#[inline]
fn frustum_batch(planes: &[[f32; 4]; 6], centers: &[Vec3; LANES], radii: &[f32; LANES]) -> u32 {
    let mut min_distance = [f32::INFINITY; LANES];
    for plane in planes {
        for j in 0..LANES {
            let c = centers[j];
            let d = plane[0] * c.x + plane[1] * c.y + plane[2] * c.z + plane[3];
            min_distance[j] = min_distance[j].min(d);
        }
    }
    let mut bits = 0u32;
    for j in 0..LANES {
        let c = centers[j];
        let r = radii[j].max(0.0);
        // NOTE: `f32::min` and `f32::max` skip NaN, so finiteness is checked explicitly on the
        // inputs (non-short-circuit `&` keeps the loop branch-free).
        let finite = c.x.is_finite() & c.y.is_finite() & c.z.is_finite() & radii[j].is_finite();
        let visible = (min_distance[j] >= -r) & finite;
        bits |= u32::from(visible) << j;
    }
    bits
}

/// Clears `out` and fills it with the indices of the spheres that
/// [`Frustum::intersects_sphere`] accepts (non-finite ones are rejected). `out` keeps its
/// capacity, so reusing it across frames does not allocate once it is large enough.
///
/// Processes `min(centers.len(), radii.len())` spheres, in batches of 8 the compiler
/// vectorises; indices must fit in `u32`.
pub fn cull_spheres_frustum(frustum: &Frustum, centers: &[Vec3], radii: &[f32], out: &mut Vec<u32>) {
    debug_assert_eq!(centers.len(), radii.len());
    debug_assert!(u32::try_from(centers.len()).is_ok());
    out.clear();
    let n = centers.len().min(radii.len());
    let planes = frustum.planes.map(|p| [p.normal.x, p.normal.y, p.normal.z, p.d]);
    let (center_batches, center_tail) = centers[..n].as_chunks::<LANES>();
    let (radius_batches, radius_tail) = radii[..n].as_chunks::<LANES>();
    let mut push_bits = |base: usize, mut bits: u32| {
        while bits != 0 {
            out.push((base + bits.trailing_zeros() as usize) as u32);
            bits &= bits - 1;
        }
    };
    for (b, (c, r)) in center_batches.iter().zip(radius_batches).enumerate() {
        push_bits(b * LANES, frustum_batch(&planes, c, r));
    }
    // The tail goes through the same kernel, padded with NaN spheres (never visible).
    let mut c = [Vec3::NAN; LANES];
    let mut r = [f32::NAN; LANES];
    c[..center_tail.len()].copy_from_slice(center_tail);
    r[..radius_tail.len()].copy_from_slice(radius_tail);
    push_bits(center_batches.len() * LANES, frustum_batch(&planes, &c, &r));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::aabb::Aabb;
    use crate::math::cascades::{CascadeInput, compute_cascades};
    use crate::math::frustum::CameraView;
    use crate::settings::CascadeFit;
    use glam::{Mat4, Quat};

    fn set(count: usize) -> (CascadeSet, CameraView) {
        let camera = CameraView {
            world_from_view: Mat4::from_rotation_translation(Quat::from_rotation_y(0.3), Vec3::new(0.0, 2.0, 0.0)),
            fov_y: 1.0,
            aspect: 1.5,
            near: 0.1,
            far: 500.0,
        };
        let set = compute_cascades(&CascadeInput {
            camera,
            light_direction: Vec3::new(0.2, -1.0, 0.3),
            scene_bounds: Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0)),
            receiver_bounds: Aabb::EMPTY,
            count,
            split_lambda: 0.5,
            max_distance: 100.0,
            resolution: 1024,
            fit: CascadeFit::Tight,
            angular_diameter: 0.01,
            blend_width: 0.0,
            snap_cells: 0,
            scroll: false,
            seen: None,
        });
        (set, camera)
    }

    #[test]
    fn casters_in_view_hit_and_far_ones_miss() {
        let (set, cam) = set(4);
        let f = cam.forward();
        let centers = [
            cam.position() + f * 0.5,
            cam.position() + f * 90.0,
            cam.position() + Vec3::new(0.0, 0.0, 5000.0),
            Vec3::NAN,
            cam.position() + f * 2.0,
        ];
        let radii = [0.1, 1.0, 1.0, 1.0, f32::INFINITY];
        let mut masks = [0xFFu8; 5];
        cull_casters(&set, &centers, &radii, &mut masks);
        assert_eq!(masks[0] & 1, 1, "{masks:?}");
        assert_eq!(masks[1] & 0b1000, 0b1000, "{masks:?}");
        assert_eq!(masks[1] & 1, 0, "{masks:?}");
        assert_eq!(masks[2], 0);
        assert_eq!(masks[3], 0);
        assert_eq!(masks[4], 0);
    }

    #[test]
    fn one_sphere_against_one_box_agrees_with_the_batched_test() {
        let (set, cam) = set(4);
        // A grid of spheres around the camera and up the light, with radii from 0 to 20 m
        // (and a NaN and an infinite one).
        let mut centers = Vec::new();
        let mut radii = Vec::new();
        for i in 0..4000 {
            let t = i as f32;
            let offset = Vec3::new(
                (t * 7.3) % 240.0 - 120.0,
                (t * 3.1) % 160.0 - 40.0,
                (t * 5.9) % 240.0 - 120.0,
            );
            centers.push(cam.position() + offset);
            radii.push((t * 0.37) % 20.0);
        }
        radii[17] = f32::NAN;
        radii[18] = f32::INFINITY;
        let mut masks = vec![0u8; centers.len()];
        cull_casters(&set, &centers, &radii, &mut masks);
        let mut hits = 0;
        for (k, cascade) in set.cascades.iter().enumerate().take(set.count) {
            for (i, (&c, &r)) in centers.iter().zip(&radii).enumerate() {
                let one = sphere_reaches_light_box(&set.light_rotation, cascade.light_min, cascade.light_max, c, r);
                assert_eq!(one, masks[i] & (1 << k) != 0, "sphere {i}, cascade {k}");
                hits += usize::from(one);
            }
        }
        assert!(hits > 400 && hits < 4 * 4000 - 400, "{hits} hits judge both ways");
    }

    #[test]
    fn casters_towards_the_light_are_kept() {
        let (set, cam) = set(2);
        // Far up the light's reverse direction above the first cascade.
        let p = cam.position() + cam.forward() * 1.0 - Vec3::new(0.2, -1.0, 0.3) * 10_000.0;
        let mut masks = [0u8];
        cull_casters(&set, &[p], &[0.5], &mut masks);
        assert_eq!(masks[0] & 1, 1);
        // Unused cascades never get a bit, even for a huge sphere.
        cull_casters(&set, &[p], &[1e30], &mut masks);
        assert_eq!(masks[0], 0b11);
    }

    #[test]
    fn frustum_culling_never_reports_padding_lanes() {
        let (_, cam) = set(1);
        let frustum = Frustum::from_clip_from_world(cam.clip_from_world());
        // Ten spheres (one full batch of 8 and a tail of 2) all in view, and a NaN radius.
        let centers: Vec<Vec3> = (0..10)
            .map(|i| cam.position() + cam.forward() * (5.0 + i as f32))
            .collect();
        let mut radii = vec![0.5; 10];
        radii[9] = f32::NAN;
        let mut out = Vec::new();
        cull_spheres_frustum(&frustum, &centers, &radii, &mut out);
        assert_eq!(out, (0..9).collect::<Vec<u32>>());
        let brute: Vec<u32> = (0..10)
            .filter(|&i| frustum.intersects_sphere(centers[i], radii[i]))
            .map(|i| i as u32)
            .collect();
        assert_eq!(out, brute);
    }

    #[test]
    fn frustum_culling_reuses_the_buffer() {
        let (_, cam) = set(1);
        let frustum = Frustum::from_clip_from_world(cam.clip_from_world());
        let f = cam.forward();
        let centers = [cam.position() + f * 10.0, cam.position() - f * 10.0, Vec3::NAN];
        let mut out = Vec::with_capacity(16);
        out.push(99);
        cull_spheres_frustum(&frustum, &centers, &[1.0, 1.0, 1.0], &mut out);
        assert_eq!(out, [0]);
        assert_eq!(out.capacity(), 16);
        cull_spheres_frustum(&frustum, &centers, &[1.0, 20.0, 1.0], &mut out);
        assert_eq!(out, [0, 1]);
    }
}
