//! The clipmap of a directional light: up to [`MAX_CLIPMAP_LEVELS`] concentric square levels
//! in the light's frame, centred on the camera, level `i` covering `level0_extent · 2^i`
//! metres with the same number of texels, so each level's texels are twice the size of the
//! level below.
//!
//! Every level's window starts on a whole texel of a grid fixed in the (render-origin
//! relative) light frame, so a texel keeps its place in the world however the camera moves:
//! turning the camera changes nothing, and moving it shifts each window by whole texels. The
//! depth range of every level covers every caster of the scene (rounded out onto a coarse
//! grid), so it does not change with the camera either. A window that moves keeps the
//! texels it still covers and only the strips newly exposed are drawn ([`exposed_strips`]):
//! a layer filtered by depth comparisons wraps (its texels stay put and the window's first
//! texel moves round it, [`wrapped_parts`]), one filtering moments is moved by the window's
//! shift.
//!
//! A receiver samples the finest level whose window holds it with a margin for the filter
//! ([`select_level`]) and blends into the next level across a band at the window's edge.

use glam::{DVec3, I64Vec2, Mat3, Mat4, Vec2, Vec3};

use crate::math::aabb::Aabb;
use crate::math::cascades::{Cascade, CascadeSet, MAX_CASCADES, TexelGrid};
use crate::math::footprint::TexelRect;
use crate::math::light_space::light_rotation;
use crate::math::pcss::pcss_params_f64;
use crate::math::snapping::{f32_down, f32_sat, f32_up, quantize_extent_up};

/// The most levels a clipmap has.
pub const MAX_CLIPMAP_LEVELS: usize = 8;

/// Depth steps per level depth range: the range's start is snapped down to a sixteenth of
/// its (quantised) length, so casters moving a little do not change it.
const DEPTH_STEPS: f64 = 16.0;

/// What a clipmap is made from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipmapInput {
    /// The camera's position (relative to the render origin).
    pub camera_position: Vec3,
    /// The direction the light travels.
    pub light_direction: Vec3,
    /// Number of levels, 1–[`MAX_CLIPMAP_LEVELS`].
    pub levels: u32,
    /// Side of level 0, metres.
    pub level0_extent: f32,
    /// Texels per side of every level (even).
    pub resolution: u32,
    /// World bounds of every caster.
    pub casters: Aabb,
}

/// One level of a clipmap.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClipmapLevel {
    /// Grid index (light-frame x, y) of the window's first texel.
    pub first_texel: I64Vec2,
    /// Side of the window, metres.
    pub extent: f32,
    /// Side of a texel, metres.
    pub texel: f32,
    /// Light-frame z of the far end of the depth range (depth 0).
    pub z_min: f32,
    /// Length of the depth range, metres (depth 1 at `z_min + depth`, the light's side).
    pub depth: f32,
    /// Light clip space from world (reverse-Z) of the whole window.
    pub clip_from_world: Mat4,
}

impl ClipmapLevel {
    /// The window's smallest light-frame x, y.
    pub fn min(&self) -> Vec2 {
        (self.first_texel.as_dvec2() * f64::from(self.texel)).as_vec2()
    }

    /// The window's largest light-frame x, y.
    pub fn max(&self) -> Vec2 {
        self.min() + Vec2::splat(self.extent)
    }
}

/// A directional light's clipmap this frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClipmapSet {
    /// Light frame from world (rotation only).
    pub light_rotation: Mat3,
    /// The levels, finest first; `count` are valid.
    pub levels: [ClipmapLevel; MAX_CLIPMAP_LEVELS],
    /// Number of valid levels.
    pub count: usize,
}

impl ClipmapSet {
    /// The valid levels.
    pub fn active(&self) -> &[ClipmapLevel] {
        &self.levels[..self.count.min(MAX_CLIPMAP_LEVELS)]
    }
}

