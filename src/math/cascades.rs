//! Cascaded shadow maps for a directional light: split the view frustum by depth, fit one
//! reverse-Z orthographic box per slice in a light frame shared by all cascades, and
//! stabilise the boxes so camera motion moves shadows by whole texels only.

use glam::{DMat3, DVec3, DVec4, Mat3, Mat4, Vec3, Vec4};

use crate::math::aabb::Aabb;
use crate::math::clip::clipped_bounds;
use crate::math::frustum::{CameraBasis, CameraView};
use crate::math::light_space::light_rotation;
use crate::math::pcss::pcss_params_f64;
use crate::math::snapping::{TexelSnap, f32_down, f32_sat, f32_up, snap_interval};
use crate::math::splits::wide_view_splits;
use crate::settings::{CascadeFit, MAX_CASCADES};

/// Smallest lateral extent or depth range of a cascade box, in world units.
///
/// Deliberately absolute (not relative to the camera's distance from the origin) so that the
/// box size never depends on the camera position. The published f32 bounds stay ordered
/// even when this is below an f32 ulp, because they are rounded outwards.
pub const MIN_BOX_EXTENT: f64 = 1.0e-4;

/// Furthest (world units) the near plane of a cascade is pushed towards the light to reach
/// the scene's casters. Casters beyond it are still drawn when depth clamping is on.
pub const MAX_CASTER_REACH: f64 = 1.0e6;

/// Largest view depth cascades cover (a near plane beyond it is lowered to half of it). Keeps
/// every light-space bound far inside f32 range even for a 180° field of view.
pub const MAX_SHADOW_DISTANCE: f32 = 1.0e12;

/// Everything one frame's cascade computation depends on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CascadeInput {
    /// The camera the cascades cover.
    pub camera: CameraView,
    /// Unit direction the light travels (sun straight down is `(0, −1, 0)`); normalised here.
    pub light_direction: Vec3,
    /// World bounds of all shadow casters; used to push each box's near plane towards the
    /// light. Empty or non-finite bounds are ignored.
    pub scene_bounds: Aabb,
    /// World bounds of everything that receives shadows: each box is fitted to the part of
    /// its slice (Tight) or sphere (Stable) inside them, so no texel is spent on sky, on space
    /// under the ground or beyond the scene's edge. Empty or non-finite bounds, or bounds
    /// that miss a slice, leave that slice whole.
    pub receiver_bounds: Aabb,
    /// Number of cascades, clamped into `1..=MAX_CASCADES`.
    pub count: usize,
    /// PSSM blend: 0 linear, 1 logarithmic.
    pub split_lambda: f32,
    /// View depth where shadows end (capped by the camera's far plane).
    pub max_distance: f32,
    /// Shadow-map resolution per cascade, in texels per side (values below 2 count as 2).
    /// Snapping is exact in f32 when it is a power of two.
    pub resolution: u32,
    /// How the boxes are fitted.
    pub fit: CascadeFit,
    /// Angular diameter of the light in radians (PCSS).
    pub angular_diameter: f32,
    /// Fraction (0–0.5) of each cascade's depth range that blends into the next cascade: each
    /// cascade after the first also covers that band of its predecessor, so blended pixels
    /// find both cascades' data.
    pub blend_width: f32,
}

