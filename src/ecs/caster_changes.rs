//! Which parts of the world changed for shadow casters this frame: when the instance list is
//! rebuilt, the bounds of every caster that appeared, disappeared, moved, or changed mesh or
//! material (old and new bounds both), or "everything" when a mesh or material asset, the
//! render origin or the whole list changed. A shadow view none of whose regions touch its
//! cull volume holds the same shadow map as before and is not rendered again.

use bevy_ecs::entity::{Entity, EntityHashMap};
use bevy_ecs::resource::Resource;

use crate::ecs::draw_groups::DrawKey;
use crate::math::aabb::Aabb;

/// The caster changes of the latest rebuild of [`RenderInstances`](crate::ecs::instances::RenderInstances).
#[derive(Resource, Debug, Default)]
pub struct CasterChanges {
    /// The instance generation these changes led to.
    pub generation: u64,
    /// Every shadow map may have changed (assets, origin, first build).
    pub everything: bool,
    /// World bounds (relative to the render origin) where a caster was or now is.
    pub regions: Vec<Aabb>,
}

/// What a caster was drawn as at the last rebuild.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CasterState {
    /// World bounds, relative to the render origin.
    pub bounds: Aabb,
    /// Mesh and material.
    pub key: DrawKey,
    /// The skinned pose it was drawn in (0 for a mesh without a skin): a new pose redraws
    /// the views its bounds touch even where the bounds stayed the same.
    pub pose: u64,
}

impl CasterChanges {
    /// Records a rebuild to `generation`: `now` holds every caster's state after it, `before`
    /// the states of the last rebuild (replaced by `now`'s). With `everything`, no regions
    /// are listed.
    pub fn record(
        &mut self,
        generation: u64,
        everything: bool,
        before: &mut EntityHashMap<CasterState>,
        now: impl Iterator<Item = (Entity, CasterState)>,
    ) {
        self.generation = generation;
        self.everything = everything;
        self.regions.clear();
        let mut next = EntityHashMap::with_capacity(before.len());
        for (entity, state) in now {
            self.note(before.remove(&entity), &state);
            next.insert(entity, state);
        }
        // What is left was a caster and is not any more.
        self.regions.extend(before.values().map(|s| s.bounds));
        if everything {
            self.regions.clear();
        }
        *before = next;
    }

    /// Records an in-place update to `generation`: `updated` holds the new states of the
    /// casters rewritten or added, `removed` the entities no longer drawn (every other caster
    /// kept its state), `before` the states of the last change (updated here).
    pub fn record_updates(
        &mut self,
        generation: u64,
        before: &mut EntityHashMap<CasterState>,
        updated: impl Iterator<Item = (Entity, CasterState)>,
        removed: &[Entity],
    ) {
        self.generation = generation;
        self.everything = false;
        self.regions.clear();
        for (entity, state) in updated {
            self.note(before.insert(entity, state), &state);
        }
        self.regions
            .extend(removed.iter().filter_map(|e| before.remove(e)).map(|s| s.bounds));
    }

    /// Lists the regions of a caster whose state went from `old` (None: it was not drawn) to
    /// `now`: none when it is the same, else where it was and where it is.
    fn note(&mut self, old: Option<CasterState>, now: &CasterState) {
        match old {
            Some(old) if old == *now => {}
            Some(old) => self.regions.extend([old.bounds, now.bounds]),
            None => self.regions.push(now.bounds),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ecs::assets::{MaterialHandle, MeshHandle};
    use glam::Vec3;

    fn state(x: f32) -> CasterState {
        CasterState {
            bounds: Aabb {
                min: Vec3::new(x, 0.0, 0.0),
                max: Vec3::new(x + 1.0, 1.0, 1.0),
            },
            key: DrawKey {
                masked: false,
                double_sided: false,
                mesh: MeshHandle(0),
                material: MaterialHandle(0),
            },
            pose: 0,
        }
    }

    #[test]
    fn moved_added_and_removed_casters_leave_their_old_and_new_bounds() {
        let (a, b, c) = (
            Entity::from_raw_u32(1).unwrap(),
            Entity::from_raw_u32(2).unwrap(),
            Entity::from_raw_u32(3).unwrap(),
        );
        let mut before = EntityHashMap::default();
        let mut changes = CasterChanges::default();
        changes.record(1, true, &mut before, [(a, state(0.0)), (b, state(5.0))].into_iter());
        assert!(changes.everything && changes.regions.is_empty());
        // a stays, b moves to 9, c appears.
        changes.record(
            2,
            false,
            &mut before,
            [(a, state(0.0)), (b, state(9.0)), (c, state(20.0))].into_iter(),
        );
        assert_eq!(changes.generation, 2);
        let xs: Vec<f32> = changes.regions.iter().map(|r| r.min.x).collect();
        assert_eq!(xs, [5.0, 9.0, 20.0]);
        // b is no longer a caster.
        changes.record(3, false, &mut before, [(a, state(0.0)), (c, state(20.0))].into_iter());
        let xs: Vec<f32> = changes.regions.iter().map(|r| r.min.x).collect();
        assert_eq!(xs, [9.0]);
        // Nothing changed.
        changes.record(4, false, &mut before, [(a, state(0.0)), (c, state(20.0))].into_iter());
        assert!(changes.regions.is_empty() && !changes.everything);
        // An in-place update: c moves to 30, a is rewritten unchanged.
        changes.record_updates(5, &mut before, [(c, state(30.0)), (a, state(0.0))].into_iter(), &[]);
        let xs: Vec<f32> = changes.regions.iter().map(|r| r.min.x).collect();
        assert_eq!((changes.generation, xs), (5, vec![20.0, 30.0]));
        assert_eq!(before[&c], state(30.0));
        // Removed in place: its last bounds; an entity never drawn leaves none.
        changes.record_updates(6, &mut before, std::iter::empty(), &[a, b]);
        let xs: Vec<f32> = changes.regions.iter().map(|r| r.min.x).collect();
        assert_eq!(xs, [0.0]);
        before.insert(a, state(0.0));
        // A full record afterwards compares against the updated state.
        changes.record(6, false, &mut before, [(a, state(0.0)), (c, state(30.0))].into_iter());
        assert!(changes.regions.is_empty());
    }
}
