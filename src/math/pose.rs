//! Skeletons and their poses, free of any file format: a node hierarchy with rest transforms,
//! the joints of one skin with their inverse bind matrices, and animation clips of node
//! translation, rotation and scale tracks; posed at a time of a clip into joint matrices.

use glam::{Mat4, Quat, Vec3};

use crate::math::animation::Track;

/// Parent links followed at most this far up (deeper chains are cut: the node at the cut
/// counts as a root).
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

/// The node property a track animates, with the track.
#[derive(Clone, Debug, PartialEq)]
pub enum NodeProperty {
    /// Translation.
    Translation(Track<Vec3>),
    /// Rotation.
    Rotation(Track<Quat>),
    /// Scale.
    Scale(Track<Vec3>),
}

impl NodeProperty {
    /// The track's last key time, seconds.
    pub fn duration(&self) -> f32 {
        match self {
            Self::Translation(t) | Self::Scale(t) => t.duration(),
            Self::Rotation(t) => t.duration(),
        }
    }

    /// Sets what the track gives at `time` on `node`.
    pub fn apply(&self, node: &mut LocalTransform, time: f32) {
        match self {
            Self::Translation(t) => node.translation = t.sample(time),
            Self::Rotation(t) => node.rotation = t.sample(time),
            Self::Scale(t) => node.scale = t.sample(time),
        }
    }
}

/// Each node's local transform at `time`: `rest`, with every `(node, property)` channel
/// applied (channels naming a node past `rest` are ignored).
pub fn local_pose<'a>(
    rest: &[LocalTransform],
    channels: impl IntoIterator<Item = (usize, &'a NodeProperty)>,
    time: f32,
) -> Vec<LocalTransform> {
    let mut pose = Vec::new();
    local_pose_into(rest, channels, time, &mut pose);
    pose
}

/// [`local_pose`] into `pose` (replacing what it held).
fn local_pose_into<'a>(
    rest: &[LocalTransform],
    channels: impl IntoIterator<Item = (usize, &'a NodeProperty)>,
    time: f32,
    pose: &mut Vec<LocalTransform>,
) {
    pose.clear();
    pose.extend_from_slice(rest);
    for (node, property) in channels {
        if let Some(n) = pose.get_mut(node) {
            property.apply(n, time);
        }
    }
}

/// Every node's model-space matrix: its ancestors' local matrices (root first) times its own.
/// `parents[i]` is node `i`'s parent; a cycle or a chain deeper than 256 is cut.
pub fn model_from_nodes(parents: &[Option<usize>], local: &[LocalTransform]) -> Vec<Mat4> {
    let mut scratch = PoseScratch::default();
    compose_nodes(parents, local, &mut scratch);
    scratch.model.into_iter().map(|m| m.unwrap_or(Mat4::IDENTITY)).collect()
}

/// [`model_from_nodes`] into `scratch.model` (`None` for no node), reusing its buffers.
fn compose_nodes(parents: &[Option<usize>], local: &[LocalTransform], scratch: &mut PoseScratch) {
    let n = parents.len().min(local.len());
    let (out, chain) = (&mut scratch.model, &mut scratch.chain);
    out.clear();
    out.resize(n, None);
    for start in 0..n {
        if out[start].is_some() {
            continue;
        }
        // The ancestors not yet composed, nearest first.
        chain.clear();
        chain.push(start);
        let mut base = Mat4::IDENTITY;
        let mut at = start;
        while let Some(parent) = parents[at] {
            if parent >= n || chain.len() >= MAX_CHAIN || chain.contains(&parent) {
                break;
            }
            if let Some(m) = out[parent] {
                base = m;
                break;
            }
            chain.push(parent);
            at = parent;
        }
        for &node in chain.iter().rev() {
            base *= local[node].matrix();
            out[node] = Some(base);
        }
    }
}

/// Buffers for posing skeletons that are kept from pose to pose, so that posing allocates
/// nothing once they have grown.
#[derive(Clone, Debug, Default)]
pub struct PoseScratch {
    local: Vec<LocalTransform>,
    model: Vec<Option<Mat4>>,
    chain: Vec<usize>,
}

/// An animation clip: tracks of node properties.
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    /// The clip's name.
    pub name: Option<String>,
    /// `(node, property)` tracks.
    pub channels: Vec<(usize, NodeProperty)>,
}

impl Clip {
    /// The last key time of any track, seconds.
    pub fn duration(&self) -> f32 {
        self.channels.iter().map(|(_, p)| p.duration()).fold(0.0, f32::max)
    }
}

/// A skin's skeleton: the node hierarchy, which nodes are its joints, their inverse bind
/// matrices, and the clips that move the nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct Skeleton {
    /// Each node's parent.
    pub parents: Vec<Option<usize>>,
    /// Each node's rest transform.
    pub rest: Vec<LocalTransform>,
    /// Node index of each joint.
    pub joints: Vec<usize>,
    /// One inverse bind matrix per joint.
    pub inverse_bind: Vec<Mat4>,
    /// Animation clips.
    pub clips: Vec<Clip>,
}

impl Skeleton {
    /// The joint matrices at `time` seconds of `clip` (the rest pose without one, or for an
    /// index past the clips).
    pub fn joint_matrices(&self, clip: Option<usize>, time: f32) -> Vec<Mat4> {
        let mut out = Vec::new();
        self.joint_matrices_into(clip, time, &mut PoseScratch::default(), &mut out);
        out
    }