/// One cascade: its projection and the numbers the shaders need.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Cascade {
    /// Reverse-Z orthographic projection of the box times the shared light rotation,
    /// texel-snapped. `clip.x, clip.y ∈ [−1, 1]` over the box (+y = light-space +y),
    /// `clip.z = 1` at `light_max.z` (towards the light), `0` at `light_min.z`; `clip.w = 1`.
    pub clip_from_world: Mat4,
    /// View depth where this cascade's slice starts.
    pub near: f32,
    /// View depth where this cascade's slice ends.
    pub far: f32,
    /// Minimum corner of the box in the shared light frame (`light_rotation * p`, no
    /// translation), rounded down to f32. `z` is the far side (away from the light).
    pub light_min: Vec3,
    /// Maximum corner of the box in the shared light frame, rounded up to f32. `z` is the
    /// near side (towards the light).
    pub light_max: Vec3,
    /// World size of one shadow texel along x: `width_x / resolution`.
    pub texel_world_size: f32,
    /// World distance from the box's near plane to its far plane.
    pub depth_range: f32,
    /// `2·tan(θ/2) / width_x`: penumbra UV width per world unit of blocker distance.
    pub light_size_uv: f32,
    /// `depth_range · 2·tan(θ/2) / width_x`: NDC-depth difference → penumbra width in UV.
    pub pcss_scale: f32,
    /// `width_x / width_y`: scale from a u-extent to the v-extent of the same world size.
    pub uv_scale_y: f32,
    /// Where the slice's own coverage starts in the box's depth `d = 1 − clip.z` (0 at the
    /// light's side, 1 at the far side): every receiver this cascade shades lies in
    /// `[receiver_start, 1]`, and what lies nearer the light is a caster above all of them
    /// (the box reaches up to the scene's casters). Moment techniques spend their precision
    /// on that span.
    pub receiver_start: f32,
}

/// The cascades of one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CascadeSet {
    /// Number of valid cascades, `1..=MAX_CASCADES` (0 only for `Default`).
    pub count: usize,
    /// The cascades; entries from `count` on are `Cascade::default()`.
    pub cascades: [Cascade; MAX_CASCADES],
    /// Split view depths: cascade `i` covers `[splits[i], splits[i + 1]]`; entries after
    /// `count` repeat the last.
    pub splits: [f32; MAX_CASCADES + 1],
    /// The light rotation (`light_from_world`, rotation only) shared by every cascade.
    pub light_rotation: Mat3,
}

impl CascadeSet {
    /// The valid cascades.
    pub fn active(&self) -> &[Cascade] {
        &self.cascades[..self.count.min(MAX_CASCADES)]
    }

    /// The far split of each cascade (`splits[1..=4]`), the layout a shader selecting a
    /// cascade by view depth wants.
    pub fn far_splits(&self) -> Vec4 {
        Vec4::from_slice(&self.splits[1..])
    }
}

