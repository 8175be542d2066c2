//! Skins: each skin's joints and inverse bind matrices, and each primitive's joints and
//! weights (`JOINTS_0`, `WEIGHTS_0`), checked before they are read: at most
//! [`MAX_JOINTS`] joints, invertible finite bind matrices, weights that sum above zero, and
//! (once a node pairs a mesh with a skin) joint indices inside the skin.

use ::gltf::Document;
use ::gltf::mesh::Primitive;
use glam::Mat4;

use crate::gltf::accessor::{self, Expect};
use crate::gltf::load::Cx;
use crate::gltf::{GltfError, GltfMesh, GltfSkin};
use crate::math::skinning::{JointWeights, MAX_JOINTS};

/// Reads every skin of the document.
pub(super) fn read_skins(cx: &Cx, document: &Document, buffers: &[Vec<u8>]) -> Result<Vec<GltfSkin>, GltfError> {
    let mut skins = Vec::new();
    for skin in document.skins() {
        let context = format!("skin {}", skin.index());
        let joints: Vec<usize> = skin.joints().map(|n| n.index()).collect();
        if joints.is_empty() {
            return Err(cx.data(&context, "has no joints"));
        }
        if joints.len() > MAX_JOINTS {
            return Err(cx.data(
                &context,
                format!("has {} joints; at most {MAX_JOINTS} per skin", joints.len()),
            ));
        }
        let inverse_bind = match skin.inverse_bind_matrices() {
            None => vec![Mat4::IDENTITY; joints.len()],
            Some(acc) => {
                accessor::check(cx, &context, "inverseBindMatrices", &acc, Expect::Mat4F32)?;
                if acc.count() < joints.len() {
                    return Err(cx.data(
                        &context,
                        format!(
                            "inverseBindMatrices (accessor {}) has {} matrices for {} joints",
                            acc.index(),
                            acc.count(),
                            joints.len()
                        ),
                    ));
                }
                let reader = skin.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
                let read: Vec<Mat4> = reader
                    .read_inverse_bind_matrices()
                    .ok_or_else(|| cx.data(&context, "inverseBindMatrices could not be read"))?
                    .take(joints.len())
                    .map(|m| Mat4::from_cols_array_2d(&m))
                    .collect();
                read
            }
        };
        for (j, m) in inverse_bind.iter().enumerate() {
            let det = m.determinant();
            if !m.is_finite() || !det.is_finite() || det.abs() < 1e-12 {
                return Err(cx.data(
                    &context,
                    format!(
                        "the inverse bind matrix of joint {j} (node {}) is not invertible (determinant {det})",
                        joints[j]
                    ),
                ));
            }
        }
        skins.push(GltfSkin {
            name: skin.name().map(str::to_owned),
            joints,
            inverse_bind,
        });
    }
    Ok(skins)
}

/// The joints and weights of each of a primitive's `vertex_count` vertices, normalised to sum
/// to 1; `None` without `JOINTS_0`. A second set (`JOINTS_1`) is ignored with a warning.
pub(super) fn read_influences(
    cx: &mut Cx,
    context: &str,
    primitive: &Primitive,
    buffers: &[Vec<u8>],
    vertex_count: usize,
) -> Result<Option<Vec<JointWeights>>, GltfError> {
    let joints = primitive.get(&::gltf::Semantic::Joints(0));
    let weights = primitive.get(&::gltf::Semantic::Weights(0));
    let (joints, weights) = match (joints, weights) {
        (None, None) => return Ok(None),
        (Some(j), Some(w)) => (j, w),
        (Some(_), None) => return Err(cx.data(context, "JOINTS_0 without WEIGHTS_0")),
        (None, Some(_)) => return Err(cx.data(context, "WEIGHTS_0 without JOINTS_0")),
    };
    if primitive.get(&::gltf::Semantic::Joints(1)).is_some() {
        cx.warn(format!(
            "{context}: JOINTS_1 and WEIGHTS_1 ignored (up to 4 joints per vertex)"
        ));
    }
    for (semantic, acc, expect) in [
        ("JOINTS_0", &joints, Expect::Joints),
        ("WEIGHTS_0", &weights, Expect::Weights),
    ] {
        accessor::check(cx, context, semantic, acc, expect)?;
        if acc.count() != vertex_count {
            return Err(cx.data(
                context,
                format!(
                    "{semantic} (accessor {}) has {} elements, POSITION has {vertex_count}",
                    acc.index(),
                    acc.count()
                ),
            ));
        }
    }
    let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let unreadable = |semantic: &str| cx.data(context, format!("{semantic} could not be read"));
    let joints: Vec<[u16; 4]> = reader
        .read_joints(0)
        .ok_or_else(|| unreadable("JOINTS_0"))?
        .into_u16()
        .collect();
    let weights: Vec<[f32; 4]> = reader
        .read_weights(0)
        .ok_or_else(|| unreadable("WEIGHTS_0"))?
        .into_f32()
        .collect();
    if joints.len() != vertex_count || weights.len() != vertex_count {
        return Err(unreadable("JOINTS_0 or WEIGHTS_0"));
    }
    let mut out = Vec::with_capacity(vertex_count);
    for (v, (j, w)) in joints.into_iter().zip(weights).enumerate() {
        let Some(influence) = JointWeights::normalized(j, w) else {
            return Err(cx.data(
                context,
                format!("WEIGHTS_0 of vertex {v} sum to 0 ({w:?}): the vertex follows no joint"),
            ));
        };
        out.push(influence);
    }
    Ok(Some(out))
}

/// Checks that every joint index of `mesh`'s skinned primitives names one of `skin`'s joints
/// (`node`: the node that pairs them, for the message).
pub(super) fn check_joint_indices(
    cx: &Cx,
    node: usize,
    mesh_index: usize,
    mesh: &GltfMesh,
    skin_index: usize,
    skin: &GltfSkin,
) -> Result<(), GltfError> {
    for (p, primitive) in mesh.primitives.iter().enumerate() {
        let Some(influences) = &primitive.influences else {
            continue;
        };
        for (v, influence) in influences.iter().enumerate() {
            if let Some((j, _)) = influence.influences().find(|&(j, _)| j >= skin.joints.len()) {
                return Err(cx.data(
                    format!("node {node}"),
                    format!(
                        "mesh {mesh_index} primitive {p}: JOINTS_0 of vertex {v} names joint {j}, but skin {skin_index} has {} joints",
                        skin.joints.len()
                    ),
                ));
            }
        }
    }
    Ok(())
}
