//! The render graph, built every frame. Nodes stay from frame to frame; each frame, each node
//! declares through typed handles ([`TextureId`], [`BufferId`]) what it reads, writes and
//! creates: imported resources (the target, the shadow storages) and transient ones (the
//! camera's depth buffer) that the graph allocates from a pool. The graph then orders the
//! nodes (each after the writers of what it reads), culls those whose output nothing kept
//! reads, lets transients with disjoint lifetimes share memory, and records the rest.
//!
//! Declarations: [`declare`]; scheduling without a GPU: [`schedule`]; the pool and the
//! handle table: [`pool`].

pub mod declare;
pub mod pool;
pub mod schedule;

pub use declare::{BufferDesc, BufferId, PassBuilder, ResourceHandle, TextureDesc, TextureId};
pub use pool::GraphResources;

use std::any::Any;
use std::sync::Arc;

use thiserror::Error;

use crate::layout::ShadowStorage;
use crate::render::frame::FrameContext;
use crate::render::frame_inputs::FrameInputs;
use crate::render::graph::declare::Declarations;
use crate::render::graph::pool::{Physical, TransientPool};
use crate::render::graph::schedule::Schedule;

/// A pass in the graph.
pub trait RenderNode: Send + Sync {
    /// Unique node name.
    fn name(&self) -> &'static str;
    /// Declares this frame's reads, writes and transient resources; keeps the handles it
    /// records with. `frame` holds the frame's shared handles (a node may fill one in, as the
    /// first to need the camera depth creates it); `inputs` is the ECS data of the frame.
    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, inputs: &FrameInputs<'_>);
    /// Records the node's GPU work, resolving its handles through `resources`.
    fn record(&mut self, ctx: &mut FrameContext<'_>, resources: &GraphResources, encoder: &mut wgpu::CommandEncoder);
    /// The frame was not drawn: a node that keeps what earlier frames drew, and draws only
    /// what changed, forgets it (this frame's changes were never drawn).
    fn skipped(&mut self) {}
}

/// A graph that cannot run (a bug in a node's declarations, not in user data).
#[derive(Clone, Debug, Error, PartialEq, Eq)]
#[non_exhaustive]
pub enum GraphError {
    /// Nodes read each other's outputs in a loop.
    #[error("render graph has a cycle through node `{0}`")]
    Cycle(&'static str),
    /// A node used a handle from another frame's graph.
    #[error("node `{node}` used a resource handle from an earlier frame; declare it again in `setup`")]
    StaleHandle {
        /// The node.
        node: &'static str,
    },
}

/// The handles every frame has, shared by the nodes.
#[derive(Clone, Copy, Debug)]
pub struct FrameResources {
    /// The colour target (imported).
    pub color: TextureId,
    /// The colour target's storage view (imported), where compute passes can write it
    /// ([`TargetViews::storage`](crate::render::target::TargetViews)).
    pub color_storage: Option<TextureId>,
    /// Its format.
    pub color_format: wgpu::TextureFormat,
    /// The target's size in pixels.
    pub size: (u32, u32),
    /// Samples per pixel of the camera's colour and depth (1 without MSAA; decided once per
    /// frame by the renderer from [`RenderOptions::msaa`](crate::render::RenderOptions) and
    /// what the adapter supports). With more than one, the lighting pass draws into a
    /// multisampled transient and resolves it into `color`.
    pub samples: u32,
    /// The analysis targets, when the frame is scored (imported).
    pub analysis: Option<[TextureId; 3]>,
    /// Each shadow storage's depth array, at [`ShadowStorage::index`] (imported: they persist
    /// between frames).
    pub shadow_maps: [TextureId; ShadowStorage::COUNT],
    /// Each shadow storage's moments, at [`ShadowStorage::index`] (imported).
    pub shadow_moments: [TextureId; ShadowStorage::COUNT],
    /// The frame writes the camera depth in a prepass (decided once per frame by the
    /// renderer from [`RenderOptions::depth_prepass`](crate::render::RenderOptions)).
    pub depth_prepass: bool,
    /// The camera's depth buffer: a transient created by the first node that needs it.
    pub depth: Option<TextureId>,
    /// The camera's normals (and receiver flags), written by the prepass when the frame
    /// resolves visibility.
    pub normals: Option<TextureId>,
    /// The resolved visibility (imported), when the frame resolves it.
    pub visibility: Option<TextureId>,
    /// The frame lights the prepass's pixels of untextured materials in a full-screen pass
    /// (decided once per frame by the renderer from
    /// [`RenderOptions::deferred_lighting`](crate::render::RenderOptions) and what the frame
    /// has: a prepass with normals, one sample, no analysis, the shipped forward shader).
    pub deferred_lighting: bool,
    /// The instance seen at each pixel where it is lit from the prepass (or
    /// [`SHADING_ID_NONE`](crate::shader::contract::SHADING_ID_NONE)), written by the prepass
    /// when the frame lights it so.
    pub shading_ids: Option<TextureId>,
    /// The prepass's depth, normals and shading ids (imported: the renderer keeps them) already
    /// hold what this frame's prepass would draw ([`crate::render::prepass_keep`]): it draws
    /// nothing.
    pub prepass_kept: bool,
}

impl FrameResources {
    /// The depth array of `storage`.
    pub fn maps(&self, storage: ShadowStorage) -> TextureId {
        self.shadow_maps[storage.index()]
    }

