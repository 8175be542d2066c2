//! Skins and animations from glTF: the shipped walker loads with its skin, weights and walk;
//! posed on the CPU its vertices follow its joints; and broken skins (joint index out of
//! range, a bind matrix that cannot be inverted, weights that sum to 0, 10 000 joints,
//! animation keys out of order) are errors that name the file and the problem.

use std::fs;
use std::path::{Path, PathBuf};

use glam::Vec3;
use gltf::json;
use penumbra::gltf::sample::SAMPLE_DIR;
use penumbra::gltf::sample::walker::{WALK_DURATION, WALK_SPEED, WALKER_BIN, WALKER_GLTF, build_walker};
use penumbra::gltf::{GltfModel, load};
use penumbra::math::skinning::{joint_bounds, skin_position, skinned_bounds};

/// A scratch folder holding a copy of the walker, edited.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("penumbra-skins-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).expect("scratch folder");
        Scratch(dir)
    }

    /// Writes the walker with `edit` applied to its JSON and `patch` to its buffer.
    fn write(&self, edit: impl FnOnce(&mut json::Root), patch: impl FnOnce(&json::Root, &mut Vec<u8>)) -> PathBuf {
        let files = build_walker();
        let mut root: json::Root = json::deserialize::from_str(&files.gltf).expect("walker JSON");
        let mut bin = files.bin;
        patch(&root, &mut bin);
        edit(&mut root);
        let path = self.0.join(WALKER_GLTF);
        fs::write(&path, json::serialize::to_string(&root).expect("serializes")).expect("write gltf");
        fs::write(self.0.join(WALKER_BIN), bin).expect("write bin");
        path
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

/// The byte offset in the buffer of `accessor`'s data.
fn data_offset(root: &json::Root, accessor: usize) -> usize {
    let a = &root.accessors[accessor];
    let view = &root.buffer_views[a.buffer_view.expect("stored").value()];
    view.byte_offset.map_or(0, |o| o.0 as usize) + a.byte_offset.map_or(0, |o| o.0 as usize)
}

/// Loading `path` fails with a message holding every part.
fn load_err(path: &Path, parts: &[&str]) {
    match load(path) {
        Ok(_) => panic!("{} loaded", path.display()),
        Err(e) => {
            let msg = e.to_string();
            assert!(
                msg.contains(&path.display().to_string()) || msg.contains(WALKER_GLTF),
                "{msg}"
            );
            for part in parts {
                assert!(msg.contains(part), "`{part}` not in: {msg}");
            }
        }
    }
}

fn walker() -> GltfModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(SAMPLE_DIR).join(WALKER_GLTF);
    load(&path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_shipped_walker_is_what_the_generator_writes() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(SAMPLE_DIR);
    let files = build_walker();
    let gltf = fs::read_to_string(dir.join(WALKER_GLTF)).expect("walker.gltf is shipped");
    let bin = fs::read(dir.join(WALKER_BIN)).expect("walker.bin is shipped");
    assert!(
        gltf == files.gltf && bin == files.bin,
        "assets/models/walker.* differ from the generator: run `cargo run --example make_sample_gltf`"
    );
}

#[test]
fn the_walker_loads_with_its_skin_weights_and_walk() {
    let model = walker();
    assert_eq!(model.skins.len(), 1);
    let skin = &model.skins[0];
    assert_eq!(skin.joints.len(), 4);
    let names: Vec<_> = skin
        .joints
        .iter()
        .map(|&j| model.hierarchy[j].name.as_deref().unwrap_or(""))
        .collect();
    assert_eq!(names, ["hips", "torso", "leg_l", "leg_r"]);
    let body = model
        .nodes
        .iter()
        .find(|n| n.name.as_deref() == Some("body"))
        .expect("a body node");
    assert_eq!(body.skin, Some(0));
    let mut vertices = 0;
    for p in &model.meshes[body.mesh].primitives {
        let influences = p.influences.as_ref().expect("skinned primitives");
        assert_eq!(influences.len(), p.mesh.vertices.len());
        vertices += influences.len();
        for i in influences {
            let sum: f32 = i.weights.iter().sum();
            assert!((sum - 1.0).abs() < 1e-6, "weights sum to {sum}");
        }
    }
    assert_eq!(vertices, 4 * 24, "four boxes of 24 vertices");
    assert_eq!(model.animations.len(), 1);
    assert_eq!(model.animations[0].channels.len(), 4);
    assert_eq!(model.animations[0].duration(), WALK_DURATION);
}

#[test]
fn posed_on_the_cpu_the_walker_follows_its_joints() {
    let model = walker();
    let body = model.nodes.iter().find(|n| n.skin.is_some()).expect("a skinned node");
    let primitive = &model.meshes[body.mesh].primitives[0];
    let influences = primitive.influences.as_ref().expect("skinned");
    let positions: Vec<Vec3> = primitive.mesh.vertices.iter().map(|v| Vec3::from(v.position)).collect();
    // The rest pose leaves every vertex where the file put it.
    let rest = model.skin_matrices(0, &model.model_from_nodes(&model.local_pose(None, 0.0)));
    for (p, i) in positions.iter().zip(influences) {
        assert!((skin_position(*p, i, &rest) - *p).length() < 1e-5);
    }
    let boxes = joint_bounds(&positions, influences, 4);
    for time in [0.0, 0.25, 0.6, 1.75, 3.3, WALK_DURATION] {
        let pose = model.skin_matrices(0, &model.model_from_nodes(&model.local_pose(Some(0), time)));
        let skinned: Vec<Vec3> = positions
            .iter()
            .zip(influences)
            .map(|(p, i)| skin_position(*p, i, &pose))
            .collect();
        // The hips walk forward: the body's centre follows them.
        let centre = skinned.iter().copied().sum::<Vec3>() / skinned.len() as f32;
        assert!((centre.z - time * WALK_SPEED).abs() < 0.2, "t {time}: centre {centre}");
        // The feet stay near the ground, the bounds hold every vertex.
        let lowest = skinned.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
        assert!((-0.05..0.1).contains(&lowest), "t {time}: lowest vertex at {lowest}");
        let bounds = skinned_bounds(&boxes, &pose);
        for p in &skinned {
            assert!(
                p.cmpge(bounds.min - 1e-4).all() && p.cmple(bounds.max + 1e-4).all(),
                "{p} outside"
            );
        }
    }
    // A quarter stride in, the left leg swings forward and the right one back.
    let pose = model.skin_matrices(0, &model.model_from_nodes(&model.local_pose(Some(0), 0.25)));
    let foot = |x: f32| {
        let k = positions
            .iter()
            .position(|p| p.y == 0.0 && (p.x - x).abs() < 0.07)
            .expect("a foot vertex");
        skin_position(positions[k], &influences[k], &pose) - Vec3::new(0.0, 0.0, 0.25 * WALK_SPEED)
    };
    let (left, right) = (foot(-0.1), foot(0.1));
    assert!(left.z < -0.2 && right.z > 0.2, "feet at {left} and {right}");
    // The hips' joint matrix carries the bind pose up by the 3 cm bob and forward.
    let hips = pose[0].w_axis;
    let expected = Vec3::new(0.0, 0.03, 0.25 * WALK_SPEED);
    assert!((hips.truncate() - expected).length() < 1e-5, "hips moved by {hips}");
    assert_eq!(pose[0].x_axis.truncate(), Vec3::X);
}

#[test]
fn a_joint_index_past_the_skin_is_an_error() {
    let scratch = Scratch::new("joint-range");
    let path = scratch.write(|root| root.skins[0].joints.truncate(2), |_, _| {});
    load_err(
        &path,
        &[
            "node ",
            "mesh 0 primitive 0: JOINTS_0 of vertex 0 names joint ",
            "but skin 0 has 2 joints",
        ],
    );
}

#[test]
fn a_bind_matrix_that_cannot_be_inverted_is_an_error() {
    let scratch = Scratch::new("bind");
    let path = scratch.write(
        |_| {},
        |root, bin| {
            let ibm = root.skins[0].inverse_bind_matrices.expect("stored").value();
            let at = data_offset(root, ibm) + 64;
            bin[at..at + 64].fill(0);
        },
    );
    load_err(
        &path,
        &["skin 0: the inverse bind matrix of joint 1 (node 2) is not invertible"],
    );
}

#[test]
fn weights_summing_to_zero_are_an_error() {
    let scratch = Scratch::new("weights");
    let path = scratch.write(
        |_| {},
        |root, bin| {
            let attributes = &root.meshes[0].primitives[0].attributes;
            let weights = attributes
                .iter()
                .find(|(k, _)| matches!(k, json::validation::Checked::Valid(json::mesh::Semantic::Weights(0))))
                .map(|(_, a)| a.value())
                .expect("WEIGHTS_0");
            let at = data_offset(root, weights) + 3 * 16;
            bin[at..at + 16].fill(0);
        },
    );
    load_err(&path, &["mesh 0 primitive 0: WEIGHTS_0 of vertex 3 sum to 0"]);
}

#[test]
fn ten_thousand_joints_are_an_error() {
    let scratch = Scratch::new("many-joints");
    let path = scratch.write(
        |root| {
            let joint = root.skins[0].joints[1];
            root.skins[0].joints = vec![joint; 10_000];
        },
        |_, _| {},
    );
    load_err(&path, &["skin 0: has 10000 joints; at most 256 per skin"]);
}

#[test]
fn animation_keys_out_of_order_are_an_error() {
    let scratch = Scratch::new("keys");
    let path = scratch.write(
        |_| {},
        |root, bin| {
            let input = root.animations[0].samplers[0].input.value();
            let at = data_offset(root, input) + 4;
            bin[at..at + 4].copy_from_slice(&(-1.0f32).to_le_bytes());
        },
    );
    load_err(
        &path,
        &["animation 0 channel 0: key times must increase: key 1 at -1 s follows 0 s"],
    );
}
