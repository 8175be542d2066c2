//! Scrolling views (clipmap levels, and cascades that scroll, [`CascadeSet::scrolls`]): what
//! a view's layer must draw this frame when its box moved or casters changed inside it. A
//! view keeps its content version while only its box moves by whole texels of its grid
//! ([`ViewCache`](crate::ecs::view_cache::ViewCache) with `scrolls`), so the renderer keeps
//! the layer: it moves the layer's texels by the box's shift in whole texels and draws only
//! the strips the box newly covers ([`exposed_strips`]) and the regions where casters moved,
//! each with the casters that reach it. The renderer checks that its layer holds this
//! version at last frame's box (`Scroll::from`) and draws the view whole otherwise. A view
//! filtered by depth comparisons wraps instead of moving ([`Scroll::origin`]): its layer
//! keeps every texel where it was drawn, the box's first texel moving round the layer, so a
//! moved box costs only its strips.

use bevy_ecs::entity::Entity;
use bevy_ecs::resource::Resource;
use glam::{I64Vec2, Vec2};

use crate::ecs::assets::MeshHandle;
use crate::ecs::caster_changes::CasterChanges;
use crate::ecs::draw_groups::{DrawGroup, push_instance};
use crate::ecs::instances::RenderInstances;
use crate::ecs::light_views::FrameLights;
use crate::ecs::lod_table::{lod_key, lod_table};
use crate::ecs::shadow_lods::ShadowLods;
use crate::ecs::view_cache::CachedView;
use crate::ecs::view_list::{CullVolume, Scroll, ShadowView};
use crate::math::aabb::Aabb;
use crate::math::cascades::{Cascade, CascadeSet, MAX_SUN_VIEWS};
use crate::math::clipmap::{GridRect, covering_texels, exposed_strips, window};
use crate::math::footprint::TexelRect;

/// Scrolling views a renderer had to draw whole from a draw group of an earlier window
/// ([`Scroll::fresh`] false): the render plugin lists them after a frame, and the next frame
/// culls them again for their window.
#[derive(Resource, Clone, Debug, Default, PartialEq, Eq)]
pub struct ScrollResync {
    /// (light entity, level) of each.
    pub views: Vec<(Entity, u32)>,
}

impl ScrollResync {
    /// Whether the view of `entity`'s level `level` must be culled whole this frame.
    pub fn wants(&self, entity: Entity, level: u32) -> bool {
        self.views.contains(&(entity, level))
    }
}

/// What a level's layer was last asked to hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Held {
    entity: Entity,
    level: u32,
    version: u64,
    window: I64Vec2,
    /// The window the level was last drawn whole for (its first texel at the layer's first),
    /// for a layer that wraps.
    anchor: Option<I64Vec2>,
    /// The grid texels the layer holds as a fresh draw would: those of the view's cull
    /// volume (the whole window unless it is bounded by the receivers).
    valid: GridRect,
}

/// A region one scrolling view draws, and the casters reaching it (its batches index `list`).
#[derive(Debug, Default)]
pub(crate) struct RegionDraw {
    /// The view's index.
    pub(crate) view: usize,
    /// The layer's texels.
    pub(crate) rect: TexelRect,
    /// The casters, as draws over `list`.
    pub(crate) group: DrawGroup,
    /// Instance indices.
    pub(crate) list: Vec<u32>,
}

/// What scroll planning keeps between frames.
#[derive(Debug, Default)]
pub(crate) struct ScrollScratch {
    held: Vec<Held>,
    next: Vec<Held>,
    /// This frame's regions (the first `count` are valid; the rest keep their allocations).
    pub(crate) regions: Vec<RegionDraw>,
    /// Valid regions.
    pub(crate) count: usize,
    rects: Vec<GridRect>,
    /// The mesh each mesh draws in the level being planned (its shadow LOD).
    lods: Vec<[MeshHandle; MAX_SUN_VIEWS]>,
    /// (caster, region bits) of the regions being culled, in draw order.
    hits: Vec<(u32, u8)>,
    /// The renderer keeps layers between frames ([`ShadowCulling::cached`]): a layer that
    /// wraps keeps its origin; otherwise each frame draws it whole at origin `[0, 0]`.
    ///
    /// [`ShadowCulling::cached`]: crate::ecs::receiver_culling::ShadowCulling::cached
    pub(crate) cached: bool,
}

