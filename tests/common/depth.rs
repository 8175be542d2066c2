//! Reads a depth texture back: what the tests of the paged clipmap compare.

use penumbra::render::GpuContext;
use penumbra::render::readback::read_buffer;

/// The `width` × `height` depth texels of `texture`'s first layer, rows downwards.
pub fn read_depth(gpu: &GpuContext, texture: &wgpu::Texture, (width, height): (u32, u32)) -> Vec<f32> {
    let row = (width * 4).next_multiple_of(256);
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(row * height),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: None,
            },
        },
        wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
    );
    gpu.queue.submit([encoder.finish()]);
    let bytes = read_buffer(&gpu.device, &staging, staging.size()).expect("the depth reads back");
    (0..height as usize)
        .flat_map(|y| {
            let start = y * row as usize;
            bytes[start..start + width as usize * 4]
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect::<Vec<_>>()
        })
        .collect()
}
