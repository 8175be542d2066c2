//! Every node's parent and rest transform (what skins and animations move), and the
//! animations: translation, rotation and scale channels with step, linear or cubic-spline
//! samplers, their key times checked finite and strictly increasing. Morph-target weights
//! are skipped with a warning.

use ::gltf::Document;
use ::gltf::animation::util::ReadOutputs;
use ::gltf::animation::{Interpolation as GltfInterpolation, Property};
use glam::{Quat, Vec3};

use crate::gltf::accessor::{self, Expect};
use crate::gltf::load::Cx;
use crate::gltf::{GltfAnimation, GltfChannel, GltfError, GltfNode, NodeProperty};
use crate::math::animation::{Interpolation, Track, unit_rotation};

/// Every node of the document, in index order, with its parent and rest transform.
pub(super) fn read_hierarchy(cx: &Cx, document: &Document) -> Result<Vec<GltfNode>, GltfError> {
    let mut nodes: Vec<GltfNode> = document
        .nodes()
        .map(|n| {
            let (translation, rotation, scale) = n.transform().decomposed();
            GltfNode {
                name: n.name().map(str::to_owned),
                parent: None,
                translation: Vec3::from(translation),
                rotation: Quat::from_array(rotation),
                scale: Vec3::from(scale),
            }
        })
        .collect();
    for node in document.nodes() {
        for child in node.children() {
            // NOTE: the node walk rejects cycles and shared subtrees are drawn once per path; a
            // node with several parents keeps its last one here.
            nodes[child.index()].parent = Some(node.index());
        }
    }
    for (i, n) in nodes.iter_mut().enumerate() {
        if !(n.translation.is_finite() && n.rotation.is_finite() && n.scale.is_finite()) {
            return Err(cx.data(format!("node {i}"), "transform is not finite"));
        }
        n.rotation = unit_rotation(n.rotation);
    }
    Ok(nodes)
}

/// Reads every animation's node channels.
pub(super) fn read_animations(
    cx: &mut Cx,
    document: &Document,
    buffers: &[Vec<u8>],
) -> Result<Vec<GltfAnimation>, GltfError> {
    let mut animations = Vec::new();
    for animation in document.animations() {
        let mut channels = Vec::new();
        for channel in animation.channels() {
            let context = format!("animation {} channel {}", animation.index(), channel.index());
            let sampler = channel.sampler();
            let interpolation = match sampler.interpolation() {
                GltfInterpolation::Step => Interpolation::Step,
                GltfInterpolation::Linear => Interpolation::Linear,
                GltfInterpolation::CubicSpline => Interpolation::CubicSpline,
            };
            let property = channel.target().property();
            let expect = match property {
                Property::MorphTargetWeights => {
                    cx.warn(format!("{context}: morph target weights ignored"));
                    continue;
                }
                Property::Rotation => Expect::Rotation,
                Property::Translation | Property::Scale => Expect::Vec3F32,
            };
            let (input, output) = (sampler.input(), sampler.output());
            accessor::check(cx, &context, "sampler input", &input, Expect::ScalarF32)?;
            accessor::check(cx, &context, "sampler output", &output, expect)?;
            let per_key = if interpolation == Interpolation::CubicSpline {
                3
            } else {
                1
            };
            if output.count() != input.count() * per_key {
                return Err(cx.data(
                    &context,
                    format!(
                        "{} output values for {} key times; {interpolation:?} needs {per_key} per key",
                        output.count(),
                        input.count()
                    ),
                ));
            }
            let reader = channel.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let unreadable = |what: &str| cx.data(&context, format!("sampler {what} could not be read"));
            let times: Vec<f32> = reader.read_inputs().ok_or_else(|| unreadable("input"))?.collect();
            if let Some(k) = times.iter().position(|t| !t.is_finite()) {
                return Err(cx.data(&context, format!("key time {k} is not finite")));
            }
            if let Some(k) = times.windows(2).position(|w| w[1] <= w[0]) {
                return Err(cx.data(
                    &context,
                    format!(
                        "key times must increase: key {} at {} s follows {} s",
                        k + 1,
                        times[k + 1],
                        times[k]
                    ),
                ));
            }
            let node = channel.target().node().index();
            let outputs = reader.read_outputs().ok_or_else(|| unreadable("output"))?;
            let vec3 = |values: Vec<[f32; 3]>| -> Result<Track<Vec3>, GltfError> {
                let values: Vec<Vec3> = values.into_iter().map(Vec3::from).collect();
                if values.iter().any(|v| !v.is_finite()) || values.len() != output.count() {
                    return Err(cx.data(&context, "output values are not finite"));
                }
                Ok(Track {
                    times: times.clone(),
                    values,
                    interpolation,
                })
            };
            let property = match outputs {
                ReadOutputs::Translations(v) => NodeProperty::Translation(vec3(v.collect())?),
                ReadOutputs::Scales(v) => NodeProperty::Scale(vec3(v.collect())?),
                ReadOutputs::Rotations(r) => {
                    let values: Vec<Quat> = r.into_f32().map(Quat::from_array).collect();
                    if values.iter().any(|q| !q.is_finite()) || values.len() != output.count() {
                        return Err(cx.data(&context, "output values are not finite"));
                    }
                    NodeProperty::Rotation(Track {
                        times: times.clone(),
                        values,
                        interpolation,
                    })
                }
                ReadOutputs::MorphTargetWeights(_) => continue,
            };
            channels.push(GltfChannel { node, property });
        }
        animations.push(GltfAnimation {
            name: animation.name().map(str::to_owned),
            channels,
        });
    }
    Ok(animations)
}