/// Computes the cascades for one frame. Allocation-free; every output is finite and every
/// active box has positive width, height and depth for any finite input.
///
/// - Splits: [`wide_view_splits`] (PSSM, pulled in for views wider than 120°) from the
///   camera's near plane to `min(max_distance, camera.far, MAX_SHADOW_DISTANCE)`.
/// - [`CascadeFit::Tight`]: x and y bound the slice's eight corners in the shared light
///   frame.
/// - [`CascadeFit::Stable`]: x and y bound the sphere around the camera position that reaches
///   the slice's farthest corner (a square box), so turning the camera in place changes
///   nothing.
/// - In both fits the lateral extent is rounded up on a fixed logarithmic grid (computed from
///   camera-relative offsets, so a pure translation keeps it bit-identical) and the box
///   start is snapped down to whole texels of a world-fixed grid.
/// - Depth: the far plane is the slice's (Tight) or sphere's (Stable) far-most point, the
///   near plane the nearer-to-the-light of the slice / sphere top and the top of
///   `scene_bounds` (capped [`MAX_CASTER_REACH`] above the slice).
pub fn compute_cascades(input: &CascadeInput) -> CascadeSet {
    let count = input.count.clamp(1, MAX_CASCADES);
    let camera = &input.camera;
    // NOTE: `f32::min` ignores a NaN operand and the comparison lets a NaN near through;
    // pssm_splits sanitises whatever remains.
    let shadow_far = input.max_distance.min(camera.far).min(MAX_SHADOW_DISTANCE);
    let near = if camera.near > 0.5 * MAX_SHADOW_DISTANCE {
        0.5 * MAX_SHADOW_DISTANCE
    } else {
        camera.near
    };
    let basis = camera.basis();
    let splits = wide_view_splits(
        near,
        shadow_far,
        count,
        input.split_lambda,
        basis.tan_half_x.max(basis.tan_half_y),
    );

    let light_rotation = light_rotation(input.light_direction);
    // NOTE: all geometry is done in f64 but with the *f32* rotation the set publishes, so
    // culling (which only has the f32 matrix) and the boxes agree exactly.
    let rot = light_rotation.as_dmat3();
    let frame = Frame {
        rot,
        camera: rot * basis.position,
        caster_top: caster_top(&rot, &input.scene_bounds),
        resolution: f64::from(input.resolution.max(2)),
    };

    let mut cascades = [Cascade::default(); MAX_CASCADES];
    for (i, cascade) in cascades.iter_mut().enumerate().take(count) {
        let (near, far) = (splits[i], splits[i + 1]);
        // NOTE: the previous cascade blends into this one over the last `blend_width` of its
        // range, so this box starts there; `near` (used for selection) stays the split.
        let blend = if input.blend_width.is_finite() {
            f64::from(input.blend_width).clamp(0.0, 0.5)
        } else {
            0.0
        };
        let covered_near = if i > 0 {
            f64::from(near) - blend * f64::from(near - splits[i - 1])
        } else {
            f64::from(near)
        };
        let receivers = receivers_from_camera(&input.receiver_bounds, basis.position);
        let coverage = match input.fit {
            CascadeFit::Tight => tight_coverage(
                &basis,
                &rot,
                (covered_near, f64::from(far)),
                receivers,
                frame.resolution,
            ),
            CascadeFit::Stable => stable_coverage(&basis, &rot, f64::from(far), receivers, frame.resolution),
        };
        *cascade = frame.cascade(&coverage, near, far, input.angular_diameter);
    }
    CascadeSet {
        count,
        cascades,
        splits,
        light_rotation,
    }
}

/// What a cascade box must cover, relative to the camera position in the light frame.
struct Coverage {
    /// Smallest light-space offset from the camera to cover.
    lo: DVec3,
    /// Largest light-space offset from the camera to cover.
    hi: DVec3,
    /// The light-most offset of the whole slice (or sphere), receivers or not: the box's
    /// light side reaches at least this far, so that only casters rising above it (not
    /// receivers moving) change the box's depth.
    top: f64,
}

/// How far, in texels of a cascade, shadow filters read around a receiver: the widest PCSS
/// kernel (32 texels) plus the largest PCF radius and the normal offset, rounded up. A box
/// fitted to its receivers keeps this margin around them laterally, so no filter reads past
/// its edge.
pub const FILTER_REACH_TEXELS: f64 = 48.0;

impl Coverage {
    /// This coverage cut laterally to `[lo, hi]` (the part of it that receives shadows),
    /// grown by [`FILTER_REACH_TEXELS`] of the box it makes at `resolution` texels but never
    /// past this coverage; its depth keeps this coverage's far side and top, and its `hi.z`
    /// becomes the receivers' top (where the receivers start in depth).
    fn clipped(&self, lo: DVec3, hi: DVec3, resolution: f64) -> Coverage {
        // NOTE: the margin is a share of the grown box: w' = w + 2·reach·w'/res.
        let share = (2.0 * FILTER_REACH_TEXELS / resolution.max(2.0 * FILTER_REACH_TEXELS + 1.0)).min(0.5);
        let grow = (hi - lo) * (0.5 * share / (1.0 - share));
        let margin = DVec3::new(grow.x, grow.y, 0.0);
        // NOTE: the far side stays the whole slice's: raised to the receivers' bottom, it
        // changed the hardware bias's clamp in metres (a share of the box's depth) and with
        // it which texels PCSS finds at the rim of umbrae.
        let lo = (lo - margin).max(self.lo);
        Coverage {
            lo: DVec3::new(lo.x, lo.y, self.lo.z),
            hi: (hi + margin).min(self.hi),
            top: self.top,
        }
    }
}

