//! Cascaded shadow maps for a directional light: split the view frustum by depth, fit one
//! reverse-Z orthographic box per slice in a light frame shared by all cascades, and
//! stabilise the boxes so camera motion moves shadows by whole texels only.

use glam::{DMat3, DVec3, DVec4, I64Vec2, Mat3, Mat4, Vec2, Vec3, Vec4};
use serde::{Deserialize, Serialize};

use crate::math::aabb::Aabb;
use crate::math::cascade_coverage::{Coverage, receivers_from_camera, stable_coverage, tight_coverage};
use crate::math::frustum::CameraView;
use crate::math::light_space::light_rotation;
use crate::math::pcss::pcss_params_f64;
use crate::math::seen_depths::SeenDepths;
use crate::math::snapping::{TexelSnap, f32_down, f32_sat, f32_up, quantize_extent_up, snap_interval, snap_outwards};
use crate::math::splits::wide_view_splits;

pub use crate::math::cascade_coverage::FILTER_REACH_TEXELS;
pub use crate::math::splits::MAX_CASCADES;

/// The most views a sun's set holds: [`MAX_CASCADES`] cascades, or up to this many clipmap
/// levels ([`crate::math::clipmap::MAX_CLIPMAP_LEVELS`]).
pub const MAX_SUN_VIEWS: usize = 8;

/// How each cascade's orthographic box is fitted to its slice of the view frustum.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum CascadeFit {
    /// XY fitted tightly to the slice corners in light space: the most texels on screen,
    /// but the box changes size as the camera turns.
    #[default]
    Tight,
    /// A sphere around the camera position that reaches the slice's farthest corner: a few
    /// texels are wasted behind the camera, but turning in place never changes the cascades.
    Stable,
    /// Sample-distribution (SDSM) fit: the splits divide the view depths the camera's pixels
    /// covered logarithmically (`split_lambda` is not used), and each box is the Tight fit of its slice cut to the world box those pixels
    /// spanned at its depths. The renderer reduces each frame's depth buffer on the GPU and a
    /// later frame fits to it (every bound grown by a guard band of
    /// [`SEEN_GUARD`](crate::math::seen_depths::SEEN_GUARD)); until a reduction has come back
    /// (the first frames, or without a renderer) it fits as Tight. Shadows still fade at
    /// `max_distance`.
    DepthBounds,
}

/// Smallest lateral extent or depth range of a cascade box, in world units.
///
/// Deliberately absolute (not relative to the camera's distance from the origin) so that the
/// box size never depends on the camera position. The published f32 bounds stay ordered
/// even when this is below an f32 ulp, because they are rounded outwards.
pub const MIN_BOX_EXTENT: f64 = 1.0e-4;

/// Steps a cascade's depth range snaps to: its near and far planes move in steps of
/// `1 / HOLD_DEPTH_STEPS` of it (rounded onto the extent grid), so a camera moving less than
/// that keeps them (the range grows by under 1/64, 1.6 %).
pub const HOLD_DEPTH_STEPS: f64 = 64.0;

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
    /// Fewest cells per side of the grid each box starts on (0: no fewest). A box holds
    /// still, and its map need not be drawn again, while the camera moves within a cell. A
    /// cell is the whole texels the box's extent, rounded up onto its grid, leaves over what
    /// it must cover (free: the rounding wastes them anyway; a single texel where it leaves
    /// none), or `1 / snap_cells` of the box where that is more, the box then one such cell
    /// wider to pay for it; at most a quarter of the box. The depth range snaps to steps of
    /// [`1 / HOLD_DEPTH_STEPS`](HOLD_DEPTH_STEPS) of itself.
    pub snap_cells: u32,
    /// The boxes scroll ([`CascadeSet::scrolls`]): a box that moved by whole texels keeps its
    /// map where its depth range held, so the range moves in steps of
    /// [`1 / HOLD_DEPTH_STEPS`](HOLD_DEPTH_STEPS) of itself, no longer than a lateral cell or
    /// a 64th of the box's width, whichever is longer.
    pub scroll: bool,
    /// What an earlier frame's camera saw, for [`CascadeFit::DepthBounds`] (ignored by the
    /// other fits; None fits as Tight). Its world boxes are in this input's world frame.
    pub seen: Option<SeenDepths>,
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
    /// The grid the box snapped to ([`CascadeInput::snap_cells`]): `x`, `y` the world size
    /// of a cell, `z` the depth step (zero for clipmap levels). Culling widens its
    /// receiver-bounded volume to it ([`crate::math::receivers::snap_to_grid`]) so that volume, too, holds
    /// while the camera moves within a cell.
    pub hold_grid: Vec3,
    /// The texel grid of the light frame the box lies on: the box's first texel and a
    /// texel's world size along light x and y. Every box of the same size and depth range
    /// is the same map moved by whole texels of this grid ([`CascadeSet::scrolls`]).
    pub grid: TexelGrid,
}

