//! Footprints: the part of a shadow map its casters can write, so a redraw clears only what
//! the last draw wrote instead of the whole layer (on GPUs with few raster units a 2048²
//! depth clear costs more than drawing a scene's casters). A caster's bounds give a clip-space
//! rectangle ([`clip_footprint`]); a view's footprint is the set of tiles of a
//! [`TILES`]² grid over the map those rectangles touch ([`TileMask`]), independent of the
//! map's resolution, and turned into texel rectangles of a map of a given size to clear.

use glam::{Mat4, Vec2, Vec3, Vec4};

use crate::math::aabb::Aabb;

/// An axis-aligned rectangle in clip-space `x`, `y`, clamped to `[-1, 1]`; empty when
/// `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipRect {
    /// Smallest corner.
    pub min: Vec2,
    /// Largest corner.
    pub max: Vec2,
}

/// A rectangle of texels: columns `x0..x1`, rows `y0..y1` (row 0 at clip `y = 1`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TexelRect {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl TexelRect {
    /// Texels inside (0 when empty).
    pub fn area(&self) -> u64 {
        u64::from(self.x1.saturating_sub(self.x0)) * u64::from(self.y1.saturating_sub(self.y0))
    }
}

impl ClipRect {
    /// Nothing.
    pub const EMPTY: Self = Self {
        min: Vec2::splat(f32::INFINITY),
        max: Vec2::splat(f32::NEG_INFINITY),
    };

    /// The whole clip square.
    pub const FULL: Self = Self {
        min: Vec2::splat(-1.0),
        max: Vec2::splat(1.0),
    };

    /// True when it covers nothing.
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y)
    }

    /// Its area in clip units (the whole square is 4; 0 when empty).
    pub fn area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let size = self.max - self.min;
        size.x * size.y
    }

    /// The smallest rectangle holding both.
    pub fn union(self, other: Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Clamped to the clip square (empty when outside it).
    fn clamped(self) -> Self {
        if self.is_empty() {
            return Self::EMPTY;
        }
        let min = self.min.max(Vec2::splat(-1.0));
        let max = self.max.min(Vec2::splat(1.0));
        let r = Self { min, max };
        if r.is_empty() { Self::EMPTY } else { r }
    }
}

/// Tiles per side of a [`TileMask`].
pub const TILES: u32 = 32;

/// A set of tiles of a [`TILES`]² grid over a map: bit `x` of row `y` is the tile of columns
/// `x·side/TILES..` and rows `y·side/TILES..` (row 0 at clip `y = 1`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TileMask {
    rows: [u32; TILES as usize],
}

impl TileMask {
    /// No tile.
    pub const EMPTY: Self = Self {
        rows: [0; TILES as usize],
    };

    /// Every tile.
    pub const FULL: Self = Self {
        rows: [u32::MAX; TILES as usize],
    };

    /// The tiles holding a texel centre inside `rect` (conservatively: a hair more).
    pub fn from_rect(rect: &ClipRect) -> Self {
        let mut mask = Self::EMPTY;
        mask.add_rect(rect);
        mask
    }

    /// Adds the tiles of [`from_rect`](Self::from_rect).
    pub fn add_rect(&mut self, rect: &ClipRect) {
        if rect.is_empty() {
            return;
        }
        // NOTE: a texel centre at u lies in tile floor(u·TILES) for any map size (see
        // `texel_runs`); the margin absorbs rounding. The value is clamped to be
        // non-negative first, so the cast's truncation is the floor.
        let tile = |u: f32| ((u * TILES as f32).clamp(0.0, (TILES - 1) as f32)) as u32;
        const MARGIN: f32 = 1e-4;
        let (x0, x1) = (
            tile(rect.min.x * 0.5 + 0.5 - MARGIN),
            tile(rect.max.x * 0.5 + 0.5 + MARGIN),
        );
        let (y0, y1) = (
            tile(0.5 - rect.max.y * 0.5 - MARGIN),
            tile(0.5 - rect.min.y * 0.5 + MARGIN),
        );
        let bits = (u32::MAX >> (TILES - 1 - (x1 - x0))) << x0;
        for row in &mut self.rows[y0 as usize..=y1 as usize] {
            *row |= bits;
        }
    }