/// Sets the [`Scroll`] of every scrolling view (the windows it moves between) and lists the
/// regions each draws in `scratch.regions[..scratch.count]`; returns that count.
pub(crate) fn plan_scrolls(
    lights: &FrameLights,
    instances: &RenderInstances,
    lods: &ShadowLods,
    changes: &CasterChanges,
    views: &mut [ShadowView],
    entries: &[CachedView],
    scratch: &mut ScrollScratch,
) -> usize {
    scratch.count = 0;
    scratch.next.clear();
    for (v, (view, entry)) in views.iter_mut().zip(entries).enumerate() {
        let cull = view.cull;
        let Some(scroll) = &mut view.scroll else { continue };
        let Some(sun) = lights.sun_at(view.light) else { continue };
        let Some(level) = sun.cascades.active().get(view.kind.index as usize) else {
            continue;
        };
        let to = level.grid.first_texel;
        let here = window(to, view.resolution);
        // NOTE: moments are blurred up to the layer's edges, so a moments sun's layer moves.
        let wraps = !sun.settings.filter.mode.effective(true).is_sun_moments();
        let held = scratch
            .held
            .iter()
            .find(|h| h.entity == view.entity && h.level == view.kind.index)
            .filter(|h| h.version == view.version && h.anchor.is_some() == wraps)
            .copied();
        // NOTE: a renderer that keeps no layer draws every level whole: at origin [0, 0] that
        // is one draw, not one per part.
        let anchor = wraps.then(|| held.filter(|_| scratch.cached).and_then(|h| h.anchor).unwrap_or(to));
        // NOTE: layer columns follow grid x, layer rows run against grid y.
        let origin = anchor.map(|a| {
            let n = i64::from(view.resolution.max(1));
            [(to.x - a.x).rem_euclid(n) as u32, (a.y - to.y).rem_euclid(n) as u32]
        });
        let valid = cull_rect(&cull, level).intersect(&here);
        scratch.next.push(Held {
            entity: view.entity,
            level: view.kind.index,
            version: view.version,
            window: to,
            anchor,
            valid,
        });
        let Some(held) = held else {
            *scroll = Scroll {
                from: to,
                to,
                fresh: entry.cull,
                origin,
                ..Scroll::default()
            };
            continue;
        };
        let from = held.window;
        scratch.rects.clear();
        // NOTE: what the layer still holds of its last volume, in this window; the rest of
        // this volume is drawn (the strips a moved window newly covers, and where a volume
        // bounded by the receivers newly reaches).
        let kept = held.valid.intersect(&here);
        if kept != valid && valid.area() > 0 {
            exposed_strips(&kept, &valid, &mut scratch.rects);
        }
        if entry.touched {
            for changed in &changes.regions {
                let rect = grid_rect(sun.cascades.light_rotation, level, changed).intersect(&here);
                if rect.area() > 0 {
                    scratch.rects.push(rect);
                }
            }
        }
        let first = scratch.count as u32;
        lod_table(lods, instances, sun.cascades.active(), &mut scratch.lods);
        let mut done = 0;
        while done < scratch.rects.len() {
            let batch = (scratch.rects.len() - done).min(MAX_SUN_VIEWS);
            // NOTE: the regions are culled as the boxes of a set of cascades, a chunk of
            // casters at a time, so a strip costs what its casters cost, not its level's.
            let mut set = CascadeSet {
                count: batch,
                light_rotation: sun.cascades.light_rotation,
                clipmap: true,
                scrolls: true,
                ..CascadeSet::default()
            };
            let texel = level.grid.texel;
            for (c, rect) in set.cascades.iter_mut().zip(&scratch.rects[done..done + batch]) {
                let (lo, hi) = (rect.min.as_vec2() * texel, rect.max.as_vec2() * texel);
                c.light_min = lo.extend(level.light_min.z);
                c.light_max = hi.extend(level.light_max.z);
            }
            while scratch.regions.len() < scratch.count + batch {
                scratch.regions.push(RegionDraw::default());
            }
            for (r, rect) in scratch.rects[done..done + batch].iter().enumerate() {
                let region = &mut scratch.regions[scratch.count + r];
                region.view = v;
                region.rect = layer_rect(rect, to, view.resolution);
                region.group.clear();
                region.list.clear();
            }
            let level_index = view.kind.index as usize;
            // NOTE: culled over the casters in space order (a strip's few casters are found
            // without visiting a chunk per mesh), the hits sorted back into draw order.
            scratch.hits.clear();
            instances.caster_space.cull_sorted(&set, &mut scratch.hits);
            let regions = &mut scratch.regions[scratch.count..];
            for &(caster, mask) in &scratch.hits {
                let instance = instances.casters[caster as usize];
                let key = lod_key(&scratch.lods, instances.keys[instance as usize], level_index);
                let mut bits = mask;
                while bits != 0 {
                    let region = &mut regions[bits.trailing_zeros() as usize];
                    push_instance(&mut region.group, &mut region.list, key, instance);
                    bits &= bits - 1;
                }
            }
            scratch.count += batch;
            done += batch;
        }
        *scroll = Scroll {
            from,
            to,
            first_region: first,
            region_count: scratch.count as u32 - first,
            fresh: entry.cull,
            origin,
        };
    }
    std::mem::swap(&mut scratch.held, &mut scratch.next);
    scratch.count
}

