//! Offscreen colour + depth targets, optional analysis targets (shadow factor, world position
//! and normal per pixel), and reading them back to the CPU.

use glam::Vec3;
use image::RgbaImage;

use crate::render::readback::read_buffer;

/// Colour format of headless targets as passes draw them (written as sRGB PNG); the texture
/// itself is [`HEADLESS_STORAGE_FORMAT`], which compute passes write through a second view.
pub const HEADLESS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// The plain format of the headless colour texture: its storage view's (a compute pass that
/// writes it encodes sRGB itself).
pub const HEADLESS_STORAGE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Depth format of the camera's depth buffer (reverse-Z: cleared to 0, nearer is greater).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Format of the three analysis targets.
pub const ANALYSIS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// The views a frame renders into (the camera's depth buffer is a transient of the graph).
pub struct TargetViews {
    /// Colour attachment.
    pub color: wgpu::TextureView,
    /// Its format.
    pub format: wgpu::TextureFormat,
    /// The colour texture seen as [`HEADLESS_STORAGE_FORMAT`] for compute passes to write
    /// (sRGB-encoded when `format` is sRGB); None where the target cannot be a storage texture.
    pub storage: Option<wgpu::TextureView>,
    /// Analysis attachments (shadow, position, normal), when the frame is to be scored.
    pub analysis: Option<[wgpu::TextureView; 3]>,
    /// Size in pixels.
    pub width: u32,
    /// Size in pixels.
    pub height: u32,
}

/// What the analysis targets held for one frame, one entry per pixel, rows top to bottom.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AnalysisImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The shadow factor the material multiplied into the sun term (1 where not evaluated).
    pub shadow: Vec<f32>,
    /// Cascade sampled, 0–3, or 255 where none (background, past max_distance, shadows off).
    pub cascade: Vec<u8>,
    /// True where the shadow was evaluated: a shadow receiver facing the sun.
    pub evaluated: Vec<bool>,
    /// Position relative to the render origin (`RenderOrigin`; background pixels hold NaN).
    pub position: Vec<Vec3>,
    /// Unit normal facing the camera (background pixels hold NaN).
    pub normal: Vec<Vec3>,
    /// `n · l` of the pixel (0 for background).
    pub n_dot_l: Vec<f32>,
}

/// An offscreen render target that can be read back.
pub struct HeadlessTarget {
    color: wgpu::Texture,
    analysis: Option<[wgpu::Texture; 3]>,
    /// Views to render into.
    pub views: TargetViews,
}

/// A single-level 2D texture of `layers` array layers.
pub fn texture_2d(
    device: &wgpu::Device,
    label: &str,
    extent: (u32, u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    texture_2d_mips(device, label, extent, format, usage, 1)
}

/// [`texture_2d`] with `mips` mip levels.
pub fn texture_2d_mips(
    device: &wgpu::Device,
    label: &str,
    extent: (u32, u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    mips: u32,
) -> wgpu::Texture {
    create_texture(device, label, extent, format, usage, (mips, 1, &[]))
}

/// [`texture_2d`] with `samples` samples per texel (a multisampled attachment when more than
/// one: then `layers` must be 1).
pub fn texture_2d_multisampled(
    device: &wgpu::Device,
    label: &str,
    extent: (u32, u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    samples: u32,
) -> wgpu::Texture {
    create_texture(device, label, extent, format, usage, (1, samples, &[]))
}

/// [`texture_2d`] (one layer) that may also be viewed in `view_formats`.
pub fn texture_2d_viewed(
    device: &wgpu::Device,
    label: &str,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    view_formats: &[wgpu::TextureFormat],
) -> wgpu::Texture {
    create_texture(device, label, (width, height, 1), format, usage, (1, 1, view_formats))
}

fn create_texture(
    device: &wgpu::Device,
    label: &str,
    (width, height, layers): (u32, u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    (mips, samples, view_formats): (u32, u32, &[wgpu::TextureFormat]),
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: layers,
        },
        mip_level_count: mips.max(1),
        sample_count: samples.max(1),
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats,
    })
}

fn view(texture: &wgpu::Texture) -> wgpu::TextureView {
    texture.create_view(&wgpu::TextureViewDescriptor::default())
}

/// Copies a 2D texture's first layer to the CPU (waits for the GPU): `texel_bytes` per texel,
/// rows top to bottom, unpadded. The texture needs `COPY_SRC`.
pub fn read_texture(device: &wgpu::Device, queue: &wgpu::Queue, texture: &wgpu::Texture, texel_bytes: u32) -> Vec<u8> {
    read_texture_layer(device, queue, texture.as_image_copy(), texel_bytes)
}

/// [`read_texture`] of one layer and aspect (`source`: texture, mip 0, origin at the
/// layer): the rows of that layer, unpadded.
pub fn read_texture_layer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    source: wgpu::TexelCopyTextureInfo<'_>,
    texel_bytes: u32,
) -> Vec<u8> {
    let (width, height) = (source.texture.width(), source.texture.height());
    let row = width * texel_bytes;
    let padded = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: padded as u64 * height as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("readback"),
    });
    encoder.copy_texture_to_buffer(
        source,
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
    let data = read_buffer(device, &buffer, padded as u64 * height as u64).unwrap_or_default();
    let mut bytes = Vec::with_capacity((row * height) as usize);
    for y in 0..height as usize {
        let start = y * padded as usize;
        if let Some(line) = data.get(start..start + row as usize) {
            bytes.extend_from_slice(line);
        }
    }
    bytes
}