/// The depth range covering `casters` along light-frame z: `(z_min, depth)`, the length
/// rounded up onto a logarithmic grid and the start down onto a sixteenth of it.
fn depth_range(rotation: Mat3, casters: &Aabb) -> (f64, f64) {
    if casters.is_empty() || !casters.is_finite() {
        return (-1.0, 2.0);
    }
    let rot = rotation.as_dmat3();
    let (lo, hi) = casters.corners().iter().fold((f64::MAX, f64::MIN), |(lo, hi), c| {
        let z = (rot * c.as_dvec3()).z;
        (lo.min(z), hi.max(z))
    });
    let depth = quantize_extent_up((hi - lo).max(0.01) * (1.0 + 2.0 / DEPTH_STEPS));
    let step = depth / DEPTH_STEPS;
    let z_min = (lo / step).floor() * step - step;
    let depth = if z_min + depth < hi {
        quantize_extent_up(hi - z_min)
    } else {
        depth
    };
    (z_min, depth)
}

/// The levels of a directional light's clipmap: each centred on the camera's light-frame
/// position rounded to its own texel grid.
pub fn compute_clipmap(input: &ClipmapInput) -> ClipmapSet {
    let rotation = light_rotation(input.light_direction);
    let count = (input.levels as usize).clamp(1, MAX_CLIPMAP_LEVELS);
    let resolution = i64::from(input.resolution.max(2) & !1);
    let camera = rotation.as_dmat3() * input.camera_position.as_dvec3();
    let (z_min, depth) = depth_range(rotation, &input.casters);
    let level0 = f64::from(input.level0_extent.max(1e-3));
    let mut set = ClipmapSet {
        light_rotation: rotation,
        count,
        ..ClipmapSet::default()
    };
    for (i, level) in set.levels.iter_mut().take(count).enumerate() {
        let extent = level0 * f64::from(1u32 << i);
        let texel = extent / resolution as f64;
        let centre = I64Vec2::new((camera.x / texel).round() as i64, (camera.y / texel).round() as i64);
        let first_texel = centre - I64Vec2::splat(resolution / 2);
        *level = ClipmapLevel {
            first_texel,
            extent: extent as f32,
            texel: texel as f32,
            z_min: z_min as f32,
            depth: depth as f32,
            clip_from_world: region_clip_from_world(
                rotation,
                first_texel,
                I64Vec2::splat(resolution),
                texel,
                z_min,
                depth,
            ),
        };
    }
    set
}

/// `level` of a clipmap of `resolution`² texel levels in the light frame `rotation`, with its
/// window moved to start at grid texel `first_texel` (a paged level's window starts on a
/// whole page).
pub fn moved_level(rotation: Mat3, level: &ClipmapLevel, first_texel: I64Vec2, resolution: u32) -> ClipmapLevel {
    let texel = f64::from(level.extent) / f64::from(resolution.max(1));
    ClipmapLevel {
        first_texel,
        clip_from_world: region_clip_from_world(
            rotation,
            first_texel,
            I64Vec2::splat(i64::from(resolution)),
            texel,
            f64::from(level.z_min),
            f64::from(level.depth),
        ),
        ..*level
    }
}

/// Light clip space from world of the region of `size` texels starting at grid texel `first`
/// and the depth range `[z_min, z_min + depth]`.
fn region_clip_from_world(rotation: Mat3, first: I64Vec2, size: I64Vec2, texel: f64, z_min: f64, depth: f64) -> Mat4 {
    let rot = rotation.as_dmat3();
    // NOTE: clip = 2·(x_l − first·texel)/(size·texel) − 1, formed from the integer indices.
    let width = size.as_dvec2() * texel;
    let row_x = (rot.row(0) * (2.0 / width.x)).extend(-2.0 * first.x as f64 / size.x as f64 - 1.0);
    let row_y = (rot.row(1) * (2.0 / width.y)).extend(-2.0 * first.y as f64 / size.y as f64 - 1.0);
    let row_z = (rot.row(2) / depth).extend(-z_min / depth);
    let rows = [row_x, row_y, row_z, glam::DVec4::W];
    Mat4::from_cols_array_2d(&std::array::from_fn(|col| {
        std::array::from_fn(|row| f32_sat(rows[row][col]))
    }))
}

