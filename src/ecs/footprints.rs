//! The footprint of a shadow view's casters ([`ShadowView::footprint`](crate::ecs::ShadowView::footprint)):
//! the tiles of its map they can write, taken culling chunk by culling chunk. A chunk counts
//! by its bounds while they cover a small part of the map (a large scene's compact chunks); a
//! chunk whose bounds cover much of it (a small scene whose few casters share one chunk spread
//! over the whole scene) counts by the bounds of each member in the view.

use glam::Mat4;

use crate::ecs::instances::RenderInstances;
use crate::math::aabb::Aabb;
use crate::math::footprint::{TileMask, clip_footprint};

/// Clip area (of 4) above which a chunk is taken member by member.
const REFINE_AREA: f32 = 0.25;

/// The tiles the casters `members` (indices into the caster arrays, all in culling chunk
/// `chunk`) can write under `clip_from_world`. Every tile for a chunk whose bounds are
/// unknown (one with a member that is not finite).
pub fn chunk_footprint(
    clip_from_world: &Mat4,
    instances: &RenderInstances,
    chunk: usize,
    members: impl Iterator<Item = usize>,
) -> TileMask {
    let bounds = instances.caster_chunks.boxes.get(chunk).copied().unwrap_or(Aabb::EMPTY);
    if bounds.is_empty() {
        return TileMask::FULL;
    }
    let rect = clip_footprint(clip_from_world, &bounds);
    if rect.area() <= REFINE_AREA {
        return TileMask::from_rect(&rect);
    }
    members.fold(TileMask::EMPTY, |tiles, k| {
        let member = instances.caster_boxes.get(k).copied().unwrap_or(bounds);
        tiles.union(TileMask::from_rect(&clip_footprint(clip_from_world, &member)))
    })
}
