//! Which mesh entities the instance sync must look at this frame: those whose transform, mesh,
//! material, shadow flags or skinned pose changed, found by change-detection scans that skip
//! [`Static`] entities by archetype, plus the entities [`Static`]'s hooks listed and those
//! whose mesh or shadow flag was removed.

use bevy_ecs::entity::Entity;
use bevy_ecs::lifecycle::RemovedComponents;
use bevy_ecs::query::{Changed, Or, With, Without};
use bevy_ecs::resource::Resource;
use bevy_ecs::system::{Query, ResMut, SystemParam};
use bevy_transform::components::GlobalTransform;

use crate::ecs::components::{Mesh3d, MeshMaterial3d, NotShadowCaster, NotShadowReceiver};
use crate::ecs::mobility::{Static, StaticChanges};
use crate::ecs::skinning::SkinnedMesh;

/// What the latest instance sync looked at and did.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct InstanceSync {
    /// Entities the change scans of the latest sync went through (those of the archetypes
    /// they match; static entities are never among them).
    pub scanned: usize,
    /// Entities listed to look at in the latest sync (changed, or listed by [`Static`]'s hooks).
    pub dirty: usize,
    /// Syncs that rewrote, appended or removed instances in place, since the app started.
    pub updates: u64,
    /// Syncs that rebuilt the whole list, since the app started.
    pub rebuilds: u64,
}

/// A moving mesh entity (not [`Static`]) that passes the change filter `F`.
type Scan<'w, 's, F> = Query<'w, 's, Entity, (With<Mesh3d>, Without<Static>, F)>;

/// The change scans and removal readers of the instance sync.
#[derive(SystemParam)]
pub struct ChangedInstances<'w, 's> {
    moved: Scan<'w, 's, Changed<GlobalTransform>>,
    meshes: Scan<'w, 's, Changed<Mesh3d>>,
    materials: Scan<'w, 's, Changed<MeshMaterial3d>>,
    flags: Scan<'w, 's, Or<(Changed<NotShadowCaster>, Changed<NotShadowReceiver>)>>,
    // NOTE: poses change every animated frame, static or not; only skinned archetypes match.
    posed: Query<'w, 's, Entity, (With<Mesh3d>, Changed<SkinnedMesh>)>,
    removed_meshes: RemovedComponents<'w, 's, Mesh3d>,
    removed_non_casters: RemovedComponents<'w, 's, NotShadowCaster>,
    removed_receivers: RemovedComponents<'w, 's, NotShadowReceiver>,
    statics: Option<ResMut<'w, StaticChanges>>,
    /// What this sync looked at and did.
    pub stats: ResMut<'w, InstanceSync>,
}

impl ChangedInstances<'_, '_> {
    /// Fills `dirty` with every entity to look at (sorted, without repeats), those whose mesh
    /// or shadow flag was removed (or that were despawned) among them.
    pub fn collect(&mut self, dirty: &mut Vec<Entity>) {
        // NOTE: an iterator's upper size bound is the length of the archetypes it matches,
        // read without visiting an entity.
        let matched = |hint: (usize, Option<usize>)| hint.1.unwrap_or(hint.0);
        let scanned = matched(self.moved.iter().size_hint())
            + matched(self.meshes.iter().size_hint())
            + matched(self.materials.iter().size_hint())
            + matched(self.flags.iter().size_hint())
            + matched(self.posed.iter().size_hint());
        dirty.clear();
        dirty.extend(self.moved.iter());
        dirty.extend(self.meshes.iter());
        dirty.extend(self.materials.iter());
        dirty.extend(self.flags.iter());
        dirty.extend(self.posed.iter());
        if let Some(statics) = self.statics.as_deref_mut() {
            dirty.append(&mut statics.marked);
            dirty.append(&mut statics.released);
        }
        dirty.extend(self.removed_meshes.read());
        dirty.extend(self.removed_non_casters.read());
        dirty.extend(self.removed_receivers.read());
        dirty.sort_unstable();
        dirty.dedup();
        self.stats.scanned = scanned;
        self.stats.dirty = dirty.len();
    }
}