/// Which level a receiver at light-frame `xy` samples: the finest whose window holds it at
/// least `margin_texels` of that level's texels inside every edge, and how far (0–1) it is
/// into the band of `blend` (a fraction of the window's half side) along the inner edge of
/// that margin, where it blends into the next level (0 in the last level). None outside
/// every level.
pub fn select_level(set: &ClipmapSet, xy: Vec2, margin_texels: f32, blend: f32) -> Option<(usize, f32)> {
    let levels = set.active();
    for (i, level) in levels.iter().enumerate() {
        let margin = margin_texels * level.texel;
        let (lo, hi) = (level.min() + margin, level.max() - margin);
        if xy.cmplt(lo).any() || xy.cmpgt(hi).any() {
            continue;
        }
        if i + 1 == levels.len() {
            return Some((i, 0.0));
        }
        let band = (blend.clamp(0.0, 1.0) * 0.5 * level.extent).max(1e-6);
        let inside = (xy - lo).min(hi - xy).min_element();
        return Some((i, (1.0 - inside / band).clamp(0.0, 1.0)));
    }
    None
}

/// The light-frame position of a world point.
pub fn light_xy(set: &ClipmapSet, world: Vec3) -> Vec2 {
    (set.light_rotation * world).truncate()
}

/// A rectangle of grid texels `[min, max)`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GridRect {
    /// First texel.
    pub min: I64Vec2,
    /// One past the last texel.
    pub max: I64Vec2,
}

impl GridRect {
    /// Texels inside (0 when empty).
    pub fn area(&self) -> u64 {
        let size = (self.max - self.min).max(I64Vec2::ZERO);
        (size.x * size.y) as u64
    }

    /// The overlap with `other` (empty when they do not meet).
    pub fn intersect(&self, other: &GridRect) -> GridRect {
        GridRect {
            min: self.min.max(other.min),
            max: self.max.min(other.max).max(self.min.max(other.min)),
        }
    }
}

/// The grid texels of a window of `resolution` texels a side starting at grid texel
/// `first_texel` (a clipmap level's, or a scrolling cascade's, [`Cascade::grid`]).
pub fn window(first_texel: I64Vec2, resolution: u32) -> GridRect {
    GridRect {
        min: first_texel,
        max: first_texel + I64Vec2::splat(i64::from(resolution)),
    }
}

/// The grid texels (of texels `texel` wide along x and y) that the light-frame rectangle
/// `[lo, hi]` touches, rounded out by a texel.
pub fn covering_texels(lo: Vec2, hi: Vec2, texel: Vec2) -> GridRect {
    GridRect {
        min: (lo / texel).floor().as_i64vec2() - I64Vec2::ONE,
        max: (hi / texel).ceil().as_i64vec2() + I64Vec2::ONE,
    }
}

/// Appends to `out` the parts of the window `new` that the window `old` (of the same level and
/// texel grid) did not cover: at most two rectangles (a column strip and a row strip; up to
/// four when `new` is larger), empty ones left out. A move of a whole window or more exposes
/// all of `new`.
pub fn exposed_strips(old: &GridRect, new: &GridRect, out: &mut Vec<GridRect>) {
    let overlap = old.intersect(new);
    if overlap.area() == 0 {
        out.push(*new);
        return;
    }
    // NOTE: the columns of `new` outside the overlap, full height; then the rows outside it
    // within the overlap's columns.
    for (x0, x1) in [(new.min.x, overlap.min.x), (overlap.max.x, new.max.x)] {
        if x1 > x0 {
            out.push(GridRect {
                min: I64Vec2::new(x0, new.min.y),
                max: I64Vec2::new(x1, new.max.y),
            });
        }
    }
    for (y0, y1) in [(new.min.y, overlap.min.y), (overlap.max.y, new.max.y)] {
        if y1 > y0 {
            out.push(GridRect {
                min: I64Vec2::new(overlap.min.x, y0),
                max: I64Vec2::new(overlap.max.x, y1),
            });
        }
    }
}

