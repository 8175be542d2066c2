//! The node hierarchy of one scene, flattened into mesh instances with composed matrices.
//! glTF forbids cycles but nothing in the JSON schema does, so the walk guards against
//! them, against absurd depth and against exponential sharing of subtrees.

use ::gltf::{Document, Node};
use glam::Mat4;

use crate::gltf::load::Cx;
use crate::gltf::skin::check_joint_indices;
use crate::gltf::{GltfError, GltfMesh, GltfNodeInstance, GltfSkin};

/// The deepest hierarchy accepted (the walk recurses once per level).
const MAX_DEPTH: usize = 256;

/// The most node visits accepted: a node listed as the child of several parents is visited
/// once per path from the scene root, which a small file can make exponential (a chain of
/// nodes each listing the next one twice). With this cap the walk stays linear in the size
/// of the document plus a constant.
pub const MAX_NODE_VISITS: usize = 1 << 18;

/// The most mesh primitives one model may draw (each node with a mesh draws all of its
/// primitives, once per path from the scene root): each becomes an instance to spawn, cull
/// and upload, per copy of the model in a scene.
pub const MAX_DRAWN_PRIMITIVES: usize = 1 << 16;

/// The nodes drawn: the file's `scene`, else scene 0, else every node that is no node's
/// child, in index order.
fn scene_roots(document: &Document) -> Vec<usize> {
    if let Some(scene) = document.default_scene().or_else(|| document.scenes().next()) {
        return scene.nodes().map(|n| n.index()).collect();
    }
    let mut is_child = vec![false; document.nodes().len()];
    for node in document.nodes() {
        for child in node.children() {
            is_child[child.index()] = true;
        }
    }
    (0..is_child.len()).filter(|&i| !is_child[i]).collect()
}

/// Every node with a mesh in the drawn scene, depth first, with its matrix composed
/// through its ancestors; a node that pairs a mesh with a skin has its joint indices checked
/// against the skin.
pub(super) fn flatten(
    cx: &mut Cx,
    document: &Document,
    meshes: &[GltfMesh],
    skins: &[GltfSkin],
) -> Result<Vec<GltfNodeInstance>, GltfError> {
    let nodes: Vec<Node> = document.nodes().collect();
    let mut walk = Walk {
        nodes: &nodes,
        meshes,
        skins,
        on_path: vec![false; nodes.len()],
        path: Vec::new(),
        visits: 0,
        drawn: 0,
        out: Vec::new(),
    };
    for root in scene_roots(document) {
        walk.visit(cx, root, Mat4::IDENTITY)?;
    }
    Ok(walk.out)
}

struct Walk<'n, 'd> {
    nodes: &'n [Node<'d>],
    meshes: &'n [GltfMesh],
    skins: &'n [GltfSkin],
    /// Whether each node is on the current path from the root.
    on_path: Vec<bool>,
    /// The current path from the root.
    path: Vec<usize>,
    visits: usize,
    /// Mesh primitives drawn by the nodes flattened so far.
    drawn: usize,
    out: Vec<GltfNodeInstance>,
}

impl Walk<'_, '_> {
    fn visit(&mut self, cx: &Cx, index: usize, parent: Mat4) -> Result<(), GltfError> {
        if self.on_path[index] {
            let chain: Vec<String> = self.path.iter().chain([&index]).map(|i| format!("node {i}")).collect();
            return Err(GltfError::NodeCycle {
                path: cx.path.to_path_buf(),
                node: index,
                chain: chain.join(" → "),
            });
        }
        if self.path.len() >= MAX_DEPTH {
            return Err(cx.data(
                format!("node {index}"),
                format!("the node hierarchy is deeper than {MAX_DEPTH} levels"),
            ));
        }
        self.visits += 1;
        if self.visits > MAX_NODE_VISITS {
            return Err(cx.data(
                format!("node {index}"),
                format!(
                    "more than {MAX_NODE_VISITS} node visits (a node listed as the child of several parents \
                     is visited once per path from the scene root)"
                ),
            ));
        }
        let node = &self.nodes[index];
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        if !local.is_finite() {
            return Err(cx.data(format!("node {index}"), "transform is not finite"));
        }
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            self.drawn = self.drawn.saturating_add(mesh.primitives().len());
            if self.drawn > MAX_DRAWN_PRIMITIVES {
                return Err(cx.data(
                    format!("node {index}"),
                    format!(
                        "the scene draws more than {MAX_DRAWN_PRIMITIVES} mesh primitives (a node is drawn once \
                         per path from the scene root)"
                    ),
                ));
            }
            let skin = node.skin().map(|s| s.index());
            if let (Some(s), Some(m)) = (skin, self.meshes.get(mesh.index())) {
                check_joint_indices(cx, index, mesh.index(), m, s, &self.skins[s])?;
            }
            self.out.push(GltfNodeInstance {
                mesh: mesh.index(),
                model_from_mesh: world,
                name: node.name().map(str::to_owned),
                node: index,
                skin,
            });
        }
        self.on_path[index] = true;
        self.path.push(index);
        for child in node.children() {
            self.visit(cx, child.index(), world)?;
        }
        self.path.pop();
        self.on_path[index] = false;
        Ok(())
    }
}