    /// Tiles in either.
    pub fn union(self, other: Self) -> Self {
        let mut rows = self.rows;
        for (a, b) in rows.iter_mut().zip(other.rows) {
            *a |= b;
        }
        Self { rows }
    }

    /// Number of tiles.
    pub fn count(&self) -> u32 {
        self.rows.iter().map(|r| r.count_ones()).sum()
    }

    /// True when it holds no tile.
    pub fn is_empty(&self) -> bool {
        self.rows.iter().all(|&r| r == 0)
    }

    /// The tiles as texel rectangles of a `side`² map (runs of tiles in a row, joined with
    /// the same run of the rows below), into `out` (cleared first). Tile `t` spans texels
    /// `floor(t·side/TILES)..ceil((t + 1)·side/TILES)`, so it holds every texel whose centre
    /// lies in it.
    pub fn texel_runs(&self, side: u32, out: &mut Vec<TexelRect>) {
        out.clear();
        let edge = |t: u32, up: bool| {
            let v = u64::from(t) * u64::from(side);
            let t = u64::from(TILES);
            (if up { v.div_ceil(t) } else { v / t }) as u32
        };
        // Open rectangles reach the previous row: (first tile, end tile, first row). A row
        // of 32 tiles holds at most 16 runs, so fixed arrays do (no allocation per call).
        const MAX_RUNS: usize = TILES as usize / 2;
        let mut open = [(0u32, 0u32, 0u32); MAX_RUNS];
        let mut next = open;
        let mut open_count = 0;
        for y in 0..=TILES {
            let mut bits = if y < TILES { self.rows[y as usize] } else { 0 };
            let mut next_count = 0;
            while bits != 0 {
                let x0 = bits.trailing_zeros();
                let x1 = x0 + (bits >> x0).trailing_ones();
                bits &= !(((1u64 << x1) - 1) as u32);
                let y0 = open[..open_count]
                    .iter()
                    .find(|o| (o.0, o.1) == (x0, x1))
                    .map_or(y, |o| o.2);
                next[next_count] = (x0, x1, y0);
                next_count += 1;
            }
            for &(x0, x1, y0) in &open[..open_count] {
                if !next[..next_count].contains(&(x0, x1, y0)) {
                    out.push(TexelRect {
                        x0: edge(x0, false),
                        y0: edge(y0, false),
                        x1: edge(x1, true),
                        y1: edge(y, true),
                    });
                }
            }
            open = next;
            open_count = next_count;
        }
    }
}

/// The clip-space rectangle `b` covers under `clip_from_world`, clamped to the clip square:
/// everything a caster inside `b` can write. The whole square when a corner is not in front
/// of the projection (`w ≤ 0`) or not finite; empty for an empty box.
pub fn clip_footprint(clip_from_world: &Mat4, b: &Aabb) -> ClipRect {
    ClipProjector::new(clip_from_world).rect(b)
}

/// [`clip_footprint`] for many boxes under one matrix: what depends only on the matrix is
/// taken apart once.
#[derive(Clone, Copy, Debug)]
pub struct ClipProjector {
    matrix: Mat4,
    /// The bottom row is `0 0 0 1` (an orthographic cascade).
    affine: bool,
    /// Rows x and y: linear parts, their absolute values, and the constants.
    rows: [Vec3; 2],
    abs_rows: [Vec3; 2],
    offsets: Vec2,
}

impl ClipProjector {
    /// Takes `clip_from_world` apart.
    pub fn new(clip_from_world: &Mat4) -> Self {
        let (rx, ry) = (clip_from_world.row(0), clip_from_world.row(1));
        Self {
            matrix: *clip_from_world,
            affine: clip_from_world.row(3) == Vec4::W,
            rows: [rx.truncate(), ry.truncate()],
            abs_rows: [rx.truncate().abs(), ry.truncate().abs()],
            offsets: Vec2::new(rx.w, ry.w),
        }
    }