/// The receivers' box as offsets from the camera position `camera`, if usable.
fn receivers_from_camera(bounds: &Aabb, camera: DVec3) -> Option<(DVec3, DVec3)> {
    if bounds.is_empty() || !bounds.is_finite() {
        return None;
    }
    Some((bounds.min.as_dvec3() - camera, bounds.max.as_dvec3() - camera))
}

/// Tight fit: the light-space bounds of the slice corners, or of the slice's part inside the
/// receivers' box where they meet, as offsets from the camera.
fn tight_coverage(
    basis: &CameraBasis,
    rot: &DMat3,
    (near, far): (f64, f64),
    receivers: Option<(DVec3, DVec3)>,
    resolution: f64,
) -> Coverage {
    // NOTE: the corners are taken relative to the camera *before* rotating, so the extents
    // do not depend on the camera position at all: translating the camera cannot change
    // the box size, not even by a rounding error (unless the receivers' box clips it).
    let corners = basis.slice_offsets(near, far);
    let offsets = corners.map(|o| *rot * o);
    let lo = offsets.iter().fold(DVec3::INFINITY, |a, &o| a.min(o));
    let hi = offsets.iter().fold(DVec3::NEG_INFINITY, |a, &o| a.max(o));
    let whole = Coverage { lo, hi, top: hi.z };
    match receivers.and_then(|(min, max)| clipped_bounds(&corners, min, max, rot)) {
        Some((lo, hi)) => whole.clipped(lo, hi, resolution),
        None => whole,
    }
}

/// Stable fit: a sphere around the camera reaching the slice's farthest corner, cut to the
/// light-space bounds of the receivers' box where they meet (both are fixed while the camera
/// turns in place).
fn stable_coverage(
    basis: &CameraBasis,
    rot: &DMat3,
    far: f64,
    receivers: Option<(DVec3, DVec3)>,
    resolution: f64,
) -> Coverage {
    // NOTE: the radius is computed from the projection parameters, not from rotated corner
    // positions, so it is bit-identical for every camera orientation.
    let radius = far * (1.0 + basis.tan_half_x * basis.tan_half_x + basis.tan_half_y * basis.tan_half_y).sqrt();
    let (lo, hi) = (DVec3::splat(-radius), DVec3::splat(radius));
    if let Some((min, max)) = receivers {
        let corners: [DVec3; 8] = std::array::from_fn(|i| {
            DVec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        });
        let (blo, bhi) = corners
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &c| {
                (a.min(*rot * c), b.max(*rot * c))
            });
        let (clo, chi) = (lo.max(blo), hi.min(bhi));
        if clo.cmple(chi).all() {
            return Coverage { lo, hi, top: hi.z }.clipped(clo, chi, resolution);
        }
    }
    Coverage { lo, hi, top: hi.z }
}

/// The top (towards the light) of the caster bounds in the light frame, if usable.
fn caster_top(rot: &DMat3, bounds: &Aabb) -> Option<f64> {
    if bounds.is_empty() || !bounds.is_finite() {
        return None;
    }
    let row = rot.row(2);
    // NOTE: in f64: the f32 sum or difference of huge finite bounds could overflow.
    let (min, max) = (bounds.min.as_dvec3(), bounds.max.as_dvec3());
    let center = (min + max) * 0.5;
    let half = (max - min) * 0.5;
    Some(row.dot(center) + row.abs().dot(half))
}

/// Per-frame values shared by every cascade.
struct Frame {
    /// Shared light rotation (f32 values in f64).
    rot: DMat3,
    /// Camera position in the light frame.
    camera: DVec3,
    /// Top of the scene's casters in the light frame.
    caster_top: Option<f64>,
    /// Shadow-map resolution (at least 2).
    resolution: f64,
}

