//! What a frame's graph is built from: typed handles to textures and buffers, descriptions of
//! the transient ones, and each pass's reads and writes as its node declares them. Rebuilt
//! every frame; the vectors keep their capacity, so a steady frame allocates nothing here.

use crate::render::graph::GraphError;

/// A texture of one frame's graph: imported (owned outside the graph) or transient (created
/// by a node's declaration, allocated from the graph's pool). Valid for that frame only.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureId(pub(crate) Handle);

/// A buffer of one frame's graph; see [`TextureId`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BufferId(pub(crate) Handle);

/// Index of a resource plus the build it belongs to, so a handle kept from an earlier frame
/// is caught instead of naming some other resource.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Handle {
    pub(crate) index: u32,
    pub(crate) build: u32,
}

/// Either kind of handle, for [`PassBuilder::read`] and [`PassBuilder::write`].
pub trait ResourceHandle: Copy {
    /// The untyped handle.
    fn handle(self) -> Handle;
}

impl ResourceHandle for TextureId {
    fn handle(self) -> Handle {
        self.0
    }
}

impl ResourceHandle for BufferId {
    fn handle(self) -> Handle {
        self.0
    }
}

/// A transient texture: single mip, 2D (or a 2D array when `layers` > 1), with `samples`
/// samples per texel (1, or a multisampled attachment: then `layers` must be 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureDesc {
    /// Debug label.
    pub label: &'static str,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Array layers (1 for a plain 2D texture).
    pub layers: u32,
    /// Texel format.
    pub format: wgpu::TextureFormat,
    /// Usages.
    pub usage: wgpu::TextureUsages,
    /// Samples per texel (1 for a plain texture).
    pub samples: u32,
}

/// A transient buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BufferDesc {
    /// Debug label.
    pub label: &'static str,
    /// Size in bytes.
    pub size: u64,
    /// Usages.
    pub usage: wgpu::BufferUsages,
}

/// What makes two transient resources interchangeable in the pool: everything but the label.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PoolKey {
    /// A texture of this size, layer count, format, usage and sample count.
    Texture {
        /// Width, height, layers.
        size: (u32, u32, u32),
        /// Format.
        format: wgpu::TextureFormat,
        /// Usages.
        usage: wgpu::TextureUsages,
        /// Samples per texel.
        samples: u32,
    },
    /// A buffer of this size and usage.
    Buffer {
        /// Size in bytes.
        size: u64,
        /// Usages.
        usage: wgpu::BufferUsages,
    },
}

impl From<&TextureDesc> for PoolKey {
    fn from(d: &TextureDesc) -> Self {
        Self::Texture {
            size: (d.width.max(1), d.height.max(1), d.layers.max(1)),
            format: d.format,
            usage: d.usage,
            samples: d.samples.max(1),
        }
    }
}

impl From<&BufferDesc> for PoolKey {
    fn from(d: &BufferDesc) -> Self {
        Self::Buffer {
            size: d.size.max(4),
            usage: d.usage,
        }
    }
}

/// One resource of the frame.
#[derive(Clone, Copy, Debug)]
pub struct ResourceDecl {
    /// Debug label (for errors).
    pub label: &'static str,
    /// None for an imported resource, else what the pool must provide.
    pub transient: Option<PoolKey>,
}

/// One read or write of a resource by a pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Access {
    /// Pass (the node's index in the graph).
    pub pass: u32,
    /// Resource index.
    pub resource: u32,
    /// A write (creating a transient counts as writing it).
    pub write: bool,
}

/// Everything declared for one frame.
#[derive(Debug, Default)]
pub struct Declarations {
    /// This build's number (handles carry it).
    pub build: u32,
    /// Resources, by handle index.
    pub resources: Vec<ResourceDecl>,
    /// Every access, in declaration order.
    pub accesses: Vec<Access>,
    /// Passes that must run even if nothing reads what they write.
    pub side_effects: Vec<bool>,
    /// The first misuse of a handle, reported when the graph is scheduled.
    pub error: Option<GraphError>,
}

impl Declarations {
    /// Starts a new build for `passes` passes: handles of earlier builds become stale.
    pub fn begin(&mut self, passes: usize) {
        self.build = self.build.wrapping_add(1);
        self.resources.clear();
        self.accesses.clear();
        self.side_effects.clear();
        self.side_effects.resize(passes, false);
        self.error = None;
    }

    /// Adds a resource and returns its handle.
    pub fn add(&mut self, label: &'static str, transient: Option<PoolKey>) -> Handle {
        self.resources.push(ResourceDecl { label, transient });
        Handle {
            index: (self.resources.len() - 1) as u32,
            build: self.build,
        }
    }

    /// The resource index of `handle`, or None (and the error noted) when it is stale.
    fn index(&mut self, handle: Handle, node: &'static str) -> Option<u32> {
        if handle.build == self.build && (handle.index as usize) < self.resources.len() {
            return Some(handle.index);
        }
        self.error.get_or_insert(GraphError::StaleHandle { node });
        None
    }
}

/// What one node declares for one frame: the resources it reads, writes and creates.
pub struct PassBuilder<'a> {
    pub(crate) decls: &'a mut Declarations,
    pub(crate) pass: u32,
    pub(crate) node: &'static str,
}

impl PassBuilder<'_> {
    /// Declares a read: this pass runs after every pass that writes `resource`.
    pub fn read<H: ResourceHandle>(&mut self, resource: H) -> H {
        self.access(resource.handle(), false);
        resource
    }

    /// Declares a write: passes that read `resource` run after this one, and this pass is
    /// kept if something kept reads it or `resource` is imported.
    pub fn write<H: ResourceHandle>(&mut self, resource: H) -> H {
        self.access(resource.handle(), true);
        resource
    }

    /// Declares a transient texture this pass writes first; the graph allocates it (or
    /// reuses a pooled one) for the passes that use it.
    pub fn create_texture(&mut self, desc: TextureDesc) -> TextureId {
        let handle = self.decls.add(desc.label, Some(PoolKey::from(&desc)));
        self.access(handle, true);
        TextureId(handle)
    }

    /// Declares a transient buffer this pass writes first; see
    /// [`create_texture`](Self::create_texture).
    pub fn create_buffer(&mut self, desc: BufferDesc) -> BufferId {
        let handle = self.decls.add(desc.label, Some(PoolKey::from(&desc)));
        self.access(handle, true);
        BufferId(handle)
    }

    /// Keeps this pass even when nothing reads what it writes (say, it reads data back).
    pub fn side_effect(&mut self) {
        self.decls.side_effects[self.pass as usize] = true;
    }

    fn access(&mut self, handle: Handle, write: bool) {
        if let Some(resource) = self.decls.index(handle, self.node) {
            self.decls.accesses.push(Access {
                pass: self.pass,
                resource,
                write,
            });
        }
    }
}
