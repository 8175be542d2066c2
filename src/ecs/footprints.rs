//! The footprint of a shadow view's casters ([`ShadowView::footprint`](crate::ecs::ShadowView::footprint)):
//! the tiles of its map they can write, taken culling chunk by culling chunk. A chunk counts
//! by its bounds while they cover a small part of the map (a large scene's compact chunks); a
//! chunk whose bounds cover much of it (a small scene whose few casters share one chunk spread
//! over the whole scene) counts by the bounds of each member in the view.

use crate::ecs::instances::RenderInstances;
use crate::math::aabb::Aabb;
use crate::math::footprint::{ClipProjector, TILES, TileMask};

/// Clip area (of 4) above which a chunk is taken member by member.
const REFINE_AREA: f32 = 0.25;

/// Adds to `tiles` those the casters `members` (indices into the caster arrays, all in
/// culling chunk `chunk`) can write under `projector`; a chunk taken member by member is
/// taken `step` consecutive members at a time (the union of their bounds). Every tile for a
/// chunk whose bounds are unknown (one with a member that is not finite).
pub fn add_chunk_footprint(
    tiles: &mut TileMask,
    projector: &ClipProjector,
    instances: &RenderInstances,
    chunk: usize,
    (members, step): (impl Iterator<Item = usize>, usize),
) {
    // NOTE: a layer written over half its tiles is cleared whole anyway, so past that point
    // the footprint is the whole map and the remaining chunks cost nothing.
    if *tiles == TileMask::FULL {
        return;
    }
    let bounds = instances.caster_chunks.boxes.get(chunk).copied().unwrap_or(Aabb::EMPTY);
    if bounds.is_empty() {
        *tiles = TileMask::FULL;
        return;
    }
    let rect = projector.rect(&bounds);
    if rect.area() > REFINE_AREA {
        let (mut part, mut taken) = (Aabb::EMPTY, 0);
        for k in members {
            part = part.union(instances.caster_boxes.get(k).copied().unwrap_or(bounds));
            taken += 1;
            if taken == step.max(1) {
                tiles.add_rect(&projector.rect(&part));
                (part, taken) = (Aabb::EMPTY, 0);
            }
        }
        tiles.add_rect(&projector.rect(&part));
    } else {
        tiles.add_rect(&rect);
    }
    if tiles.count() * 2 >= TILES * TILES {
        *tiles = TileMask::FULL;
    }
}
