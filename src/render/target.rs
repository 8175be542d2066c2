//! Offscreen colour + depth targets, and reading the colour back into an image.

use image::RgbaImage;

/// Colour format of headless targets (written as sRGB PNG).
pub const HEADLESS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// Depth format of the camera's depth buffer (reverse-Z: cleared to 0, nearer is greater).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The views a frame renders into.
pub struct TargetViews {
    /// Colour attachment.
    pub color: wgpu::TextureView,
    /// Its format.
    pub format: wgpu::TextureFormat,
    /// Depth attachment.
    pub depth: wgpu::TextureView,
    /// Size in pixels.
    pub width: u32,
    /// Size in pixels.
    pub height: u32,
}

/// An offscreen render target that can be read back.
pub struct HeadlessTarget {
    color: wgpu::Texture,
    /// Views to render into.
    pub views: TargetViews,
}

/// A single-level 2D texture.
pub fn texture_2d(
    device: &wgpu::Device,
    label: &str,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

fn depth_view(device: &wgpu::Device, width: u32, height: u32) -> wgpu::TextureView {
    texture_2d(
        device,
        "camera depth",
        (width, height),
        DEPTH_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    )
    .create_view(&wgpu::TextureViewDescriptor::default())
}

impl TargetViews {
    /// Views for an external colour texture (a swapchain image) plus a new depth buffer.
    pub fn for_color(
        device: &wgpu::Device,
        color: wgpu::TextureView,
        format: wgpu::TextureFormat,
        width: u32,
        height: u32,
    ) -> Self {
        Self {
            color,
            format,
            depth: depth_view(device, width, height),
            width,
            height,
        }
    }
}

impl HeadlessTarget {
    /// Allocates a `width`×`height` target.
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let color = texture_2d(device, "headless colour", (width, height), HEADLESS_FORMAT, usage);
        let view = color.create_view(&wgpu::TextureViewDescriptor::default());
        let views = TargetViews::for_color(device, view, HEADLESS_FORMAT, width, height);
        Self { color, views }
    }

    /// Copies the colour target to the CPU (waits for the GPU).
    pub fn read(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> RgbaImage {
        let (width, height) = (self.views.width, self.views.height);
        let row = width * 4;
        let padded = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("colour readback"),
            size: padded as u64 * height as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("readback"),
        });
        encoder.copy_texture_to_buffer(
            self.color.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        queue.submit([encoder.finish()]);
        let slice = buffer.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        let _ = device.poll(wgpu::PollType::wait_indefinitely());
        let mut pixels = Vec::with_capacity((row * height) as usize);
        if let Ok(data) = slice.get_mapped_range() {
            for y in 0..height as usize {
                let start = y * padded as usize;
                pixels.extend_from_slice(&data[start..start + row as usize]);
            }
        }
        buffer.unmap();
        RgbaImage::from_raw(width, height, pixels).unwrap_or_else(|| RgbaImage::new(width, height))
    }
}
