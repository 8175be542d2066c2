//! Posing a model: every node's local transform at a time of one of its animations (its rest
//! transform where no channel moves it), every node's model-space matrix, a skin's joint
//! matrices in that pose, and a skin's [`Skeleton`] for the ECS. The math is
//! [`crate::math::pose`]'s.

use glam::Mat4;

use crate::gltf::GltfModel;
pub use crate::math::pose::LocalTransform;
use crate::math::pose::{Clip, Skeleton, local_pose, model_from_nodes, skin_matrices};

impl GltfModel {
    /// Every node's rest transform, in index order.
    fn rest(&self) -> Vec<LocalTransform> {
        self.hierarchy
            .iter()
            .map(|n| LocalTransform {
                translation: n.translation,
                rotation: n.rotation,
                scale: n.scale,
            })
            .collect()
    }

    fn parents(&self) -> Vec<Option<usize>> {
        self.hierarchy.iter().map(|n| n.parent).collect()
    }

    /// Every node's local transform at `time` seconds of `animation` (an index into
    /// [`GltfModel::animations`]; `None`, or an index past them, gives the rest pose).
    pub fn local_pose(&self, animation: Option<usize>, time: f32) -> Vec<LocalTransform> {
        let channels = animation
            .and_then(|a| self.animations.get(a))
            .map_or(&[][..], |a| &a.channels);
        local_pose(&self.rest(), channels.iter().map(|c| (c.node, &c.property)), time)
    }

    /// Every node's model-space matrix (its ancestors' local matrices, root first, times its
    /// own) in the pose `local` (one entry per node of [`GltfModel::hierarchy`]).
    pub fn model_from_nodes(&self, local: &[LocalTransform]) -> Vec<Mat4> {
        model_from_nodes(&self.parents(), local)
    }

    /// The joint matrices of `skin` (an index into [`GltfModel::skins`]) in the pose whose
    /// node matrices are `model_from_node`: each joint's model matrix times its inverse bind
    /// matrix. Empty for an unknown skin.
    pub fn skin_matrices(&self, skin: usize, model_from_node: &[Mat4]) -> Vec<Mat4> {
        self.skins
            .get(skin)
            .map_or_else(Vec::new, |s| skin_matrices(&s.joints, &s.inverse_bind, model_from_node))
    }

    /// The skeleton of `skin` with every animation of the model as its clips; `None` for an
    /// unknown skin.
    pub fn skeleton(&self, skin: usize) -> Option<Skeleton> {
        let skin = self.skins.get(skin)?;
        Some(Skeleton {
            parents: self.parents(),
            rest: self.rest(),
            joints: skin.joints.clone(),
            inverse_bind: skin.inverse_bind.clone(),
            clips: self
                .animations
                .iter()
                .map(|a| Clip {
                    name: a.name.clone(),
                    channels: a.channels.iter().map(|c| (c.node, c.property.clone())).collect(),
                })
                .collect(),
        })
    }
}
