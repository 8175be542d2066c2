//! Multi-draw: a pass's consecutive batches that bind nothing between them (every batch of a
//! shadow view's depth-only pass, a camera pass's batches of one material) are recorded as one
//! `multi_draw_indexed_indirect` over arguments written while the frame is recorded and
//! uploaded before it is submitted — meshes of different sizes share the mesh buffers, so one
//! command draws them all. Without indirect first-instance support (or with it turned off), or
//! past the buffer's room, batches are drawn one `draw_indexed` each, as before.

use bytemuck::{Pod, Zeroable};

/// One indexed draw's arguments, as the GPU reads them.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct IndexedArgs {
    /// Indices drawn.
    pub index_count: u32,
    /// Instances drawn.
    pub instance_count: u32,
    /// First index in the index buffer.
    pub first_index: u32,
    /// Added to every index.
    pub base_vertex: i32,
    /// First instance (the shader's `instance_index` starts here).
    pub first_instance: u32,
}

/// Bytes of one [`IndexedArgs`].
const ARGS_BYTES: u64 = size_of::<IndexedArgs>() as u64;

/// The frame's multi-draw arguments and the buffer they are uploaded to.
#[derive(Default)]
pub struct DrawArgs {
    buffer: Option<wgpu::Buffer>,
    /// Arguments the buffer holds room for.
    capacity: usize,
    /// This frame's arguments, in recording order.
    args: Vec<IndexedArgs>,
    /// Draws pushed and not yet recorded.
    pending: Vec<IndexedArgs>,
    /// Draws recorded this frame (multi-drawn or drawn directly past the room), the room
    /// the next frame reserves at least.
    wanted: usize,
    /// Whether this frame draws with multi-draw.
    enabled: bool,
    /// Draws recorded this frame from arguments the GPU wrote (a culling phase's).
    gpu_written: usize,
}

impl DrawArgs {
    /// Starts a frame that records about `expected` draws, with multi-draw when `enabled`:
    /// grows the buffer to hold them (and what the last frame wanted) first.
    pub fn begin(&mut self, device: &wgpu::Device, expected: usize, enabled: bool) {
        self.args.clear();
        self.gpu_written = 0;
        self.enabled = enabled;
        let needed = expected.max(self.wanted);
        self.wanted = 0;
        if !enabled || needed <= self.capacity {
            return;
        }
        let capacity = needed.next_power_of_two().max(256);
        self.buffer = Some(device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("multi-draw arguments"),
            size: capacity as u64 * ARGS_BYTES,
            usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }));
        self.capacity = capacity;
    }

    /// Adds a draw to the run [`flush`](Self::flush) records next.
    pub fn push(&mut self, draw: IndexedArgs) {
        self.pending.push(draw);
    }

    /// Records the draws pushed since the last flush into `pass`: one multi-draw when they
    /// fit the buffer's room, else one `draw_indexed` each. Returns the commands recorded (0
    /// for none pushed).
    pub fn flush(&mut self, pass: &mut wgpu::RenderPass<'_>) -> u32 {
        let draws = &self.pending;
        if draws.is_empty() {
            return 0;
        }
        self.wanted += draws.len();
        let first = self.args.len();
        let calls = match &self.buffer {
            Some(buffer) if self.enabled && first + draws.len() <= self.capacity => {
                self.args.extend_from_slice(draws);
                pass.multi_draw_indexed_indirect(buffer, first as u64 * ARGS_BYTES, draws.len() as u32);
                1
            }
            _ => {
                for d in draws {
                    let indices = d.first_index..d.first_index + d.index_count;
                    let instances = d.first_instance..d.first_instance + d.instance_count;
                    pass.draw_indexed(indices, d.base_vertex, instances);
                }
                draws.len() as u32
            }
        };
        self.pending.clear();
        calls
    }

    /// Uploads the frame's arguments; call after recording, before submitting.
    pub fn upload(&self, queue: &wgpu::Queue) {
        if let (Some(buffer), false) = (&self.buffer, self.args.is_empty()) {
            queue.write_buffer(buffer, 0, bytemuck::cast_slice(&self.args));
        }
    }

    /// Counts `n` draws recorded from arguments the GPU wrote.
    pub fn count_gpu_written(&mut self, n: usize) {
        self.gpu_written += n;
    }

    /// Draws recorded this frame, in multi-draws or one by one (some of a culling phase's may
    /// draw no instance).
    pub fn draws(&self) -> usize {
        self.wanted + self.gpu_written
    }
}
