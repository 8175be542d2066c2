//! What a paged sun's pages must be drawn again for, found on the CPU each frame by
//! comparing the frame with the last: every page when the light turned, a level's depth
//! range or texel, the depth bias or clamping, or the moments' parameters changed (or the
//! casters were rebuilt); otherwise, for each caster that moved,
//! the pages of each level its bounding sphere covered before and covers now. The allocator's
//! invalidation pass ([`PageAllocator::record_invalidation`](crate::render::shadows::page_allocate::PageAllocator::record_invalidation))
//! then marks those of them that are resident for drawing.

use glam::{DVec2, Mat3, Mat4, Vec4};

use crate::math::pages::{PageLayout, PageRect, PagedLevel};
use crate::render::shadows::page_allocate::MAX_INVALIDATIONS;
use crate::render::shadows::sun_moments::CascadeMoments;

/// One caster as the comparison sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackedCaster {
    /// World from local.
    pub world_from_local: Mat4,
    /// World bounding sphere: centre, radius.
    pub sphere: Vec4,
}

/// What a frame's pages were drawn from.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PagedFrame {
    /// The light's frame from world.
    pub light_rotation: Mat3,
    /// Each level's clip space from world and window.
    pub levels: Vec<(Mat4, PagedLevel)>,
    /// The casters, in instance order.
    pub casters: Vec<TrackedCaster>,
    /// How each level's moments are baked (empty while the sun filters no moments).
    pub moments: Vec<CascadeMoments>,
    /// How casters are rasterised: slope-scaled depth bias, its clamp, depth clamping.
    pub raster: (f32, f32, bool),
}

/// The pages to draw again this frame.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Invalidation {
    /// Every page.
    pub all: bool,
    /// Rectangles of grid pages, one level each.
    pub rects: Vec<(u32, PageRect)>,
}

impl Invalidation {
    /// Whether nothing is invalidated.
    pub fn is_empty(&self) -> bool {
        !self.all && self.rects.is_empty()
    }
}

/// The pages of a level (`level`, cut by `layout`) a sphere of world centre `centre` and radius
/// `radius` covers, seen from the light (`light_rotation`).
pub fn sphere_pages(layout: &PageLayout, level: &PagedLevel, light_rotation: Mat3, sphere: Vec4) -> PageRect {
    let light = (light_rotation * sphere.truncate()).as_dvec3();
    let at = DVec2::new(light.x, light.y) / level.texel;
    layout.footprint(at, f64::from(sphere.w) / level.texel + 1.0)
}

/// Whether the level's content changes for every page: its light-frame depth mapping (the
/// clip matrix's depth row) or its texel.
fn same_depth(a: &(Mat4, PagedLevel), b: &(Mat4, PagedLevel)) -> bool {
    a.0.row(2) == b.0.row(2) && a.1.texel == b.1.texel
}

/// What `now` must draw again after `last` (None: nothing was drawn before, so nothing is
/// resident to invalidate).
pub fn invalidation(layout: &PageLayout, last: Option<&PagedFrame>, now: &PagedFrame) -> Invalidation {
    let Some(last) = last else {
        return Invalidation::default();
    };
    let levels_kept =
        last.levels.len() == now.levels.len() && last.levels.iter().zip(&now.levels).all(|(a, b)| same_depth(a, b));
    let everything = Invalidation {
        all: true,
        rects: Vec::new(),
    };
    let moments_kept = last.moments == now.moments && last.raster == now.raster;
    if last.light_rotation != now.light_rotation
        || !levels_kept
        || !moments_kept
        || last.casters.len() != now.casters.len()
    {
        return everything;
    }
    let mut out = Invalidation::default();
    for (old, new) in last.casters.iter().zip(&now.casters) {
        if old == new {
            continue;
        }
        for (l, (_, level)) in now.levels.iter().enumerate() {
            for sphere in [old.sphere, new.sphere] {
                let rect = sphere_pages(layout, level, now.light_rotation, sphere);
                if let Some(rect) = rect.intersect(&layout.window(level.first_texel)) {
                    out.rects.push((l as u32, rect));
                }
            }
        }
        if out.rects.len() > MAX_INVALIDATIONS {
            return everything;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use glam::{I64Vec2, Vec3};

    use super::*;

    fn frame(casters: &[Vec3]) -> PagedFrame {
        PagedFrame {
            light_rotation: Mat3::IDENTITY,
            levels: vec![(
                Mat4::IDENTITY,
                PagedLevel {
                    first_texel: I64Vec2::splat(-2048),
                    texel: 0.01,
                },
            )],
            casters: casters
                .iter()
                .map(|&c| TrackedCaster {
                    world_from_local: Mat4::from_translation(c),
                    sphere: c.extend(0.5),
                })
                .collect(),
            moments: Vec::new(),
            raster: (1.0, 0.0, true),
        }
    }

    #[test]
    fn a_still_frame_invalidates_nothing_and_a_first_frame_nothing_either() {
        let layout = PageLayout::new(4096, 128).unwrap();
        let a = frame(&[Vec3::ZERO, Vec3::X]);
        assert!(invalidation(&layout, Some(&a), &a).is_empty());
        assert!(invalidation(&layout, None, &a).is_empty());
    }

    #[test]
    fn a_moving_caster_invalidates_the_pages_of_its_old_and_new_spheres_only() {
        let layout = PageLayout::new(4096, 128).unwrap();
        let a = frame(&[Vec3::ZERO, Vec3::new(10.0, 0.0, 0.0)]);
        let b = frame(&[Vec3::ZERO, Vec3::new(11.0, 0.0, 0.0)]);
        let got = invalidation(&layout, Some(&a), &b);
        assert!(!got.all);
        // 0.5 m spheres of 1 cm texels, 1.28 m pages: x 9.5–10.5 m is pages 7–8, 10.5–11.5 m
        // pages 8–8; y −0.5–0.5 m pages −1–0.
        let rects: Vec<_> = got.rects.iter().map(|(l, r)| (*l, r.min, r.max)).collect();
        assert_eq!(
            rects,
            vec![
                (0, I64Vec2::new(7, -1), I64Vec2::new(8, 0)),
                (0, I64Vec2::new(8, -1), I64Vec2::new(8, 0)),
            ]
        );
    }

    #[test]
    fn a_turned_light_a_new_caster_count_new_moments_or_a_new_bias_invalidate_everything() {
        let layout = PageLayout::new(4096, 128).unwrap();
        let a = frame(&[Vec3::ZERO]);
        let mut turned = a.clone();
        turned.light_rotation = Mat3::from_rotation_x(0.01);
        assert!(invalidation(&layout, Some(&a), &turned).all);
        assert!(invalidation(&layout, Some(&a), &frame(&[Vec3::ZERO, Vec3::X])).all);
        let mut evsm = a.clone();
        evsm.moments.push(CascadeMoments {
            blur_texels: 2.0,
            ..CascadeMoments::default()
        });
        assert!(invalidation(&layout, Some(&a), &evsm).all);
        let mut blurred = evsm.clone();
        blurred.moments[0].blur_texels = 3.0;
        assert!(invalidation(&layout, Some(&evsm), &blurred).all);
        assert!(invalidation(&layout, Some(&evsm), &evsm).is_empty());
        let mut biased = a.clone();
        biased.raster.0 = 2.0;
        assert!(invalidation(&layout, Some(&a), &biased).all);
    }
}
