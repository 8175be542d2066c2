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

    /// An empty storage buffer that can be copied from (read back).
    pub fn readable(device: &wgpu::Device, label: &'static str) -> Self {
        Self::with_usage(
            device,
            label,
            256,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        )
    }

    /// An empty storage buffer of indirect draw arguments (a culling pass writes them), that
    /// can be read back.
    pub fn indirect(device: &wgpu::Device, label: &'static str) -> Self {
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_SRC;
        Self::with_usage(device, label, 256, usage)
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

    /// The generation written last by [`write_generation`](Self::write_generation) or
    /// [`write_patch`](Self::write_patch).
    pub fn generation(&self) -> Option<u64> {
        self.generation
    }

    /// Writes generation `generation` of `data` (elements of `stride` bytes): only the
    /// elements `patch` lists (sorted, each in `data`) when it is given, the buffer is large
    /// enough and holds the data they were changed from; else whole, as
    /// [`write_generation`](Self::write_generation). Runs of listed elements less than
    /// [`PATCH_GAP`] elements apart are written as one range. Returns true when the buffer was
    /// replaced.
    pub fn write_patch(
        &mut self,
        gpu: &GpuContext,
        generation: u64,
        data: &[u8],
        stride: usize,
        patch: Option<&[u32]>,
    ) -> Result<bool, LimitError> {
        if self.generation == Some(generation) {
            return Ok(false);
        }
        let Some(patch) = patch.filter(|_| data.len() as u64 <= self.buffer.size() && self.generation.is_some()) else {
            return self.write_generation(gpu, generation, data);
        };
        // NOTE: the data must still fit the device's binding, as a whole write checks.
        let whole_binding = self.usage.contains(wgpu::BufferUsages::STORAGE);
        gpu.limits.check_buffer(self.label, data.len() as u64, whole_binding)?;
        for (first, end) in patch_runs(patch, data.len() / stride.max(1)) {
            let range = first * stride..end * stride;
            gpu.queue.write_buffer(&self.buffer, range.start as u64, &data[range]);
        }
        self.generation = Some(generation);
        Ok(false)
    }
}

/// Listed elements closer than this are written with the ones between them, as one range.
pub const PATCH_GAP: usize = 16;

/// The ranges `(first, end)` covering the sorted element indices `patch` (those below `len`),
/// merging indices less than [`PATCH_GAP`] apart.
pub fn patch_runs(patch: &[u32], len: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
    let mut i = 0;
    std::iter::from_fn(move || {
        let (&first, rest) = patch.get(i..)?.split_first()?;
        let first = first as usize;
        if first >= len {
            return None;
        }
        let mut end = first + 1;
        i += 1;
        for &next in rest {
            let next = next as usize;
            if next >= len || next >= end + PATCH_GAP {
                break;
            }
            end = end.max(next + 1);
            i += 1;
        }
        Some((first, end))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patch_runs_merge_close_indices_and_stop_at_the_end() {
        let runs: Vec<_> = patch_runs(&[0, 1, 2, 10, 40, 41, 200], 100).collect();
        assert_eq!(runs, [(0, 11), (40, 42)]);
        assert_eq!(patch_runs(&[], 10).count(), 0);
        let runs: Vec<_> = patch_runs(&[5, 5, 6], 10).collect();
        assert_eq!(runs, [(5, 7)]);
    }
}
