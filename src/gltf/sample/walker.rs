//! The skinned sample model: a blocky walker 1.74 m tall, written to `assets/models/` beside
//! the fern by `cargo run --example make_sample_gltf`.
//!
//! One skin of four joints (`hips`, and under it `torso`, `leg_l`, `leg_r`) moves two
//! primitives (body and head); where a leg or the torso meets the hips its vertices are
//! shared half and half between the two joints. One animation, `walk`, uses every
//! interpolation the loader reads: the hips walk [`WALK_SPEED`] metres a second along +Z for
//! [`WALK_DURATION`] seconds, bobbing (a cubic spline whose tangents keep the forward motion
//! exact), the legs swing ±25° a stride (linear), and the torso turns ±5° every half stride
//! (step). Computed from constants, so [`build_walker`] returns the same bytes every time.

use ::gltf::json;
use ::gltf::json::Index;
use ::gltf::json::accessor::Type;
use ::gltf::json::animation::{Interpolation, Property};
use ::gltf::json::validation::{Checked, USize64};
use glam::{DQuat, Vec3};

use crate::gltf::sample::Geometry;
use crate::gltf::sample::builder::{Builder, Node};

/// File name of the walker's glTF JSON.
pub const WALKER_GLTF: &str = "walker.gltf";
/// File name of the walker's binary buffer.
pub const WALKER_BIN: &str = "walker.bin";
/// Seconds the walk lasts before it starts again.
pub const WALK_DURATION: f32 = 8.0;
/// Metres a second the hips move along +Z.
pub const WALK_SPEED: f32 = 1.0;
/// Seconds of one stride cycle (left leg forward, back, forward again).
pub const STRIDE: f32 = 1.0;
/// Height of the hips joint at rest.
pub const HIPS_HEIGHT: f32 = 0.9;

/// The two files of the walker, ready to write side by side.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WalkerFiles {
    /// Contents of [`WALKER_GLTF`].
    pub gltf: String,
    /// Contents of [`WALKER_BIN`].
    pub bin: Vec<u8>,
}

/// Joint indices in the skin.
const HIPS: u8 = 0;
const TORSO: u8 = 1;
const LEG_L: u8 = 2;
const LEG_R: u8 = 3;

/// Where each joint sits at rest, model space.
const JOINT_POSITIONS: [Vec3; 4] = [
    Vec3::new(0.0, HIPS_HEIGHT, 0.0),
    Vec3::new(0.0, HIPS_HEIGHT + 0.05, 0.0),
    Vec3::new(-0.1, HIPS_HEIGHT, 0.0),
    Vec3::new(0.1, HIPS_HEIGHT, 0.0),
];

/// A box's geometry with each vertex's joints and weights, chosen by its height.
#[derive(Default)]
struct Skinned {
    geometry: Geometry,
    joints: Vec<[u8; 4]>,
    weights: Vec<[f32; 4]>,
}

impl Skinned {
    /// Adds a box from `min` to `max`; `bind(y)` gives a vertex at height `y` its joints and
    /// weights.
    fn cuboid(&mut self, min: Vec3, max: Vec3, bind: impl Fn(f32) -> ([u8; 4], [f32; 4])) {
        let g = &mut self.geometry;
        let before = g.positions.len();
        let c = |x: bool, y: bool, z: bool| {
            Vec3::new(
                if x { max.x } else { min.x },
                if y { max.y } else { min.y },
                if z { max.z } else { min.z },
            )
        };
        let (f, t) = (false, true);
        g.quad([c(t, f, t), c(t, f, f), c(t, t, f), c(t, t, t)], Vec3::X);
        g.quad([c(f, f, f), c(f, f, t), c(f, t, t), c(f, t, f)], Vec3::NEG_X);
        g.quad([c(f, t, t), c(t, t, t), c(t, t, f), c(f, t, f)], Vec3::Y);
        g.quad([c(f, f, f), c(t, f, f), c(t, f, t), c(f, f, t)], Vec3::NEG_Y);
        g.quad([c(f, f, t), c(t, f, t), c(t, t, t), c(f, t, t)], Vec3::Z);
        g.quad([c(t, f, f), c(f, f, f), c(f, t, f), c(t, t, f)], Vec3::NEG_Z);
        for p in &g.positions[before..] {
            let (j, w) = bind(p.y);
            self.joints.push(j);
            self.weights.push(w);
        }
    }
}

