//! The marker of the entities a scene file spawned.

use bevy_ecs::component::Component;

/// Marks every entity [`spawn_scene`](crate::app::spawn_scene) creates, so [`despawn_scene`](crate::app::despawn_scene) can remove them.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SceneEntity;
