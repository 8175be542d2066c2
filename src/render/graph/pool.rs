//! The GPU side of a frame's graph: the pool that keeps transient textures and buffers from
//! frame to frame (a frame that declares what the last one did creates nothing), and the
//! table that turns a handle into the texture view or buffer a node records with.

use std::any::Any;
use std::collections::HashMap;
use std::sync::Arc;

use crate::render::graph::declare::{BufferId, PoolKey, TextureId};
use crate::render::graph::schedule::Schedule;
use crate::render::target::texture_2d_multisampled;

/// Frames a pooled resource may go unused before it is freed (a resized window leaves its
/// old depth buffer behind).
const IDLE_FRAMES: u32 = 3;

/// A texture with its default view, or a buffer.
#[derive(Clone, Debug)]
pub enum Physical {
    /// A texture and the view of all its layers.
    Texture(wgpu::Texture, wgpu::TextureView),
    /// An imported texture view (the graph does not own the texture).
    View(wgpu::TextureView),
    /// An imported texture view with the object that owns it (a shadow storage with its
    /// layer views), for the nodes that render into its parts.
    Object(wgpu::TextureView, Arc<dyn Any + Send + Sync>),
    /// A buffer.
    Buffer(wgpu::Buffer),
}

/// Transient resources kept between frames, by key.
#[derive(Default)]
pub struct TransientPool {
    entries: HashMap<PoolKey, Vec<(Physical, u32)>>,
}

fn create(device: &wgpu::Device, key: PoolKey) -> Physical {
    match key {
        PoolKey::Texture {
            size: (width, height, layers),
            format,
            usage,
            samples,
        } => {
            let extent = (width, height, layers);
            let texture = texture_2d_multisampled(device, "graph transient", extent, format, usage, samples);
            let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
            Physical::Texture(texture, view)
        }
        PoolKey::Buffer { size, usage } => Physical::Buffer(device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("graph transient"),
            size,
            usage,
            mapped_at_creation: false,
        })),
    }
}

impl TransientPool {
    /// Makes sure every slot of `schedule` has a resource, creating those missing, and ages
    /// the rest; returns how many were created.
    pub fn acquire(&mut self, device: &wgpu::Device, schedule: &Schedule) -> u32 {
        let mut created = 0;
        for entries in self.entries.values_mut() {
            for entry in entries.iter_mut() {
                entry.1 += 1;
            }
        }
        for &(key, ordinal) in &schedule.slots {
            let entries = self.entries.entry(key).or_default();
            while entries.len() <= ordinal as usize {
                entries.push((create(device, key), 0));
                created += 1;
            }
            entries[ordinal as usize].1 = 0;
        }
        // NOTE: only trailing entries are freed so ordinals of the ones kept stay valid.
        for entries in self.entries.values_mut() {
            while entries.last().is_some_and(|e| e.1 > IDLE_FRAMES) {
                entries.pop();
            }
        }
        self.entries.retain(|_, e| !e.is_empty());
        created
    }

    /// The pooled resource of `slot` (after [`acquire`](Self::acquire)).
    fn get(&self, (key, ordinal): (PoolKey, u32)) -> Option<&Physical> {
        self.entries.get(&key)?.get(ordinal as usize).map(|e| &e.0)
    }
}

/// Every resource of the frame, by handle: what a node's `record` reads its handles from.
#[derive(Default)]
pub struct GraphResources {
    table: Vec<Option<Physical>>,
}

impl GraphResources {
    /// Starts a frame: forgets the last frame's resources.
    pub(crate) fn clear(&mut self) {
        self.table.clear();
    }

    /// Sets resource `index` (imports are set as they are declared).
    pub(crate) fn set(&mut self, index: u32, physical: Physical) {
        let index = index as usize;
        if self.table.len() <= index {
            self.table.resize(index + 1, None);
        }
        self.table[index] = Some(physical);
    }

    /// Fills the transients from the pool, as `schedule` placed them.
    pub(crate) fn bind_transients(&mut self, pool: &TransientPool, schedule: &Schedule) {
        for (index, slot) in schedule.slot_of.iter().enumerate() {
            let physical = slot.and_then(|s| pool.get(schedule.slots[s as usize]));
            if let Some(physical) = physical {
                self.set(index as u32, physical.clone());
            }
        }
    }

    /// The view of a texture of this frame. Panics when the handle was not declared by the
    /// node that uses it (a pass only sees what it declared, so this is a bug in the node).
    pub fn view(&self, texture: TextureId) -> &wgpu::TextureView {
        match self.table.get(texture.0.index as usize) {
            Some(Some(Physical::Texture(_, view) | Physical::View(view) | Physical::Object(view, _))) => view,
            _ => panic!("texture handle {texture:?} was not declared in this frame's graph"),
        }
    }

    /// The object imported with `texture` ([`RenderGraph::import_object`](crate::render::graph::RenderGraph::import_object)).
    /// Panics like [`view`](Self::view), or when it was imported as another type (a bug in
    /// the node).
    pub fn object<T: Any>(&self, texture: TextureId) -> &T {
        match self.table.get(texture.0.index as usize) {
            Some(Some(Physical::Object(_, object))) => match object.downcast_ref() {
                Some(object) => object,
                None => panic!("texture handle {texture:?} was imported with another type"),
            },
            _ => panic!("texture handle {texture:?} was not imported with an object in this frame's graph"),
        }
    }

    /// The object imported with `texture`, shared (for a node that keeps it while it records);
    /// panics like [`object`](Self::object).
    pub fn shared<T: Any + Send + Sync>(&self, texture: TextureId) -> Arc<T> {
        match self.table.get(texture.0.index as usize) {
            Some(Some(Physical::Object(_, object))) => match object.clone().downcast() {
                Ok(object) => object,
                Err(_) => panic!("texture handle {texture:?} was imported with another type"),
            },
            _ => panic!("texture handle {texture:?} was not imported with an object in this frame's graph"),
        }
    }

    /// The buffer of this frame behind `buffer`; panics like [`view`](Self::view).
    pub fn buffer(&self, buffer: BufferId) -> &wgpu::Buffer {
        match self.table.get(buffer.0.index as usize) {
            Some(Some(Physical::Buffer(b))) => b,
            _ => panic!("buffer handle {buffer:?} was not declared in this frame's graph"),
        }
    }
}
