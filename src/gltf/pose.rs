//! Posing a model: every node's local transform at a time of one of its animations (its rest
//! transform where no channel moves it), every node's model-space matrix, and a skin's joint
//! matrices in that pose (what the skinning stage blends).

use glam::{Mat4, Quat, Vec3};

use crate::gltf::{GltfModel, NodeProperty};
use crate::math::skinning::joint_matrices;

/// Parent links followed at most this far up (deeper chains, which the loader refuses for the
/// drawn scene, are cut: the node at the cut counts as a root).
const MAX_CHAIN: usize = 256;

/// One node's local transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalTransform {
    /// Translation.
    pub translation: Vec3,
    /// Rotation, unit length.
    pub rotation: Quat,
    /// Scale.
    pub scale: Vec3,
}

impl LocalTransform {
    /// The matrix: scale, then rotation, then translation.
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }
}

impl GltfModel {
    /// Every node's local transform at `time` seconds of `animation` (an index into
    /// [`GltfModel::animations`]; `None`, or an index past them, gives the rest pose).
    pub fn local_pose(&self, animation: Option<usize>, time: f32) -> Vec<LocalTransform> {
        let mut pose: Vec<LocalTransform> = self
            .hierarchy
            .iter()
            .map(|n| LocalTransform {
                translation: n.translation,
                rotation: n.rotation,
                scale: n.scale,
            })
            .collect();
        for channel in animation
            .and_then(|a| self.animations.get(a))
            .map_or(&[][..], |a| &a.channels)
        {
            let Some(node) = pose.get_mut(channel.node) else {
                continue;
            };
            match &channel.property {
                NodeProperty::Translation(t) => node.translation = t.sample(time),
                NodeProperty::Rotation(t) => node.rotation = t.sample(time),
                NodeProperty::Scale(t) => node.scale = t.sample(time),
            }
        }
        pose
    }

    /// Every node's model-space matrix (its ancestors' local matrices, root first, times its
    /// own) in the pose `local` (one entry per node of [`GltfModel::hierarchy`]).
    pub fn model_from_nodes(&self, local: &[LocalTransform]) -> Vec<Mat4> {
        let n = self.hierarchy.len().min(local.len());
        let mut out: Vec<Option<Mat4>> = vec![None; n];
        for start in 0..n {
            if out[start].is_some() {
                continue;
            }
            // The chain of ancestors not yet composed, nearest first.
            let mut chain = vec![start];
            let mut base = Mat4::IDENTITY;
            while let Some(parent) = self.hierarchy[*chain.last().unwrap_or(&start)].parent {
                if parent >= n || chain.len() >= MAX_CHAIN || chain.contains(&parent) {
                    break;
                }
                if let Some(m) = out[parent] {
                    base = m;
                    break;
                }
                chain.push(parent);
            }
            for &node in chain.iter().rev() {
                base *= local[node].matrix();
                out[node] = Some(base);
            }
        }
        out.into_iter().map(|m| m.unwrap_or(Mat4::IDENTITY)).collect()
    }

    /// The joint matrices of `skin` (an index into [`GltfModel::skins`]) in the pose whose
    /// node matrices are `model_from_node`: each joint's model matrix times its inverse bind
    /// matrix. Empty for an unknown skin.
    pub fn skin_matrices(&self, skin: usize, model_from_node: &[Mat4]) -> Vec<Mat4> {
        let Some(skin) = self.skins.get(skin) else {
            return Vec::new();
        };
        let joints: Vec<Mat4> = skin
            .joints
            .iter()
            .map(|&j| model_from_node.get(j).copied().unwrap_or(Mat4::IDENTITY))
            .collect();
        joint_matrices(&joints, &skin.inverse_bind)
    }
}