    /// The clip-space rectangle `b` covers (see [`clip_footprint`]).
    pub fn rect(&self, b: &Aabb) -> ClipRect {
        if b.is_empty() {
            return ClipRect::EMPTY;
        }
        if !b.is_finite() {
            return ClipRect::FULL;
        }
        if self.affine {
            // Centre and extent, two rows only.
            let (c, e) = (b.center(), b.half_extents());
            let center = Vec2::new(self.rows[0].dot(c), self.rows[1].dot(c)) + self.offsets;
            let extent = Vec2::new(self.abs_rows[0].dot(e), self.abs_rows[1].dot(e));
            return ClipRect {
                min: center - extent,
                max: center + extent,
            }
            .clamped();
        }
        let mut rect = ClipRect::EMPTY;
        for corner in b.corners() {
            let p = self.matrix * corner.extend(1.0);
            if !p.is_finite() || p.w <= 1e-6 {
                return ClipRect::FULL;
            }
            let xy = p.truncate().truncate() / p.w;
            rect = rect.union(ClipRect { min: xy, max: xy });
        }
        rect.clamped()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::projection::{ortho_reverse_z, perspective_reverse_z};
    use glam::Vec3;

    fn ortho() -> Mat4 {
        // Light looking down -Z from above; a 20 m square.
        ortho_reverse_z(-10.0, 10.0, -10.0, 10.0, 0.1, 100.0)
    }

    #[test]
    fn a_box_maps_to_its_clip_rectangle_and_texels() {
        let b = Aabb::new(Vec3::new(0.0, 0.0, -5.0), Vec3::new(5.0, 5.0, -4.0));
        let r = clip_footprint(&ortho(), &b);
        assert!((r.min - Vec2::new(0.0, 0.0)).abs().max_element() < 1e-6, "{r:?}");
        assert!((r.max - Vec2::new(0.5, 0.5)).abs().max_element() < 1e-6, "{r:?}");
        // x 0..0.5 → tiles 16..=23, one more on each side by the margin's hair past the
        // boundaries: 15..=24, texels 480..800 of 1024; y 0..0.5 → tile rows 7..=16.
        let mut runs = Vec::new();
        TileMask::from_rect(&r).texel_runs(1024, &mut runs);
        assert_eq!(
            runs,
            [TexelRect {
                x0: 480,
                y0: 224,
                x1: 800,
                y1: 544
            }]
        );
    }

    #[test]
    fn perspective_corners_behind_the_eye_give_the_whole_square() {
        let persp = perspective_reverse_z(1.0, 1.0, 0.05, 100.0);
        let in_front = Aabb::new(Vec3::new(-0.1, -0.1, -3.0), Vec3::new(0.1, 0.1, -2.0));
        let r = clip_footprint(&persp, &in_front);
        assert!(!r.is_empty() && r.max.x < 0.2 && r.min.x > -0.2, "{r:?}");
        let straddling = Aabb::new(Vec3::new(-0.1, -0.1, -3.0), Vec3::new(0.1, 0.1, 1.0));
        assert_eq!(clip_footprint(&persp, &straddling), ClipRect::FULL);
    }

    #[test]
    fn outside_empty_and_non_finite_boxes() {
        let far = Aabb::new(Vec3::new(50.0, 0.0, -5.0), Vec3::new(60.0, 1.0, -4.0));
        assert!(clip_footprint(&ortho(), &far).is_empty());
        assert!(TileMask::from_rect(&clip_footprint(&ortho(), &far)).is_empty());
        assert!(clip_footprint(&ortho(), &Aabb::EMPTY).is_empty());
        let inf = Aabb::new(Vec3::splat(f32::NEG_INFINITY), Vec3::ZERO);
        assert_eq!(clip_footprint(&ortho(), &inf), ClipRect::FULL);
        let mut runs = Vec::new();
        TileMask::from_rect(&ClipRect::FULL).texel_runs(512, &mut runs);
        assert_eq!(
            runs,
            [TexelRect {
                x0: 0,
                y0: 0,
                x1: 512,
                y1: 512
            }]
        );
        assert_eq!(TileMask::from_rect(&ClipRect::FULL), TileMask::FULL);
    }

    #[test]
    fn every_projected_point_of_a_box_lies_in_its_footprint() {
        // Deterministic sweep over boxes and both projections.
        // Looking down from 10 m above the origin.
        let view = Mat4::from_rotation_translation(
            glam::Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            Vec3::new(0.0, 10.0, 0.0),
        )
        .inverse();
        let persp = perspective_reverse_z(1.2, 1.0, 0.05, 100.0) * view;
        let mut s = 1u32;
        let mut next = || {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (s >> 8) as f32 / (1 << 24) as f32
        };
        for m in [ortho(), persp] {
            for _ in 0..200 {
                let c = Vec3::new(next() * 16.0 - 8.0, next() * 4.0 - 6.0, next() * 16.0 - 8.0);
                let h = Vec3::new(next(), next(), next()) * 2.0;
                let b = Aabb::new(c - h, c + h);
                let r = clip_footprint(&m, &b);
                // 250: a size that is not a multiple of the tile grid.
                let side = 250;
                let mut runs = Vec::new();
                TileMask::from_rect(&r).texel_runs(side, &mut runs);
                for k in 0..27 {
                    let t = Vec3::new((k % 3) as f32, (k / 3 % 3) as f32, (k / 9) as f32) * 0.5;
                    let p = m * (b.min + (b.max - b.min) * t).extend(1.0);
                    if p.w <= 0.0 {
                        continue;
                    }
                    let (x, y) = (p.x / p.w, p.y / p.w);
                    if x.abs() > 1.0 || y.abs() > 1.0 {
                        continue;
                    }
                    // The texel whose centre is nearest the point.
                    let col = (((x * 0.5 + 0.5) * side as f32 - 0.5).round() as u32).min(side - 1);
                    let row = (((0.5 - y * 0.5) * side as f32 - 0.5).round() as u32).min(side - 1);
                    let centre = |c: u32| (c as f32 + 0.5) / side as f32;
                    // Only texels whose centre is inside the rectangle are written.
                    let (u, v) = (centre(col) * 2.0 - 1.0, 1.0 - centre(row) * 2.0);
                    if u < r.min.x || u > r.max.x || v < r.min.y || v > r.max.y {
                        continue;
                    }
                    assert!(
                        runs.iter()
                            .any(|t| (t.x0..t.x1).contains(&col) && (t.y0..t.y1).contains(&row)),
                        "{b:?}: texel ({col}, {row}) outside {runs:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn tile_runs_join_rows_and_cover_exactly_the_tiles() {
        // Two rectangles: tiles x 0..2 rows 0..2, and x 4..8 rows 1..3.
        let t = |x0: f32, x1: f32, y0: f32, y1: f32| {
            let clip = |u: f32| u / TILES as f32 * 2.0 - 1.0;
            // Tile rows count down from clip y = 1.
            TileMask::from_rect(&ClipRect {
                min: Vec2::new(clip(x0 + 0.1), -clip(y1 - 0.1)),
                max: Vec2::new(clip(x1 - 0.1), -clip(y0 + 0.1)),
            })
        };
        let mask = t(0.0, 2.0, 0.0, 2.0).union(t(4.0, 8.0, 1.0, 3.0));
        assert_eq!(mask.count(), 4 + 8);
        let mut runs = Vec::new();
        mask.texel_runs(64, &mut runs);
        runs.sort_by_key(|r| (r.y0, r.x0));
        let area: u64 = runs.iter().map(|r| r.area()).sum();
        assert_eq!(area, 12 * 4, "{runs:?}");
        assert_eq!(runs.len(), 2, "{runs:?}");
        assert!(TileMask::EMPTY.is_empty() && TileMask::FULL.count() == TILES * TILES);
    }

    #[test]
    fn texel_rect_areas() {
        let r = TexelRect {
            x0: 2,
            y0: 1,
            x1: 8,
            y1: 3,
        };
        assert_eq!(r.area(), 12);
        assert_eq!(
            TexelRect { x1: 1, ..r }.area(),
            0,
            "an inverted rectangle holds nothing"
        );
    }
}