impl Frame {
    /// Fits, snaps and projects one cascade box.
    fn cascade(&self, cov: &Coverage, near: f32, far: f32, angular_diameter: f32) -> Cascade {
        let lo = self.camera + cov.lo;
        let hi = self.camera + cov.hi;
        let spread = cov.hi - cov.lo;

        let x = snap_interval(lo.x, spread.x, self.resolution, MIN_BOX_EXTENT);
        let y = snap_interval(lo.y, spread.y, self.resolution, MIN_BOX_EXTENT);

        // Depth: far side at the coverage bottom, near side at the whole slice's top raised
        // to the casters' top.
        let slice_top = self.camera.z + cov.top;
        let z_max = match self.caster_top {
            Some(top) => slice_top.max(top.min(slice_top + MAX_CASTER_REACH)),
            None => slice_top,
        };
        let depth_range = (z_max - lo.z).max(MIN_BOX_EXTENT);
        let z_min = z_max - depth_range;

        let pcss = pcss_params_f64(angular_diameter, x.width, y.width, depth_range);
        let receiver_start = ((z_max - hi.z) / depth_range).clamp(0.0, 1.0);
        let light_min = Vec3::new(f32_down(x.min()), f32_down(y.min()), f32_down(z_min));
        // NOTE: rounded outwards, and at least one ulp apart: far beyond any real scene the
        // extent can vanish even in f64, but the published box must never be flat.
        let light_max = Vec3::new(f32_up(x.max()), f32_up(y.max()), f32_up(z_max)).max(light_min.map(f32::next_up));
        Cascade {
            clip_from_world: self.clip_from_world(&x, &y, z_min, depth_range),
            near,
            far,
            light_min,
            light_max,
            texel_world_size: f32_sat(x.texel),
            depth_range: f32_sat(depth_range),
            light_size_uv: pcss.light_size_uv,
            pcss_scale: pcss.pcss_scale,
            uv_scale_y: pcss.uv_scale_y,
            // NOTE: rounded down, so the span it starts is never shorter than the slice's.
            receiver_start: f32_down(receiver_start).clamp(0.0, 1.0),
        }
    }

