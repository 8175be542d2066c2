//! Linear blend skinning, the CPU mirror of the skinned vertex stage: a vertex bound to up to
//! four joints moves with the weighted sum of their matrices (each joint's current transform
//! times its inverse bind matrix); and the bounds of a skinned mesh in any pose, from boxes of
//! the bind-pose vertices each joint moves, carried by the joints' matrices.

use glam::{Mat3, Mat4, Vec3};

use crate::math::aabb::Aabb;

/// The most joints one skin may have (the joint-matrix buffer's per-skin slice).
pub const MAX_JOINTS: usize = 256;

/// A vertex's joints (indices into its skin's joint list) and their weights, summing to 1.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointWeights {
    /// Joint indices.
    pub joints: [u16; 4],
    /// Weights, in `[0, 1]`, summing to 1.
    pub weights: [f32; 4],
}

impl JointWeights {
    /// Scales `weights` to sum to 1 (negative or non-finite weights count as 0); `None` when
    /// nothing is left to scale.
    pub fn normalized(joints: [u16; 4], weights: [f32; 4]) -> Option<JointWeights> {
        let weights = weights.map(|w| if w.is_finite() && w > 0.0 { w } else { 0.0 });
        let sum: f32 = weights.iter().sum();
        (sum > 0.0 && sum.is_finite()).then(|| JointWeights {
            joints,
            weights: weights.map(|w| w / sum),
        })
    }

    /// The joints with a weight above zero, with their weights.
    pub fn influences(&self) -> impl Iterator<Item = (usize, f32)> + '_ {
        self.joints
            .iter()
            .zip(self.weights)
            .filter(|(_, w)| *w > 0.0)
            .map(|(&j, w)| (usize::from(j), w))
    }
}

/// Each joint's skinning matrix: `model_from_joint[j] · inverse_bind[j]`, the transform from
/// the mesh's bind space to model space the joint gives its vertices.
///
/// # Panics
/// If the two slices differ in length.
pub fn joint_matrices(model_from_joint: &[Mat4], inverse_bind: &[Mat4]) -> Vec<Mat4> {
    assert_eq!(
        model_from_joint.len(),
        inverse_bind.len(),
        "one inverse bind matrix per joint"
    );
    model_from_joint
        .iter()
        .zip(inverse_bind)
        .map(|(j, b)| *j * *b)
        .collect()
}

/// The weighted sum of a vertex's joint matrices (joints past `matrices` count as identity).
pub fn blended_matrix(influence: &JointWeights, matrices: &[Mat4]) -> Mat4 {
    let mut sum = Mat4::ZERO;
    for (j, w) in influence.influences() {
        sum += matrices.get(j).copied().unwrap_or(Mat4::IDENTITY) * w;
    }
    sum
}

/// A bind-space position skinned into model space.
pub fn skin_position(position: Vec3, influence: &JointWeights, matrices: &[Mat4]) -> Vec3 {
    blended_matrix(influence, matrices).transform_point3(position)
}

/// A bind-space normal skinned into model space: the blended matrix's cofactor matrix (its
/// inverse transpose times the determinant) applied, signed by the determinant and made unit
/// length; `normal` itself where that leaves no length.
pub fn skin_normal(normal: Vec3, influence: &JointWeights, matrices: &[Mat4]) -> Vec3 {
    let m = blended_matrix(influence, matrices);
    let (c0, c1, c2) = (m.x_axis.truncate(), m.y_axis.truncate(), m.z_axis.truncate());
    let cofactor = Mat3::from_cols(c1.cross(c2), c2.cross(c0), c0.cross(c1));
    let sign = if c0.dot(c1.cross(c2)) < 0.0 { -1.0 } else { 1.0 };
    let n = cofactor * normal * sign;
    let length = n.length();
    if length > 1e-20 { n / length } else { normal }
}

/// For each of `joint_count` joints, the box of the bind-space positions it moves (weight
/// above zero); [`Aabb::EMPTY`] for a joint that moves none. Joints past `joint_count` are
/// ignored (the loader rejects them).
pub fn joint_bounds(positions: &[Vec3], influences: &[JointWeights], joint_count: usize) -> Vec<Aabb> {
    let mut boxes = vec![Aabb::EMPTY; joint_count];
    for (p, influence) in positions.iter().zip(influences) {
        for (j, _) in influence.influences() {
            if let Some(b) = boxes.get_mut(j) {
                *b = b.with_point(*p);
            }
        }
    }
    boxes
}

/// Model-space bounds of the skinned mesh in the pose `matrices`: the union of each joint's
/// box carried by its matrix. A skinned vertex is a weighted mean of its joints' images of
/// it, each inside its joint's carried box, so the union holds every skinned vertex.
pub fn skinned_bounds(joint_boxes: &[Aabb], matrices: &[Mat4]) -> Aabb {
    joint_boxes
        .iter()
        .zip(matrices)
        .filter(|(b, _)| !b.is_empty())
        .fold(Aabb::EMPTY, |acc, (b, m)| acc.union(b.transformed(m)))
}

#[cfg(test)]
#[path = "skinning_tests.rs"]
mod tests;
