//! Reading GPU buffers back to the CPU: map a buffer range, wait for the GPU, copy it out.

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
