//! Skinned, animated meshes: [`SkinnedMesh`] (a skeleton, the bind pose it deforms from
//! [`SkinSources`], this frame's joint matrices and the bounds they give), [`AnimationPlayer`]
//! (which clip plays, where, how fast), posed each frame by [`animate_skins`] as
//! [`AnimationClock`] advances; and [`SkinningFrame`], one job per skinned entity, which the
//! renderer's compute skinning runs into the entity's own mesh before any pass draws it.
//!
//! A skinned entity's [`Mesh3d`] is its own copy of the bind pose (the renderer overwrites it
//! with the posed vertices); its bounds, for culling and for the shadow views it redraws,
//! are the union of its joints' boxes carried by their matrices
//! ([`crate::math::skinning::skinned_bounds`]), never the rest pose's.

use std::sync::Arc;

use bevy_ecs::change_detection::DetectChanges;
use bevy_ecs::component::Component;
use bevy_ecs::entity::Entity;
use bevy_ecs::resource::Resource;
use bevy_ecs::system::{Local, Query, Res, ResMut};
use bevy_ecs::world::Ref;
use glam::Mat4;

use crate::ecs::assets::{MeshHandle, asset_store};
use crate::ecs::components::Mesh3d;
use crate::math::aabb::Aabb;
use crate::math::pose::{PoseScratch, Skeleton};
use crate::math::skinning::{JointWeights, joint_bounds, skinned_bounds};
use crate::mesh::Vertex;

/// The bind pose a skinned mesh deforms: its vertices, their joints and weights, and the box
/// of the bind-pose vertices each joint moves.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SkinSource {
    /// Bind-pose vertices (model space of the skinned model).
    pub vertices: Vec<Vertex>,
    /// One influence per vertex.
    pub influences: Vec<JointWeights>,
    /// Per joint of the skin, the box of the vertices it moves.
    pub joint_boxes: Vec<Aabb>,
}

impl SkinSource {
    /// A source from its vertices and influences, for a skin of `joint_count` joints.
    pub fn new(vertices: Vec<Vertex>, influences: Vec<JointWeights>, joint_count: usize) -> SkinSource {
        let positions: Vec<glam::Vec3> = vertices.iter().map(|v| glam::Vec3::from(v.position)).collect();
        let joint_boxes = joint_bounds(&positions, &influences, joint_count);
        SkinSource {
            vertices,
            influences,
            joint_boxes,
        }
    }
}

/// Index of a bind pose in [`SkinSources`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SkinSourceHandle(pub u32);

asset_store!(
    /// Every bind pose skinned entities deform, addressed by [`SkinnedMesh::source`].
    SkinSources, SkinSource, SkinSourceHandle
);

/// A mesh deformed by a skeleton. Insert it with the entity's own [`Mesh3d`] (a copy of the
/// source's bind pose) and, to animate it, an [`AnimationPlayer`].
#[derive(Component, Clone, Debug)]
pub struct SkinnedMesh {
    /// The skeleton (shared by every entity of the same model).
    pub skeleton: Arc<Skeleton>,
    /// The bind pose it deforms.
    pub source: SkinSourceHandle,
    /// Joint matrices of the current pose, bind space to the entity's local space (set by
    /// [`animate_skins`]; empty until the first pose).
    pub joint_matrices: Vec<Mat4>,
    /// Bounds of the posed mesh in the entity's local space.
    pub bounds: Aabb,
    /// Counts the poses taken, so a caster whose pose changed within the same bounds still
    /// redraws the shadow views it touches.
    pub pose: u64,
    /// The clip and time of the current pose (`None` before the first).
    pub posed_at: Option<(Option<usize>, f32)>,
}

impl SkinnedMesh {
    /// A skinned mesh of `skeleton` deforming source `source`, not posed yet.
    pub fn new(skeleton: Arc<Skeleton>, source: SkinSourceHandle) -> SkinnedMesh {
        SkinnedMesh {
            skeleton,
            source,
            joint_matrices: Vec::new(),
            bounds: Aabb::EMPTY,
            pose: 0,
            posed_at: None,
        }
    }
}

/// Which clip of a [`SkinnedMesh`]'s skeleton plays, and where.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct AnimationPlayer {
    /// Index of the clip (`None`: the rest pose).
    pub clip: Option<usize>,
    /// Seconds into the clip.
    pub time: f32,
    /// Clip seconds per clock second (negative plays backwards).
    pub speed: f32,
    /// Whether the clip starts again past its end (else it holds its last pose).
    pub looping: bool,
    /// Whether time stands still.
    pub paused: bool,
}

