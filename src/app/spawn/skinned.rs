//! Spawning skinned parts of a scene's models: each entity gets its own copy of the bind-pose
//! mesh (the renderer writes its posed vertices there), a [`SkinnedMesh`] of the model's
//! skeleton and an [`AnimationPlayer`] playing the animation the object asks for (the model's
//! first by default).

use std::sync::Arc;

use bevy_ecs::world::World;

use crate::app::scene_entity::SceneEntity;
use crate::app::spawn::EntityPlan;
use crate::ecs::assets::{MaterialHandle, MeshHandle, Meshes};
use crate::ecs::components::{Mesh3d, MeshMaterial3d, NotShadowCaster, NotShadowReceiver};
use crate::ecs::mobility::Static;
use crate::ecs::skinning::{AnimationPlayer, SkinSource, SkinSourceHandle, SkinSources, SkinnedMesh};
use crate::math::pose::{Clip, Skeleton};
use crate::scene::AnimationDesc;

/// The skin of one mesh part: indices into the prepared scene's skin sources and skeletons.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct SkinPart {
    /// Index into the prepared skin sources.
    pub source: usize,
    /// Index into the prepared skeletons.
    pub skeleton: usize,
}

/// What the skinned entities of a prepared scene are spawned from.
pub(super) struct SkinnedPlans<'a> {
    /// Every entity plan; the skinned ones are spawned here.
    pub entities: &'a [EntityPlan],
    /// Bind poses, moved into [`SkinSources`].
    pub sources: Vec<SkinSource>,
    /// Skeletons.
    pub skeletons: &'a [Arc<Skeleton>],
}

impl SkinnedPlans<'_> {
    /// Spawns every skinned entity; returns how many.
    pub(super) fn spawn(self, world: &mut World, meshes: &[MeshHandle], materials: &[MaterialHandle]) -> usize {
        let handles: Vec<SkinSourceHandle> = {
            let mut store = world.resource_mut::<SkinSources>();
            self.sources.into_iter().map(|s| store.add(s)).collect()
        };
        let mut spawned = 0;
        for plan in self.entities {
            let Some(part) = plan.skin else {
                continue;
            };
            let mesh = {
                let mut store = world.resource_mut::<Meshes>();
                let bind_pose = store.get(meshes[plan.mesh]).cloned().unwrap_or_default();
                store.add(bind_pose)
            };
            let skin = SkinnedMesh::new(self.skeletons[part.skeleton].clone(), handles[part.source]);
            let mut entity = world.spawn((
                plan.transform,
                Mesh3d(mesh),
                MeshMaterial3d(materials[plan.material]),
                SceneEntity,
                Static,
                skin,
                plan.player.unwrap_or_default(),
            ));
            if !plan.cast {
                entity.insert(NotShadowCaster);
            }
            if !plan.receive {
                entity.insert(NotShadowReceiver);
            }
            spawned += 1;
        }
        spawned
    }
}

/// The player of copy `copy` of an object whose skinned meshes deform `skeleton`, as
/// `animation` asks (the first clip, from 0, looping, without one); its start time wrapped into
/// (or, not looping, clamped to) the clip. The error names a clip the model does not have.
pub(super) fn first_player(
    skeleton: &Skeleton,
    animation: Option<&AnimationDesc>,
    copy: u64,
) -> Result<AnimationPlayer, String> {
    let Some(a) = animation else {
        return Ok(AnimationPlayer::default());
    };
    let clip = match &a.clip {
        None => 0,
        Some(name) => (skeleton.clips.iter())
            .position(|c| c.name.as_deref() == Some(name.as_str()))
            .ok_or_else(|| {
                let names: Vec<String> = (skeleton.clips.iter())
                    .map(|c| c.name.as_deref().map_or("(unnamed)".to_owned(), |n| format!("{n:?}")))
                    .collect();
                let has = if names.is_empty() {
                    "none".to_owned()
                } else {
                    names.join(", ")
                };
                format!("`animation.clip`: the model has no animation named {name:?} (it has: {has})")
            })?,
    };
    let duration = skeleton.clips.get(clip).map_or(0.0, Clip::duration);
    let start = a.start_of_copy(copy);
    let time = match (duration > 0.0, a.looping) {
        (false, _) => 0.0,
        (true, true) => start.rem_euclid(duration),
        (true, false) => start.clamp(0.0, duration),
    };
    Ok(AnimationPlayer {
        clip: Some(clip),
        time,
        speed: a.speed,
        looping: a.looping,
        paused: !a.playing,
    })
}
