//! Reading GPU buffers back to the CPU: map a buffer range, wait for the GPU, copy it out;
//! the pair of buffers a query set's results travel through ([`QueryReadback`]); and the
//! lists a culling pass wrote ([`read_indirect_lists`]).

use crate::render::draw_args::IndexedArgs;

/// A query set's results on their way to the CPU: resolved into one buffer, copied into a
/// mappable one.
pub struct QueryReadback {
    resolve: wgpu::Buffer,
    /// The mappable copy.
    pub readback: wgpu::Buffer,
}

impl QueryReadback {
    /// Buffers for `queries` 8-byte query results.
    pub fn new(device: &wgpu::Device, label: &str, queries: u32) -> Self {
        let buffer = |usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: u64::from(queries.max(1)) * 8,
                usage,
                mapped_at_creation: false,
            })
        };
        Self {
            resolve: buffer(wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            readback: buffer(wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST),
        }
    }

    /// Records the resolve of the first `count` queries of `set` and their copy to
    /// [`readback`](Self::readback).
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, set: &wgpu::QuerySet, count: u32) {
        self.resolve(encoder, set, count, 0);
        self.copy(encoder, u64::from(count) * 8);
    }

    /// Records the resolve of the first `count` queries of `set` to byte `offset` of the
    /// resolve buffer (a multiple of `wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT`).
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder, set: &wgpu::QuerySet, count: u32, offset: u64) {
        encoder.resolve_query_set(set, 0..count, &self.resolve, offset);
    }

    /// Records the copy of the resolve buffer's first `bytes` to [`readback`](Self::readback).
    pub fn copy(&self, encoder: &mut wgpu::CommandEncoder, bytes: u64) {
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, bytes);
    }
}

/// Maps `buffer[..size]` for reading, waits for the device, and returns a copy of the bytes
/// (None if mapping or waiting failed). The buffer is unmapped again.
pub fn read_buffer(device: &wgpu::Device, buffer: &wgpu::Buffer, size: u64) -> Option<Vec<u8>> {
    let slice = buffer.slice(..size);
    slice.map_async(wgpu::MapMode::Read, |_| {});
    let waited = device.poll(wgpu::PollType::wait_indefinitely()).is_ok();
    let bytes = if waited {
        slice.get_mapped_range().ok().map(|data| data.to_vec())
    } else {
        None
    };
    buffer.unmap();
    bytes
}

/// Copies `source[..size]` (a `COPY_SRC` buffer) into a fresh readable buffer, submits the
/// copy and returns its bytes as [`read_buffer`] does (waits for the device).
pub fn copy_and_read(device: &wgpu::Device, queue: &wgpu::Queue, source: &wgpu::Buffer, size: u64) -> Option<Vec<u8>> {
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: size.max(4),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(source, 0, &staging, 0, size);
    queue.submit([encoder.finish()]);
    read_buffer(device, &staging, size)
}

/// Polls `device` once without blocking, or with `wait` until every submission has finished.
/// A failed poll is ignored: what it would have finished is looked at on the next one.
pub fn poll_device(device: &wgpu::Device, wait: bool) {
    let poll = if wait {
        wgpu::PollType::wait_indefinitely()
    } else {
        wgpu::PollType::Poll
    };
    let _ = device.poll(poll);
}

/// The lists a culling pass wrote, read back (waits for the GPU): for each of the `count`
/// indexed indirect arguments from argument `first` of `args`, the `instance_count` entries of
/// `list` from its `first_instance`.
pub fn read_indirect_lists(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    (args, list): (&wgpu::Buffer, &wgpu::Buffer),
    first: usize,
    count: usize,
) -> Option<Vec<Vec<u32>>> {
    let stride = size_of::<IndexedArgs>();
    let data = copy_and_read(device, queue, args, ((first + count) * stride) as u64)?;
    let args: &[IndexedArgs] = bytemuck::cast_slice(&data);
    let args = args.get(first..)?;
    let end = args
        .iter()
        .map(|a| a.first_instance + a.instance_count)
        .max()
        .unwrap_or(0);
    let data = copy_and_read(device, queue, list, u64::from(end.max(1)) * 4)?;
    let entries: &[u32] = bytemuck::cast_slice(&data);
    let lists = args.iter().map(|a| {
        let range = a.first_instance as usize..(a.first_instance + a.instance_count) as usize;
        entries.get(range).map_or_else(Vec::new, <[u32]>::to_vec)
    });
    Some(lists.collect())
}
