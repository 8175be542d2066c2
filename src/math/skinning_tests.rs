//! Skinning math: rigid and blended joints, normals, weights, and bounds that hold every
//! skinned vertex of random meshes in random poses.

use glam::{Mat4, Quat, Vec3};
use proptest::prelude::*;

use super::*;

fn weights(joints: [u16; 4], w: [f32; 4]) -> JointWeights {
    JointWeights::normalized(joints, w).expect("some weight")
}

#[test]
fn one_joint_moves_its_vertices_rigidly() {
    let joint = Mat4::from_rotation_translation(Quat::from_rotation_z(0.7), Vec3::new(1.0, 2.0, 3.0));
    let bind = Mat4::from_translation(Vec3::new(0.0, 1.0, 0.0));
    let matrices = joint_matrices(&[joint], &[bind.inverse()]);
    let influence = weights([0, 0, 0, 0], [1.0, 0.0, 0.0, 0.0]);
    let p = Vec3::new(0.5, 1.5, -0.25);
    let expected = joint.transform_point3(bind.inverse().transform_point3(p));
    assert!((skin_position(p, &influence, &matrices) - expected).length() < 1e-5);
    let n = skin_normal(Vec3::X, &influence, &matrices);
    assert!((n - Quat::from_rotation_z(0.7) * Vec3::X).length() < 1e-5);
}

#[test]
fn the_bind_pose_leaves_vertices_in_place() {
    let binds = [
        Mat4::from_translation(Vec3::Y),
        Mat4::from_rotation_x(0.4),
        Mat4::from_scale(Vec3::splat(2.0)),
    ];
    let inverse: Vec<Mat4> = binds.iter().map(|b| b.inverse()).collect();
    let matrices = joint_matrices(&binds, &inverse);
    let influence = weights([0, 1, 2, 0], [0.2, 0.3, 0.5, 0.0]);
    let p = Vec3::new(0.3, -0.7, 1.1);
    assert!((skin_position(p, &influence, &matrices) - p).length() < 1e-5);
}

#[test]
fn two_joints_blend_halfway() {
    let matrices = [Mat4::IDENTITY, Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0))];
    let influence = weights([0, 1, 0, 0], [0.5, 0.5, 0.0, 0.0]);
    assert_eq!(skin_position(Vec3::X, &influence, &matrices), Vec3::new(1.0, 1.0, 0.0));
}

#[test]
fn weights_are_scaled_to_one_and_empty_ones_refused() {
    let w = weights([3, 1, 0, 0], [2.0, 2.0, 0.0, 0.0]);
    assert_eq!(w.weights, [0.5, 0.5, 0.0, 0.0]);
    assert_eq!(w.influences().collect::<Vec<_>>(), vec![(3, 0.5), (1, 0.5)]);
    assert!(JointWeights::normalized([0; 4], [0.0; 4]).is_none());
    assert!(JointWeights::normalized([0; 4], [-1.0, f32::NAN, 0.0, 0.0]).is_none());
    let w = weights([0, 1, 2, 3], [f32::INFINITY, 1.0, -3.0, 1.0]);
    assert_eq!(w.weights, [0.0, 0.5, 0.0, 0.5]);
}

#[test]
fn a_joint_that_moves_nothing_adds_no_bounds() {
    let positions = [Vec3::ZERO, Vec3::X];
    let influences = [weights([0, 0, 0, 0], [1.0, 0.0, 0.0, 0.0]); 2];
    let boxes = joint_bounds(&positions, &influences, 2);
    assert!(boxes[1].is_empty());
    let far = Mat4::from_translation(Vec3::splat(1000.0));
    let b = skinned_bounds(&boxes, &[Mat4::IDENTITY, far]);
    assert_eq!((b.min, b.max), (Vec3::ZERO, Vec3::X));
}

fn joint_matrix() -> impl Strategy<Value = Mat4> {
    (
        prop::array::uniform3(-3.0f32..3.0),
        prop::array::uniform3(-1.0f32..1.0),
        0.0f32..6.3,
        0.3f32..2.0,
    )
        .prop_map(|(t, axis, angle, scale)| {
            let axis = Vec3::from(axis).try_normalize().unwrap_or(Vec3::Y);
            Mat4::from_scale_rotation_translation(Vec3::splat(scale), Quat::from_axis_angle(axis, angle), Vec3::from(t))
        })
}

proptest! {
    #[test]
    fn bounds_from_the_joints_hold_every_skinned_vertex(
        matrices in prop::collection::vec(joint_matrix(), 1..6),
        vertices in prop::collection::vec(
            (prop::array::uniform3(-2.0f32..2.0), prop::array::uniform4(0u16..6), prop::array::uniform4(0.0f32..1.0)),
            1..40,
        ),
    ) {
        let n = matrices.len() as u16;
        let positions: Vec<Vec3> = vertices.iter().map(|v| Vec3::from(v.0)).collect();
        let influences: Vec<JointWeights> = vertices
            .iter()
            .map(|v| {
                let w = [v.2[0] + 0.01, v.2[1], v.2[2], v.2[3]];
                JointWeights::normalized(v.1.map(|j| j % n), w).expect("the first weight is positive")
            })
            .collect();
        let boxes = joint_bounds(&positions, &influences, matrices.len());
        let bounds = skinned_bounds(&boxes, &matrices);
        for (p, influence) in positions.iter().zip(&influences) {
            let skinned = skin_position(*p, influence, &matrices);
            let slack = 1e-4 * (1.0 + skinned.abs().max_element());
            prop_assert!(
                skinned.cmpge(bounds.min - slack).all() && skinned.cmple(bounds.max + slack).all(),
                "{} outside {:?}", skinned, bounds
            );
        }
    }
}