/// A vertex at the hips' height is shared half and half with the hips; the others follow
/// `joint` alone.
fn follows(joint: u8) -> impl Fn(f32) -> ([u8; 4], [f32; 4]) {
    move |y| {
        if (y - HIPS_HEIGHT).abs() < 1e-6 {
            ([joint, HIPS, 0, 0], [0.5, 0.5, 0.0, 0.0])
        } else {
            ([joint, 0, 0, 0], [1.0, 0.0, 0.0, 0.0])
        }
    }
}

/// Builds the walker's files.
pub fn build_walker() -> WalkerFiles {
    let mut b = Builder::default();
    let cloth = b.material("cloth", [0.15, 0.3, 0.65, 1.0], None);
    let skin_material = b.material("face", [0.85, 0.62, 0.48, 1.0], None);

    let mut body = Skinned::default();
    for (leg, x) in [(LEG_L, -0.1), (LEG_R, 0.1)] {
        body.cuboid(
            Vec3::new(x - 0.06, 0.0, -0.07),
            Vec3::new(x + 0.06, HIPS_HEIGHT, 0.07),
            follows(leg),
        );
    }
    body.cuboid(
        Vec3::new(-0.18, HIPS_HEIGHT, -0.1),
        Vec3::new(0.18, 1.5, 0.1),
        follows(TORSO),
    );
    let mut head = Skinned::default();
    head.cuboid(Vec3::new(-0.1, 1.52, -0.1), Vec3::new(0.1, 1.74, 0.1), follows(TORSO));
    let primitives = [(&body, cloth), (&head, skin_material)]
        .map(|(s, m)| b.skinned_primitive(&s.geometry, &s.joints, &s.weights, m))
        .to_vec();
    let mesh = b.mesh("walker", primitives);

    // Joints: hips at the root, torso and legs under it (local translations from the hips).
    let root = b.node(Node::new("walker"));
    let hips = b.child(root, Node::new("hips").translation(JOINT_POSITIONS[0].to_array()));
    let local = |j: usize| (JOINT_POSITIONS[j] - JOINT_POSITIONS[0]).to_array();
    let joints = [
        hips,
        b.child(hips, Node::new("torso").translation(local(1))),
        b.child(hips, Node::new("leg_l").translation(local(2))),
        b.child(hips, Node::new("leg_r").translation(local(3))),
    ];
    let body_node = b.child(root, Node::new("body").mesh(mesh));
    let inverse_bind: Vec<f32> = JOINT_POSITIONS
        .iter()
        .flat_map(|p| glam::Mat4::from_translation(-*p).to_cols_array())
        .collect();
    let inverse_bind = b.floats(&inverse_bind, Type::Mat4, 16, false);
    let skin = b.root.push(json::Skin {
        extensions: None,
        extras: Default::default(),
        inverse_bind_matrices: Some(inverse_bind),
        joints: joints.to_vec(),
        name: Some("walker".into()),
        skeleton: Some(hips),
    });
    b.root.nodes[body_node.value()].skin = Some(skin);

    let animation = walk(&mut b, joints);
    b.root.animations.push(animation);
    let scene = b.root.push(json::Scene {
        extensions: None,
        extras: Default::default(),
        name: Some("walker".into()),
        nodes: vec![root],
    });
    b.root.scene = Some(scene);
    b.root.asset.generator = Some("penumbra::gltf::sample::walker".into());
    b.root.buffers.push(json::Buffer {
        byte_length: USize64::from(b.bin.len()),
        name: Some("walker".into()),
        uri: Some(WALKER_BIN.into()),
        extensions: None,
        extras: Default::default(),
    });
    let mut gltf = json::serialize::to_string_pretty(&b.root).expect("the walker's JSON serializes");
    gltf.push('\n');
    WalkerFiles { gltf, bin: b.bin }
}