/// A grid of shadow texels fixed in the light frame: `first_texel` the grid index (light x,
/// y) of a view's first texel, `texel` a texel's world size along x and y.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TexelGrid {
    /// Grid index of the view's first texel.
    pub first_texel: I64Vec2,
    /// World size of a texel along light x and y.
    pub texel: Vec2,
}

impl TexelGrid {
    /// `clip_from_world` of a view on this kind of grid with its first texel moved to the
    /// grid's origin: equal for every box of one size and depth range, wherever it lies (its
    /// first texel only adds a whole number of texels to clip x and y). What a scrolling
    /// view's texels hold depends on this matrix alone.
    pub fn at_origin(clip_from_world: Mat4) -> Mat4 {
        let mut m = clip_from_world;
        m.w_axis.x = -1.0;
        m.w_axis.y = -1.0;
        m
    }
}

/// The cascades of one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CascadeSet {
    /// Number of valid cascades, `1..=MAX_CASCADES` (clipmap levels: up to
    /// [`MAX_SUN_VIEWS`]; 0 only for `Default`).
    pub count: usize,
    /// The cascades; entries from `count` on are `Cascade::default()`.
    pub cascades: [Cascade; MAX_SUN_VIEWS],
    /// Split view depths: cascade `i` covers `[splits[i], splits[i + 1]]`; entries after
    /// `count` repeat the last.
    pub splits: [f32; MAX_CASCADES + 1],
    /// View depth where shadows end (they fade out before it): `splits[count]`, except with
    /// [`CascadeFit::DepthBounds`], whose last split may stop short of it where nothing
    /// farther was seen.
    pub end: f32,
    /// The light rotation (`light_from_world`, rotation only) shared by every cascade.
    pub light_rotation: Mat3,
    /// The views are clipmap levels ([`crate::math::clipmap`]): a receiver picks one by its
    /// light-frame position, not by its view depth, and `splits` are unused.
    pub clipmap: bool,
    /// Its views scroll: a view whose box keeps its size and depth range while moving by
    /// whole texels of its [`Cascade::grid`] keeps its map, and only the texels the box
    /// newly covers are drawn (clipmap levels always; cascades when
    /// [`CascadeSettings::scroll`](crate::settings::CascadeSettings::scroll) asks for it).
    pub scrolls: bool,
}

impl CascadeSet {
    /// The valid cascades.
    pub fn active(&self) -> &[Cascade] {
        &self.cascades[..self.count.min(MAX_SUN_VIEWS)]
    }

