//! A storage buffer that grows with its contents: the instance list, draw-index lists, and
//! the frame's lights and shadow views. It doubles up to the device's storage-binding size
//! and refuses data larger than that before any wgpu call, so nothing is silently truncated.

use crate::render::context::GpuContext;
use crate::render::limits::LimitError;

/// A storage buffer that grows (by doubling, up to the device's storage-binding size) and
/// reports when it was replaced.
pub struct GrowBuffer {
    /// The current buffer (replaced when it grows).
    pub buffer: wgpu::Buffer,
    label: &'static str,
    usage: wgpu::BufferUsages,
    /// The generation of the data last written by [`write_generation`](Self::write_generation).
    generation: Option<u64>,
}

impl GrowBuffer {
    /// An empty storage buffer of at least `size` bytes.
    pub fn new(device: &wgpu::Device, label: &'static str, size: u64) -> Self {
        Self::with_usage(device, label, size, wgpu::BufferUsages::STORAGE)
    }

    /// An empty buffer of at least `size` bytes for `usage` (`STORAGE`, or `UNIFORM` for a
    /// buffer bound in fixed-size slices at dynamic offsets).
    pub fn with_usage(device: &wgpu::Device, label: &'static str, size: u64, usage: wgpu::BufferUsages) -> Self {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(256),
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            buffer,
            label,
            usage,
            generation: None,
        }
    }

    /// Writes `data` of `generation` unless the buffer already holds that generation (data
    /// whose producer bumps a counter whenever it changes); returns true when the buffer was
    /// replaced.
    pub fn write_generation(&mut self, gpu: &GpuContext, generation: u64, data: &[u8]) -> Result<bool, LimitError> {
        if self.generation == Some(generation) {
            return Ok(false);
        }
        let replaced = self.write(gpu, data)?;
        self.generation = Some(generation);
        Ok(replaced)
    }

    /// Grows the buffer to hold at least `bytes` (its contents are then undefined); returns
    /// true when it was replaced. Refused past one storage binding, as [`write`](Self::write).
    pub fn reserve(&mut self, gpu: &GpuContext, bytes: u64) -> Result<bool, LimitError> {
        let limits = &gpu.limits;
        let whole_binding = self.usage.contains(wgpu::BufferUsages::STORAGE);
        limits.check_buffer(self.label, bytes, whole_binding)?;
        if bytes <= self.buffer.size() {
            return Ok(false);
        }
        let most = if whole_binding {
            limits.max_storage_binding_bytes.min(limits.max_buffer_bytes)
        } else {
            limits.max_buffer_bytes
        };
        let size = bytes.next_power_of_two().min(most & !3).max(bytes);
        *self = Self::with_usage(&gpu.device, self.label, size, self.usage);
        Ok(true)
    }

    /// Writes `data`, growing first if needed; returns true when the buffer was replaced.
    /// Data larger than one storage binding is refused before any wgpu call.
    pub fn write(&mut self, gpu: &GpuContext, data: &[u8]) -> Result<bool, LimitError> {
        // NOTE: a storage buffer is bound whole; a uniform one only in slices; storage
        // bindings are sized in multiples of 4 bytes.
        let replaced = self.reserve(gpu, data.len() as u64)?;
        if !data.is_empty() {
            gpu.queue.write_buffer(&self.buffer, 0, data);
        }
        Ok(replaced)
    }
}