/// The `walk` animation of the four joints.
fn walk(b: &mut Builder, [hips, torso, leg_l, leg_r]: [Index<json::Node>; 4]) -> json::Animation {
    let quarter = STRIDE / 4.0;
    let keys = (WALK_DURATION / quarter) as usize + 1;
    let times: Vec<f32> = (0..keys).map(|k| k as f32 * quarter).collect();
    let input = b.floats(&times, Type::Scalar, 1, true);
    // Hips: a cubic spline through a bob of 3 cm each half stride, tangents (0, 0, speed).
    let mut hips_keys = Vec::new();
    for &t in &times {
        let up = if (t / quarter) as usize % 2 == 1 { 0.03 } else { 0.0 };
        let tangent = [0.0, 0.0, WALK_SPEED];
        hips_keys.extend(tangent);
        hips_keys.extend([0.0, HIPS_HEIGHT + up, t * WALK_SPEED]);
        hips_keys.extend(tangent);
    }
    // Legs: ±25° about X, opposite in phase; linear (spherical) between quarter strides.
    let swing = |k: usize, sign: f64| {
        let phase = [0.0, 1.0, 0.0, -1.0][k % 4];
        let q = DQuat::from_rotation_x(sign * phase * 25f64.to_radians()).as_quat();
        q.to_array()
    };
    let leg_keys = |sign: f64| (0..keys).flat_map(|k| swing(k, sign)).collect::<Vec<f32>>();
    // Torso: ±5° about Y, stepping every half stride.
    let turn_keys: Vec<f32> = (0..keys)
        .flat_map(|k| {
            let sign = if (k / 2) % 2 == 0 { 1.0 } else { -1.0 };
            DQuat::from_rotation_y(sign * 5f64.to_radians()).as_quat().to_array()
        })
        .collect();
    let tracks = [
        (
            hips,
            Property::Translation,
            Interpolation::CubicSpline,
            hips_keys,
            Type::Vec3,
            3,
        ),
        (
            leg_l,
            Property::Rotation,
            Interpolation::Linear,
            leg_keys(1.0),
            Type::Vec4,
            4,
        ),
        (
            leg_r,
            Property::Rotation,
            Interpolation::Linear,
            leg_keys(-1.0),
            Type::Vec4,
            4,
        ),
        (torso, Property::Rotation, Interpolation::Step, turn_keys, Type::Vec4, 4),
    ];
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    for (k, (node, path, interpolation, values, type_, per)) in tracks.into_iter().enumerate() {
        let output = b.floats(&values, type_, per, false);
        samplers.push(json::animation::Sampler {
            extensions: None,
            extras: Default::default(),
            input,
            interpolation: Checked::Valid(interpolation),
            output,
        });
        channels.push(json::animation::Channel {
            sampler: Index::new(k as u32),
            target: json::animation::Target {
                extensions: None,
                extras: Default::default(),
                node,
                path: Checked::Valid(path),
            },
            extensions: None,
            extras: Default::default(),
        });
    }
    json::Animation {
        extensions: None,
        extras: Default::default(),
        channels,
        name: Some("walk".into()),
        samplers,
    }
}

#[cfg(test)]
mod tests {
    use super::build_walker;

    #[test]
    fn the_walker_is_built_the_same_every_time() {
        assert_eq!(build_walker(), build_walker());
    }

    #[test]
    fn the_walker_json_names_its_skin_and_animation() {
        let files = build_walker();
        for part in [
            "\"skins\"",
            "\"inverseBindMatrices\"",
            "\"JOINTS_0\"",
            "\"WEIGHTS_0\"",
            "\"CUBICSPLINE\"",
            "\"STEP\"",
            "\"walk\"",
        ] {
            assert!(files.gltf.contains(part), "{part} missing");
        }
        let _: ::gltf::json::Root = ::gltf::json::deserialize::from_str(&files.gltf).expect("the walker's JSON parses");
    }
}