    /// [`joint_matrices`](Self::joint_matrices) into `out` (replacing what it held), with the
    /// intermediate poses in `scratch`: no allocation once both have grown.
    pub fn joint_matrices_into(&self, clip: Option<usize>, time: f32, scratch: &mut PoseScratch, out: &mut Vec<Mat4>) {
        let channels = clip.and_then(|c| self.clips.get(c)).map_or(&[][..], |c| &c.channels);
        let mut local = std::mem::take(&mut scratch.local);
        local_pose_into(&self.rest, channels.iter().map(|(n, p)| (*n, p)), time, &mut local);
        compose_nodes(&self.parents, &local, scratch);
        scratch.local = local;
        let model = &scratch.model;
        skin_matrices_into(
            &self.joints,
            &self.inverse_bind,
            |j| model.get(j).copied().flatten(),
            out,
        );
    }
}

/// The joint matrices of a skin whose joints are the nodes `joints` (inverse bind matrices
/// `inverse_bind`), in the pose whose node matrices are `model_from_node`: each joint's model
/// matrix times its inverse bind matrix (a joint past the nodes counts as at the origin).
pub fn skin_matrices(joints: &[usize], inverse_bind: &[Mat4], model_from_node: &[Mat4]) -> Vec<Mat4> {
    let mut out = Vec::new();
    skin_matrices_into(joints, inverse_bind, |j| model_from_node.get(j).copied(), &mut out);
    out
}

/// [`skin_matrices`] into `out` (replacing what it held), with node `j`'s model matrix
/// `model(j)` (None counts as the origin).
fn skin_matrices_into(
    joints: &[usize],
    inverse_bind: &[Mat4],
    model: impl Fn(usize) -> Option<Mat4>,
    out: &mut Vec<Mat4>,
) {
    assert_eq!(joints.len(), inverse_bind.len(), "one inverse bind matrix per joint");
    out.clear();
    out.extend(
        joints
            .iter()
            .zip(inverse_bind)
            .map(|(&j, b)| model(j).unwrap_or(Mat4::IDENTITY) * *b),
    );
}

#[cfg(test)]
mod tests {
    use glam::{Mat4, Quat, Vec3};

    use super::{LocalTransform, model_from_nodes};

    fn at(x: f32) -> LocalTransform {
        LocalTransform {
            translation: Vec3::new(x, 0.0, 0.0),
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
        }
    }

    #[test]
    fn children_compose_through_their_parents_in_any_order() {
        // Node 0's parent is node 2, whose parent is node 1.
        let parents = [Some(2), None, Some(1)];
        let model = model_from_nodes(&parents, &[at(1.0), at(10.0), at(100.0)]);
        assert_eq!(model[1], Mat4::from_translation(Vec3::X * 10.0));
        assert_eq!(model[2], Mat4::from_translation(Vec3::X * 110.0));
        assert_eq!(model[0], Mat4::from_translation(Vec3::X * 111.0));
    }

    #[test]
    fn posing_into_reused_buffers_equals_posing_afresh() {
        use super::{Clip, NodeProperty, PoseScratch, Skeleton};
        use crate::math::animation::{Interpolation, Track};
        let swing = Track {
            times: vec![0.0, 1.0],
            values: vec![Quat::IDENTITY, Quat::from_rotation_z(1.0)],
            interpolation: Interpolation::Linear,
        };
        let skeleton = Skeleton {
            parents: vec![None, Some(0), Some(1)],
            rest: vec![at(0.0), at(1.0), at(1.0)],
            joints: vec![2, 0, 1],
            inverse_bind: vec![Mat4::from_translation(Vec3::X * -2.0), Mat4::IDENTITY, Mat4::IDENTITY],
            clips: vec![Clip {
                name: None,
                channels: vec![(1, NodeProperty::Rotation(swing))],
            }],
        };
        let (mut scratch, mut out) = (PoseScratch::default(), Vec::new());
        for (clip, time) in [(Some(0), 0.25), (None, 0.0), (Some(0), 0.75), (Some(3), 0.5)] {
            skeleton.joint_matrices_into(clip, time, &mut scratch, &mut out);
            assert_eq!(out, skeleton.joint_matrices(clip, time), "clip {clip:?} at {time}");
        }
        // The rest pose puts joint 0 (node 2, bound at x = 2) at its bind place.
        skeleton.joint_matrices_into(None, 0.0, &mut scratch, &mut out);
        assert_eq!(out[0], Mat4::IDENTITY);
        // Node 2 turns about node 1 (x = 1) halfway through the swing.
        skeleton.joint_matrices_into(Some(0), 0.5, &mut scratch, &mut out);
        let tip = out[0].transform_point3(Vec3::X * 2.0);
        assert!(
            (tip - (Vec3::X + Quat::from_rotation_z(0.5) * Vec3::X)).length() < 1e-5,
            "{tip}"
        );
    }

    #[test]
    fn a_cycle_is_cut_instead_of_looping() {
        let parents = [Some(1), Some(0)];
        let model = model_from_nodes(&parents, &[at(1.0), at(2.0)]);
        assert!(model.iter().all(|m| m.is_finite()));
    }
}