/// The grid texels of `level`'s grid that cull volume `cull` covers (rounded out by a
/// texel); none for a volume that is not a light-frame box.
fn cull_rect(cull: &CullVolume, level: &Cascade) -> GridRect {
    let CullVolume::LightBox { min, max, .. } = *cull else {
        return GridRect::default();
    };
    covering_texels(min.truncate(), max.truncate(), level.grid.texel)
}

/// The grid texels of `level`'s grid a world box covers in the light's frame (rounded out).
fn grid_rect(rotation: glam::Mat3, level: &Cascade, world: &Aabb) -> GridRect {
    let (lo, hi) = world.corners().iter().fold((Vec2::MAX, Vec2::MIN), |(lo, hi), &c| {
        let p = (rotation * c).truncate();
        (lo.min(p), hi.max(p))
    });
    covering_texels(lo, hi, level.grid.texel)
}

/// The layer texels of grid rectangle `rect` in the window starting at grid texel `to`
/// (`resolution` texels; layer row 0 is the window's top, grid y grows upwards).
fn layer_rect(rect: &GridRect, to: I64Vec2, resolution: u32) -> TexelRect {
    let n = i64::from(resolution);
    let (min, max) = (rect.min - to, rect.max - to);
    let clamp = |v: i64| v.clamp(0, n) as u32;
    TexelRect {
        x0: clamp(min.x),
        y0: clamp(n - max.y),
        x1: clamp(max.x),
        y1: clamp(n - min.y),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grid_rect_lands_in_the_layer_rows_counted_from_the_window_top() {
        let to = I64Vec2::new(100, 200);
        let rect = GridRect {
            min: I64Vec2::new(100, 200),
            max: I64Vec2::new(104, 202),
        };
        // The window's bottom-left grid texels are the layer's last rows, first columns.
        let r = layer_rect(&rect, to, 16);
        assert_eq!((r.x0, r.x1, r.y0, r.y1), (0, 4, 14, 16));
        // Outside the window: empty after clamping.
        let outside = GridRect {
            min: I64Vec2::new(0, 0),
            max: I64Vec2::new(10, 10),
        };
        assert_eq!(layer_rect(&outside, to, 16).area(), 0);
    }
}