/// Reads an `Rgba32Float` texture as texels.
fn read_f32x4(device: &wgpu::Device, queue: &wgpu::Queue, texture: &wgpu::Texture) -> Vec<[f32; 4]> {
    let bytes = read_texture(device, queue, texture, 16);
    bytes
        .chunks_exact(16)
        .map(bytemuck::pod_read_unaligned::<[f32; 4]>)
        .collect()
}

impl TargetViews {
    /// Views for an external colour texture (a swapchain image); the render graph provides
    /// the depth buffer.
    pub fn for_color(color: wgpu::TextureView, format: wgpu::TextureFormat, width: u32, height: u32) -> Self {
        Self {
            color,
            format,
            storage: None,
            analysis: None,
            width,
            height,
        }
    }
}

impl HeadlessTarget {
    /// Allocates a `width`×`height` target; with `analysis`, also the three analysis targets.
    pub fn new(device: &wgpu::Device, width: u32, height: u32, analysis: bool) -> Self {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        // NOTE: a plain texture drawn through an sRGB view (an sRGB format cannot be a storage
        // texture); the bytes read back are the same.
        let color = create_texture(
            device,
            "headless colour",
            (width, height, 1),
            HEADLESS_STORAGE_FORMAT,
            usage | wgpu::TextureUsages::STORAGE_BINDING,
            (1, 1, &[HEADLESS_FORMAT]),
        );
        let analysis = analysis.then(|| {
            ["analysis shadow", "analysis position", "analysis normal"]
                .map(|label| texture_2d(device, label, (width, height, 1), ANALYSIS_FORMAT, usage))
        });
        // NOTE: each view asks only for the usage its format allows.
        let srgb = color.create_view(&wgpu::TextureViewDescriptor {
            format: Some(HEADLESS_FORMAT),
            usage: Some(wgpu::TextureUsages::RENDER_ATTACHMENT),
            ..Default::default()
        });
        let storage = color.create_view(&wgpu::TextureViewDescriptor {
            usage: Some(wgpu::TextureUsages::STORAGE_BINDING),
            ..Default::default()
        });
        let mut views = TargetViews::for_color(srgb, HEADLESS_FORMAT, width, height);
        views.storage = Some(storage);
        views.analysis = analysis.as_ref().map(|textures| textures.each_ref().map(view));
        Self { color, analysis, views }
    }

    /// Copies the colour target to the CPU (waits for the GPU).
    pub fn read(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> RgbaImage {
        let (width, height) = (self.views.width, self.views.height);
        let pixels = read_texture(device, queue, &self.color, 4);
        RgbaImage::from_raw(width, height, pixels).unwrap_or_else(|| RgbaImage::new(width, height))
    }

    /// Copies the analysis targets to the CPU, if this target has them.
    pub fn read_analysis(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Option<AnalysisImage> {
        let [shadow, position, normal] = self.analysis.as_ref()?.each_ref().map(|t| read_f32x4(device, queue, t));
        let drawn = |p: &[f32; 4]| p[3] > 0.5;
        Some(AnalysisImage {
            width: self.views.width,
            height: self.views.height,
            shadow: shadow.iter().map(|s| s[0]).collect(),
            cascade: shadow
                .iter()
                .zip(&position)
                .map(|(s, p)| if drawn(p) && s[1] >= 0.0 { s[1] as u8 } else { 255 })
                .collect(),
            evaluated: shadow.iter().map(|s| s[2] > 0.5).collect(),
            position: position
                .iter()
                .map(|p| {
                    if drawn(p) {
                        Vec3::new(p[0], p[1], p[2])
                    } else {
                        Vec3::NAN
                    }
                })
                .collect(),
            normal: normal
                .iter()
                .zip(&position)
                .map(|(n, p)| {
                    if drawn(p) {
                        Vec3::new(n[0], n[1], n[2])
                    } else {
                        Vec3::NAN
                    }
                })
                .collect(),
            n_dot_l: shadow.iter().map(|s| s[3]).collect(),
        })
    }
}