    /// `ortho_reverse_z(box) · light_from_world(rot, 0)`, assembled row by row.
    fn clip_from_world(&self, x: &TexelSnap, y: &TexelSnap, z_min: f64, depth: f64) -> Mat4 {
        let res = self.resolution;
        // clip.x = 2·(x_l − x.min)/width − 1 = (2/width)·x_l − 2·first_texel/res − 1.
        // NOTE: the constant is formed from the integer texel index, not from x.min: for a
        // power-of-two resolution it is then exact in f32, and since the linear part only
        // depends on the (quantised) width, a camera translation changes the f32 matrix by
        // exactly a whole number of texels, however far from the origin the camera is.
        let row_x = (self.rot.row(0) * (2.0 / x.width)).extend(-2.0 * x.first_texel / res - 1.0);
        let row_y = (self.rot.row(1) * (2.0 / y.width)).extend(-2.0 * y.first_texel / res - 1.0);
        // clip.z = (z_l − z_min) / depth: 1 at the near (light) side, 0 at the far side.
        let row_z = (self.rot.row(2) / depth).extend(-z_min / depth);
        let rows = [row_x, row_y, row_z, DVec4::W];
        Mat4::from_cols_array_2d(&std::array::from_fn(|col| {
            std::array::from_fn(|row| f32_sat(rows[row][col]))
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::frustum::slice_corners;
    use crate::math::light_space::light_from_world;
    use crate::math::projection::ortho_reverse_z;
    use glam::Quat;

    fn input(fit: CascadeFit) -> CascadeInput {
        CascadeInput {
            camera: CameraView {
                world_from_view: Mat4::from_rotation_translation(
                    Quat::from_euler(glam::EulerRot::YXZ, 0.6, -0.2, 0.0),
                    Vec3::new(12.0, 1.8, -40.0),
                ),
                fov_y: 1.0,
                aspect: 16.0 / 9.0,
                near: 0.1,
                far: 1000.0,
            },
            light_direction: Vec3::new(0.3, -0.8, 0.5),
            scene_bounds: Aabb::new(Vec3::new(-200.0, -5.0, -200.0), Vec3::new(200.0, 60.0, 200.0)),
            receiver_bounds: Aabb::EMPTY,
            count: 4,
            split_lambda: 0.6,
            max_distance: 150.0,
            resolution: 2048,
            fit,
            angular_diameter: 0.0093,
            blend_width: 0.0,
        }
    }

    fn project(m: Mat4, p: Vec3) -> Vec3 {
        (m * p.extend(1.0)).truncate()
    }

    #[test]
    fn slices_fit_inside_their_boxes() {
        for fit in [CascadeFit::Tight, CascadeFit::Stable] {
            let inp = input(fit);
            let set = compute_cascades(&inp);
            assert_eq!(set.count, 4);
            assert_eq!(set.splits[0], 0.1);
            assert_eq!(set.splits[4], 150.0);
            for (i, c) in set.active().iter().enumerate() {
                assert_eq!((c.near, c.far), (set.splits[i], set.splits[i + 1]));
                for p in slice_corners(&inp.camera, c.near, c.far) {
                    let q = project(c.clip_from_world, p);
                    assert!(q.x.abs() <= 1.0 + 1e-5 && q.y.abs() <= 1.0 + 1e-5, "{i} {q}");
                    assert!(q.z >= -1e-5 && q.z <= 1.0 + 1e-5, "{i} {q}");
                    let l = set.light_rotation * p;
                    assert!(l.cmpge(c.light_min - 1e-4).all() && l.cmple(c.light_max + 1e-4).all());
                }
            }
        }
    }

    #[test]
    fn matrix_is_ortho_times_light_view_of_the_box() {
        let set = compute_cascades(&input(CascadeFit::Tight));
        for c in set.active() {
            let (lo, hi) = (c.light_min, c.light_max);
            // The light looks down −Z, so near distance = −z_max and far distance = −z_min.
            let want = ortho_reverse_z(lo.x, hi.x, lo.y, hi.y, -hi.z, -lo.z)
                * light_from_world(set.light_rotation, Vec3::ZERO);
            for p in [Vec3::new(3.0, 2.0, 1.0), Vec3::new(-50.0, 10.0, -80.0)] {
                let a = project(c.clip_from_world, p);
                let b = project(want, p);
                assert!(a.abs_diff_eq(b, 1e-4), "{a} vs {b}");
            }
        }
    }

    #[test]
    fn near_plane_reaches_the_scene_casters() {
        let inp = input(CascadeFit::Tight);
        let set = compute_cascades(&inp);
        let top = inp
            .scene_bounds
            .corners()
            .map(|p| (set.light_rotation * p).z)
            .into_iter()
            .fold(f32::MIN, f32::max);
        for c in set.active() {
            assert!(c.light_max.z >= top - 1e-3, "{} < {top}", c.light_max.z);
        }
        // The slice's corners lie in the receiver span [receiver_start, 1] of the box's depth.
        for (c, i) in set.active().iter().zip(0..) {
            assert!(c.receiver_start > 0.0 && c.receiver_start < 1.0, "{c:?}");
            for p in slice_corners(&inp.camera, c.near, c.far) {
                let d = 1.0 - project(c.clip_from_world, p).z;
                assert!(d >= c.receiver_start - 1e-5 && d <= 1.0 + 1e-5, "cascade {i}: {d}");
            }
        }
        // Without scene bounds the box is only as deep as the slice.
        let bare = compute_cascades(&CascadeInput {
            scene_bounds: Aabb::EMPTY,
            ..inp
        });
        for (a, b) in bare.active().iter().zip(set.active()) {
            assert_eq!(a.receiver_start, 0.0);
            assert!(a.depth_range < b.depth_range);
            assert_eq!(a.light_min.z, b.light_min.z);
        }
    }

    #[test]
    fn derived_values_follow_their_formulas() {
        let inp = input(CascadeFit::Tight);
        let set = compute_cascades(&inp);
        for c in set.active() {
            let wx = c.light_max.x - c.light_min.x;
            let wy = c.light_max.y - c.light_min.y;
            assert!((c.texel_world_size - wx / 2048.0).abs() <= 1e-5 * wx);
            assert!((c.depth_range - (c.light_max.z - c.light_min.z)).abs() <= 1e-4);
            let s = 2.0 * (inp.angular_diameter * 0.5).tan();
            assert!((c.light_size_uv - s / wx).abs() <= 1e-5 * c.light_size_uv);
            assert!((c.pcss_scale - c.depth_range * s / wx).abs() <= 1e-5 * c.pcss_scale);
            assert!((c.uv_scale_y - wx / wy).abs() <= 1e-5);
            // Texel size from the matrix's first row, as in the seed: 2·(1/res)/|row0|.
            let row0 = c.clip_from_world.row(0).truncate().length();
            assert!((2.0 / 2048.0 / row0 - c.texel_world_size).abs() <= 1e-5 * wx);
        }
    }

    #[test]
    fn stable_boxes_are_square_and_unused_cascades_default() {
        let set = compute_cascades(&CascadeInput {
            count: 2,
            ..input(CascadeFit::Stable)
        });
        assert_eq!(set.count, 2);
        for c in set.active() {
            assert_eq!(c.uv_scale_y, 1.0);
        }
        assert_eq!(set.cascades[2], Cascade::default());
        assert_eq!(set.splits[2..], [150.0; 3]);
        assert_eq!(set.far_splits(), Vec4::new(set.splits[1], 150.0, 150.0, 150.0));
    }

    #[test]
    fn snapping_moves_by_whole_texels() {
        let inp = input(CascadeFit::Tight);
        let a = compute_cascades(&inp);
        let mut moved = inp;
        let t = a.cascades[0].texel_world_size;
        moved.camera.world_from_view.w_axis += Vec4::new(0.37 * t, -0.21 * t, 0.44 * t, 0.0);
        let b = compute_cascades(&moved);
        let p = Vec3::new(20.0, 0.0, -60.0);
        for (ca, cb) in a.active().iter().zip(b.active()) {
            let ua = project(ca.clip_from_world, p).truncate().as_dvec2() * 1024.0;
            let ub = project(cb.clip_from_world, p).truncate().as_dvec2() * 1024.0;
            let d = ub - ua;
            assert!((d - d.round()).abs().max_element() < 1e-3, "{d}");
        }
    }

    #[test]
    fn degenerate_inputs_stay_finite() {
        let mut inp = input(CascadeFit::Tight);
        inp.light_direction = Vec3::ZERO;
        inp.camera.fov_y = 0.0;
        inp.camera.aspect = 0.0;
        inp.camera.near = 0.0;
        inp.camera.far = 0.0;
        inp.resolution = 0;
        inp.count = 0;
        inp.angular_diameter = f32::NAN;
        inp.scene_bounds = Aabb::new(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX));
        let mut far_away = inp;
        far_away.camera.near = 1e38;
        far_away.camera.far = f32::MAX;
        far_away.camera.fov_y = std::f32::consts::PI;
        far_away.camera.aspect = f32::MAX;
        far_away.max_distance = f32::MAX;
        far_away.camera.world_from_view.w_axis = Vec4::new(f32::MAX, -f32::MAX, f32::MAX, 1.0);
        far_away.light_direction = Vec3::new(1.0, 1.0, 1.0);
        for fit in [CascadeFit::Tight, CascadeFit::Stable] {
            for base in [inp, far_away] {
                let set = compute_cascades(&CascadeInput { fit, ..base });
                assert_eq!(set.count, 1);
                let c = set.cascades[0];
                assert!(c.clip_from_world.is_finite() && c.light_min.is_finite(), "{c:?}");
                assert!(c.light_max.is_finite(), "{c:?}");
                assert!(c.texel_world_size > 0.0 && c.depth_range > 0.0, "{c:?}");
                assert!(c.light_max.cmpgt(c.light_min).all(), "{c:?}");
            }
        }
    }
}