    /// The moments of `storage`.
    pub fn moments(&self, storage: ShadowStorage) -> TextureId {
        self.shadow_moments[storage.index()]
    }

    /// Every storage's depth array and moments: what a pass that samples shadows reads.
    pub fn shadow_textures(&self) -> impl Iterator<Item = TextureId> + use<> {
        self.shadow_maps.into_iter().chain(self.shadow_moments)
    }
}

/// The nodes, the pool of transients, and the last frame's schedule.
#[derive(Default)]
pub struct RenderGraph {
    nodes: Vec<Box<dyn RenderNode>>,
    names: Vec<&'static str>,
    decls: Declarations,
    schedule: Schedule,
    pool: TransientPool,
    resources: GraphResources,
}

impl RenderGraph {
    /// Adds a node; it declares its work from the next frame on.
    pub fn add_node(&mut self, node: Box<dyn RenderNode>) {
        self.names.push(node.name());
        self.nodes.push(node);
    }

    /// Starts a frame's build: handles of the last frame become stale.
    pub fn begin_frame(&mut self) {
        self.decls.begin(self.nodes.len());
        self.resources.clear();
    }

    /// Imports a texture that lives outside the graph (its view), for this frame.
    pub fn import_texture(&mut self, label: &'static str, view: &wgpu::TextureView) -> TextureId {
        let handle = self.decls.add(label, None);
        self.resources.set(handle.index, Physical::View(view.clone()));
        TextureId(handle)
    }

    /// Imports `view` with the object that owns it (read back by the nodes with
    /// [`GraphResources::object`]), for this frame.
    pub fn import_object(
        &mut self,
        label: &'static str,
        view: wgpu::TextureView,
        object: Arc<dyn Any + Send + Sync>,
    ) -> TextureId {
        let handle = self.decls.add(label, None);
        self.resources.set(handle.index, Physical::Object(view, object));
        TextureId(handle)
    }

    /// Lets every node declare its work, schedules the frame and allocates its transients;
    /// returns how many transient resources had to be created.
    pub fn build(
        &mut self,
        device: &wgpu::Device,
        frame: &mut FrameResources,
        inputs: &FrameInputs<'_>,
    ) -> Result<u32, GraphError> {
        for (pass, node) in self.nodes.iter_mut().enumerate() {
            let mut builder = PassBuilder {
                decls: &mut self.decls,
                pass: pass as u32,
                node: self.names[pass],
            };
            node.setup(&mut builder, frame, inputs);
        }
        self.schedule.compute(&self.decls, &self.names)?;
        let created = self.pool.acquire(device, &self.schedule);
        self.resources.bind_transients(&self.pool, &self.schedule);
        Ok(created)
    }

    /// Names of the nodes the last build kept, in execution order.
    pub fn execution_order(&self) -> Vec<&'static str> {
        self.schedule.order.iter().map(|&p| self.names[p as usize]).collect()
    }

    /// Names of the nodes the last build culled.
    pub fn culled(&self) -> Vec<&'static str> {
        self.schedule.culled.iter().map(|&p| self.names[p as usize]).collect()
    }

    /// Tells every node the frame was not drawn ([`RenderNode::skipped`]).
    pub fn skip(&mut self) {
        for node in &mut self.nodes {
            node.skipped();
        }
    }

    /// Records the kept nodes, in order, into one encoder.
    pub fn execute(&mut self, ctx: &mut FrameContext<'_>, encoder: &mut wgpu::CommandEncoder) {
        for &pass in &self.schedule.order {
            self.nodes[pass as usize].record(ctx, &self.resources, encoder);
        }
    }
}