impl Default for AnimationPlayer {
    /// The first clip, from its start, at normal speed, looping.
    fn default() -> Self {
        AnimationPlayer {
            clip: Some(0),
            time: 0.0,
            speed: 1.0,
            looping: true,
            paused: false,
        }
    }
}

/// Seconds one frame advances every [`AnimationPlayer`] (a fixed step, so frames and tests
/// are repeatable; an app sets it from its frame time).
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct AnimationClock {
    /// Seconds per frame.
    pub delta: f32,
}

impl Default for AnimationClock {
    fn default() -> Self {
        AnimationClock { delta: 1.0 / 60.0 }
    }
}

/// Advances every player by the clock and poses its skinned mesh: joint matrices and bounds,
/// wherever the clip or time differs from the current pose (a paused player whose time is
/// set is posed there; a mesh without a player takes the rest pose once). Posing allocates
/// nothing once the buffers have grown.
pub fn animate_skins(
    clock: Option<Res<AnimationClock>>,
    sources: Res<SkinSources>,
    mut skins: Query<(&mut SkinnedMesh, Option<&mut AnimationPlayer>)>,
    mut scratch: Local<PoseScratch>,
) {
    let delta = clock.map_or(AnimationClock::default().delta, |c| c.delta);
    for (mut skin, player) in &mut skins {
        let (clip, time) = match player {
            Some(mut p) => {
                let duration = p
                    .clip
                    .and_then(|c| skin.skeleton.clips.get(c))
                    .map_or(0.0, |c| c.duration());
                // NOTE: the first pose is taken at the player's time, unadvanced.
                let advances = skin.posed_at.is_some() && !p.paused && p.speed != 0.0 && delta.is_finite();
                if advances && duration > 0.0 {
                    let t = p.time + delta * p.speed;
                    p.time = if p.looping {
                        t.rem_euclid(duration)
                    } else {
                        t.clamp(0.0, duration)
                    };
                }
                (p.clip, p.time)
            }
            None => (None, 0.0),
        };
        if skin.posed_at == Some((clip, time)) {
            continue;
        }
        let skin = skin.as_mut();
        let SkinnedMesh {
            skeleton,
            joint_matrices,
            ..
        } = skin;
        skeleton.joint_matrices_into(clip, time, &mut scratch, joint_matrices);
        skin.bounds = sources
            .get(skin.source)
            .map_or(Aabb::EMPTY, |s| skinned_bounds(&s.joint_boxes, &skin.joint_matrices));
        skin.pose += 1;
        skin.posed_at = Some((clip, time));
    }
}

/// One skinned entity's job for the compute skinning this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SkinJob {
    /// The entity.
    pub entity: Entity,
    /// The bind pose it deforms.
    pub source: SkinSourceHandle,
    /// The entity's own mesh, which receives the posed vertices.
    pub mesh: MeshHandle,
    /// First of its joint matrices in [`SkinningFrame::joints`].
    pub joint_first: u32,
    /// Whether its pose changed since the last frame.
    pub changed: bool,
}

/// Every skinned entity's job and joint matrices, gathered after [`animate_skins`].
#[derive(Resource, Debug, Default)]
pub struct SkinningFrame {
    /// One job per skinned entity.
    pub jobs: Vec<SkinJob>,
    /// Every job's joint matrices, back to back.
    pub joints: Vec<Mat4>,
}

impl SkinningFrame {
    /// True when some job's pose changed.
    pub fn any_changed(&self) -> bool {
        self.jobs.iter().any(|j| j.changed)
    }
}

/// Gathers [`SkinningFrame`] from every posed skinned entity.
pub fn collect_skinning(mut frame: ResMut<SkinningFrame>, skins: Query<(Entity, &Mesh3d, Ref<SkinnedMesh>)>) {
    let frame = frame.as_mut();
    frame.jobs.clear();
    frame.joints.clear();
    for (entity, mesh, skin) in &skins {
        if skin.joint_matrices.is_empty() {
            continue;
        }
        frame.jobs.push(SkinJob {
            entity,
            source: skin.source,
            mesh: mesh.0,
            joint_first: frame.joints.len() as u32,
            changed: skin.is_changed(),
        });
        frame.joints.extend_from_slice(&skin.joint_matrices);
    }
}
