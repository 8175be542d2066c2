//! Occlusion culling's math, the CPU mirror of `shaders/occlusion_cull.wgsl` and
//! `occlusion_pyramid.wgsl`: a depth pyramid whose every texel holds the farthest depth
//! (reverse-Z: the smallest value) of the pixels under it, and the test that finds a bounding
//! sphere behind every depth under its screen rectangle, read where that rectangle spans at
//! most 2 × 2 texels.

use glam::{Mat4, Vec2, Vec3, Vec4};

use crate::math::frustum::Frustum;

/// The levels of a pyramid over a `width` × `height` depth buffer: down to one texel.
pub fn level_count(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

/// A depth pyramid: level 0 is the depth buffer; level `k + 1` is half of level `k` (rounded
/// down), each texel the farthest of the 2 × 2 above it and, at an odd level's last row or
/// column, of the texels left over.
#[derive(Clone, Debug, PartialEq)]
pub struct Pyramid {
    /// Each level's width, height and depths (rows top to bottom).
    pub levels: Vec<(u32, u32, Vec<f32>)>,
}

impl Pyramid {
    /// The pyramid of `depth`, `width` × `height` pixels, rows top to bottom.
    pub fn build(depth: &[f32], width: u32, height: u32) -> Pyramid {
        let mut levels = vec![(width, height, depth.to_vec())];
        for _ in 1..level_count(width, height) {
            let (w, h, above) = levels.last().expect("level 0");
            let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
            let mut level = Vec::with_capacity((nw * nh) as usize);
            for y in 0..nh {
                for x in 0..nw {
                    let ys = 2 * y..=if y == nh - 1 { h - 1 } else { (2 * y + 1).min(h - 1) };
                    let xs = 2 * x..=if x == nw - 1 { w - 1 } else { (2 * x + 1).min(w - 1) };
                    let farthest = ys
                        .flat_map(|yy| xs.clone().map(move |xx| (xx, yy)))
                        .map(|(xx, yy)| above[(yy * w + xx) as usize])
                        .fold(1.0f32, f32::min);
                    level.push(farthest);
                }
            }
            levels.push((nw, nh, level));
        }
        Pyramid { levels }
    }

    /// The depth of texel (`x`, `y`) of `level`.
    pub fn texel(&self, level: usize, x: u32, y: u32) -> f32 {
        let (w, _, d) = &self.levels[level];
        d[(y * w + x) as usize]
    }
}

/// The camera a test projects with: its clip space from view space (reverse-Z), view space
/// from world space, and near plane.
#[derive(Clone, Copy, Debug)]
pub struct CullCamera {
    /// Clip space from view space (reverse-Z perspective).
    pub clip_from_view: Mat4,
    /// View space from world space.
    pub view_from_world: Mat4,
    /// Near plane distance.
    pub near: f32,
}

/// The screen rectangle (pixels of a `size` screen, y down, clamped to it) of the view-space
/// box around a sphere of view-space centre `centre` and radius `r`, and the sphere's
/// nearest depth (reverse-Z NDC); None when the box reaches the near plane.
pub fn sphere_rect(camera: &CullCamera, centre: Vec3, r: f32, size: Vec2) -> Option<(Vec2, Vec2, f32)> {
    if -centre.z - r <= camera.near {
        return None;
    }
    let (mut lo, mut hi) = (Vec2::splat(1e30), Vec2::splat(-1e30));
    for i in 0..8u32 {
        let sign = |bit: u32| if i & bit != 0 { 1.0 } else { -1.0 };
        let corner = centre + r * Vec3::new(sign(1), sign(2), sign(4));
        let clip = camera.clip_from_view * corner.extend(1.0);
        let ndc = Vec2::new(clip.x, clip.y) / clip.w;
        lo = lo.min(ndc);
        hi = hi.max(ndc);
    }
    let nearest = camera.clip_from_view * Vec4::new(centre.x, centre.y, centre.z + r, 1.0);
    let to_pixels = |x: f32, y: f32| (Vec2::new(x * 0.5 + 0.5, 0.5 - y * 0.5) * size).clamp(Vec2::ZERO, size);
    Some((to_pixels(lo.x, hi.y), to_pixels(hi.x, lo.y), nearest.z / nearest.w))
}

/// True when the sphere (`centre`, `radius`, world space) is finite and meets every plane
/// of `frustum`, its radius padded by a relative 1e-5 (as the shader's `in_frustum`).
pub fn in_frustum(frustum: &Frustum, centre: Vec3, radius: f32) -> bool {
    let r = radius.max(0.0);
    let pad = r + 1e-5 * (centre.x.abs() + centre.y.abs() + centre.z.abs() + r);
    centre.is_finite() && radius.is_finite() && frustum.planes.iter().all(|p| p.normal.dot(centre) + p.d >= -pad)
}

/// The mesh level the GPU draws a sphere (`centre`, `radius`) with: the coarsest of the
/// levels of relative `errors` (finest first; level `l` has error `errors[l - 1]`, level 0 is
/// the whole mesh) whose error stays within `error_per_depth` times the sphere's nearest view
/// depth from `eye` along `forward`; 0 for a sphere reaching the camera's plane (as the
/// shader's `level_batch`).
pub fn level_for(
    errors: &[f32],
    (eye, forward): (Vec3, Vec3),
    error_per_depth: f32,
    centre: Vec3,
    radius: f32,
) -> usize {
    let depth = (centre - eye).dot(forward) - radius;
    if depth.is_nan() || depth <= 0.0 {
        return 0;
    }
    let budget = depth * error_per_depth;
    (1..=errors.len())
        .filter(|&l| errors[l - 1] * radius <= budget)
        .max()
        .unwrap_or(0)
}

/// True when the sphere (`centre`, `radius`, world space) lies behind the pyramid's depths
/// everywhere under its screen rectangle.
pub fn hidden(pyramid: &Pyramid, camera: &CullCamera, centre: Vec3, radius: f32) -> bool {
    let (w, h, _) = pyramid.levels[0];
    let view = camera.view_from_world.transform_point3(centre);
    let Some((p0, p1, nearest)) = sphere_rect(camera, view, radius, Vec2::new(w as f32, h as f32)) else {
        return false;
    };
    let extent = (p1.x - p0.x).max(p1.y - p0.y);
    let level = extent.max(1.0).log2().ceil() as usize;
    if level >= pyramid.levels.len() {
        return false;
    }
    let (lw, lh, _) = pyramid.levels[level];
    let scale = 1.0 / (1u32 << level) as f32;
    let texel = |p: Vec2| (((p.x * scale) as u32).min(lw - 1), ((p.y * scale) as u32).min(lh - 1));
    let ((x0, y0), (x1, y1)) = (texel(p0), texel(p1));
    let mut farthest = 1.0f32;
    for y in y0..=y1 {
        for x in x0..=x1 {
            farthest = farthest.min(pyramid.texel(level, x, y));
        }
    }
    nearest < farthest
}

#[cfg(test)]
#[path = "occlusion_tests.rs"]
mod tests;