    /// The coarsest step of a depth stored in `steps` steps (65 535 for 16-bit unorm) among
    /// the active cascades, in shadow texels: the largest `depth_range / steps` over the
    /// cascade's `texel_world_size`; 0 without cascades.
    pub fn depth_step_in_texels(&self, steps: f32) -> f32 {
        let step = |c: &Cascade| c.depth_range / steps / c.texel_world_size;
        self.active()
            .iter()
            .map(step)
            .filter(|s| s.is_finite())
            .fold(0.0, f32::max)
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
    let tan_half = basis.tan_half_x.max(basis.tan_half_y);
    let plain = wide_view_splits(near, shadow_far, count, input.split_lambda, tan_half);
    let seen = match input.fit {
        CascadeFit::DepthBounds => input.seen.as_ref(),
        CascadeFit::Tight | CascadeFit::Stable => None,
    };
    // NOTE: logarithmic splits over the seen range (as SDSM does): PSSM blends towards linear
    // because a log split from a near plane far in front of anything seen wastes the first
    // cascades; from the nearest depth seen, the log split keeps the texel-to-pixel ratio
    // even. With the scene's λ the field's first cascade grew from 10 to 17 m and its
    // penumbra error rose; logarithmic, it fell (tight 0.211, λ 0.226, log 0.194, PCF).
    let splits = seen
        .and_then(|seen| seen_splits(seen, (plain[0], plain[count]), count, tan_half))
        .unwrap_or(plain);

    let light_rotation = light_rotation(input.light_direction);
    // NOTE: all geometry is done in f64 but with the *f32* rotation the set publishes, so
    // culling (which only has the f32 matrix) and the boxes agree exactly.
    let rot = light_rotation.as_dmat3();
    let frame = Frame {
        rot,
        camera: rot * basis.position,
        caster_top: caster_top(&rot, &input.scene_bounds),
        resolution: f64::from(input.resolution.max(2)),
        cells: f64::from(input.snap_cells),
        scroll: input.scroll,
    };

    let mut cascades = [Cascade::default(); MAX_SUN_VIEWS];
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
        let receivers = match seen {
            Some(seen) => seen_receivers(seen, &input.receiver_bounds, covered_near as f32, far),
            None => input.receiver_bounds,
        };
        let receivers = receivers_from_camera(&receivers, basis.position);
        let coverage = match input.fit {
            CascadeFit::Tight | CascadeFit::DepthBounds => tight_coverage(
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
        end: plain[count],
        light_rotation,
        clipmap: false,
        scrolls: input.scroll,
    }
}

/// Logarithmic splits over the view depths `seen` covered (guarded, within `(near, end)`),
/// the first
/// moved back to `near` so nothing nearer goes unshadowed; None where that range is empty
/// (everything seen lies past `end`).
fn seen_splits(
    seen: &SeenDepths,
    (near, end): (f32, f32),
    count: usize,
    tan_half: f64,
) -> Option<[f32; MAX_CASCADES + 1]> {
    let (lo, hi) = seen.guarded_range();
    let (lo, hi) = (lo.max(near), hi.min(end));
    // NOTE: also None where either bound is NaN.
    if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
        return None;
    }
    let mut splits = wide_view_splits(lo, hi, count, 1.0, tan_half);
    splits[0] = near;
    Some(splits)
}

/// The receivers of the slice `[near, far]`: the world box of what was seen at those depths,
/// cut to `receivers` where both are usable and meet; the usable one otherwise.
fn seen_receivers(seen: &SeenDepths, receivers: &Aabb, near: f32, far: f32) -> Aabb {
    let (lo, hi) = seen.guarded_range();
    let seen = seen.bounds_between(near.max(lo), far.min(hi));
    if seen.is_empty() {
        return *receivers;
    }
    if receivers.is_empty() || !receivers.is_finite() {
        return seen;
    }
    let cut = Aabb::new(seen.min.max(receivers.min), seen.max.min(receivers.max));
    if cut.is_empty() { *receivers } else { cut }
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
    /// Fewest cells per side of the grid boxes start on (0: no fewest).
    cells: f64,
    /// The boxes scroll: the depth step may reach a 64th of the box's width where its
    /// lateral cells are smaller.
    scroll: bool,
}

impl Frame {
    /// Fits, snaps and projects one cascade box.
    fn cascade(&self, cov: &Coverage, near: f32, far: f32, angular_diameter: f32) -> Cascade {
        let lo = self.camera + cov.lo;
        let hi = self.camera + cov.hi;
        let spread = cov.hi - cov.lo;

        let min_cell = if self.cells > 0.0 {
            (self.resolution / self.cells).floor()
        } else {
            1.0
        };
        let x = snap_interval(lo.x, spread.x, self.resolution, MIN_BOX_EXTENT, min_cell);
        let y = snap_interval(lo.y, spread.y, self.resolution, MIN_BOX_EXTENT, min_cell);

        // Depth: far side at the coverage bottom, near side at the whole slice's top raised
        // to the casters' top, both widened to whole depth steps.
        let slice_top = self.camera.z + cov.top;
        let z_max = match self.caster_top {
            Some(top) => slice_top.max(top.min(slice_top + MAX_CASTER_REACH)),
            None => slice_top,
        };
        // NOTE: a step of the whole depth range (rounded onto the extent grid, so it holds
        // while the range changes a little), not of the slice's: the near plane usually sits
        // at the casters' top, far above a near cascade's slice, and a step of the slice's
        // depth moved the far side every few frames. No longer than a lateral cell: under a
        // low sun the range is far deeper than the box is wide, and a 64th of it added bias
        // in metres enough to open leaks at the casters' feet (the hard cases' 0.5° sun).
        // A scrolling box keeps its map while its range holds, whatever its lateral cells: its
        // step may reach a 64th of its width where its cells are smaller (a 64th of the range
        // under a 0.5° sun let 6 of 498 umbra pixels of the hard cases leak, a 64th of the
        // width 4).
        let whole_step = quantize_extent_up(z_max - lo.z) / HOLD_DEPTH_STEPS;
        let cell = (x.cell * x.texel).min(y.cell * y.texel);
        let depth_step = if self.scroll {
            whole_step.min(cell.max(x.width.min(y.width) / HOLD_DEPTH_STEPS))
        } else {
            whole_step.min(cell)
        };
        let snapped = snap_outwards(lo.z, z_max, depth_step);
        // NOTE: a near side at the casters' top does not move with the camera: it keeps its
        // place, so the range grows by under one step, not two. Near the end of f32's range
        // a step can carry a bound past it; such a box keeps its exact depth.
        let top = if z_max > slice_top { z_max } else { snapped.1 };
        let limit = f64::from(f32::MAX) / 4.0;
        let (z_far, z_max) = if snapped.0 > -limit && top < limit {
            (snapped.0, top)
        } else {
            (lo.z, z_max)
        };
        let depth_range = (z_max - z_far).max(MIN_BOX_EXTENT);
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
            hold_grid: Vec3::new(
                f32_sat(x.cell * x.texel),
                f32_sat(y.cell * y.texel),
                f32_sat(depth_step),
            ),
            grid: TexelGrid {
                first_texel: I64Vec2::new(x.first_texel as i64, y.first_texel as i64),
                texel: Vec2::new(f32_sat(x.texel), f32_sat(y.texel)),
            },
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
#[path = "cascades_tests.rs"]
mod tests;