/// The clipmap as a [`CascadeSet`] the renderer draws and samples as it does cascades: one
/// entry per level (its window's matrix, light-frame box, texel size and depth range, the PCSS
/// factors of a sun of `angular_diameter`), marked [`CascadeSet::clipmap`] so receivers pick a
/// level by their light-frame position. Shadows end at the last level's corners (`end`, a
/// view depth no receiver inside it exceeds).
pub fn clipmap_cascades(set: &ClipmapSet, angular_diameter: f32) -> CascadeSet {
    let mut out = CascadeSet {
        count: set.count,
        light_rotation: set.light_rotation,
        clipmap: true,
        scrolls: true,
        ..CascadeSet::default()
    };
    let last = set.active().last().copied().unwrap_or_default();
    // NOTE: a receiver in the last window is at most half its diagonal from the camera.
    let end = last.extent * std::f32::consts::FRAC_1_SQRT_2 + 2.0 * last.texel;
    for (cascade, level) in out.cascades.iter_mut().zip(set.active()) {
        let extent = f64::from(level.extent);
        let pcss = pcss_params_f64(angular_diameter, extent, extent, f64::from(level.depth));
        let (lo, hi) = (level.min(), level.max());
        *cascade = Cascade {
            clip_from_world: level.clip_from_world,
            near: 0.0,
            far: end,
            light_min: Vec3::new(f32_down(f64::from(lo.x)), f32_down(f64::from(lo.y)), level.z_min),
            light_max: Vec3::new(
                f32_up(f64::from(hi.x)),
                f32_up(f64::from(hi.y)),
                level.z_min + level.depth,
            ),
            texel_world_size: level.texel,
            depth_range: level.depth,
            light_size_uv: pcss.light_size_uv,
            pcss_scale: pcss.pcss_scale,
            uv_scale_y: pcss.uv_scale_y,
            receiver_start: 0.0,
            hold_grid: Vec3::ZERO,
            grid: TexelGrid {
                first_texel: level.first_texel,
                texel: Vec2::splat(level.texel),
            },
        };
    }
    out.splits = [end; MAX_CASCADES + 1];
    out.splits[0] = 0.0;
    out.end = end;
    out
}

/// Light-frame world position of grid texel corner `texel` at `z` (for tests and tools).
pub fn grid_point(set: &ClipmapSet, level: &ClipmapLevel, texel: I64Vec2, z: f32) -> Vec3 {
    let xy = texel.as_dvec2() * f64::from(level.texel);
    set.light_rotation.transpose() * DVec3::new(xy.x, xy.y, f64::from(z)).as_vec3()
}

/// The parts of `rect` (texels of a window `side` texels wide, rows from its top) in a layer
/// that wraps with the window's first texel at layer texel `origin`: for each part, the
/// viewport origin that draws the window there (`origin` less a side where the part wraps
/// round) and the part's texels in the layer. At most four parts; together they cover the
/// layer texels of `rect` once.
pub fn wrapped_parts(rect: TexelRect, origin: [u32; 2], side: u32) -> impl Iterator<Item = ([i64; 2], TexelRect)> {
    let n = i64::from(side);
    let [ox, oy] = origin.map(|o| i64::from(o) % n.max(1));
    (0..4).filter_map(move |q| {
        let (vx, vy) = (ox - (q & 1) * n, oy - (q >> 1) * n);
        let cut = |a: u32, b: u32, v: i64| {
            let (lo, hi) = ((i64::from(a) + v).max(0), (i64::from(b) + v).min(n));
            (lo < hi).then_some((lo as u32, hi as u32))
        };
        let (x0, x1) = cut(rect.x0, rect.x1, vx)?;
        let (y0, y1) = cut(rect.y0, rect.y1, vy)?;
        Some(([vx, vy], TexelRect { x0, y0, x1, y1 }))
    })
}

#[cfg(test)]
#[path = "clipmap_tests.rs"]
mod tests;
