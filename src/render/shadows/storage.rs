//! Shadow storage: a depth 2D array (`Depth32Float`, or `Depth16Unorm` for a sun's cascades
//! where [`SunDepth::Unorm16`](crate::render::SunDepth) asks for it) with one layer per shadow
//! view of one kind (the
//! cascades of every shadowed sun; every shadowed spot light; the six faces of every shadowed
//! point light). A view smaller than the layer is drawn in its top-left corner and sampled
//! through its UV rectangle, so each light keeps its own resolution — except point lights,
//! whose array is sampled as a cube array (hardware face selection, filtering across face
//! edges) and so share one face size: the largest any of them asks for. The array is owned across frames: it is recreated when the largest
//! view changes size or more layers are needed, never for fewer.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::render::target::{read_texture_layer, texture_2d};

/// Numbers every array ever created, so a pass can tell its layers were replaced.
static CREATED: AtomicU64 = AtomicU64::new(1);

/// Depth format of every shadow map but a sun's cascades drawn with 16 bits.
pub const SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Bytes of one texel of a shadow depth format, as wgpu copies its depth (2 for
/// `Depth16Unorm`, 4 for `Depth32Float`).
pub fn depth_texel_bytes(format: wgpu::TextureFormat) -> u32 {
    format
        .block_copy_size(Some(wgpu::TextureAspect::DepthOnly))
        .unwrap_or(4)
}

/// One kind's depth array and its views.
pub struct DepthArray {
    /// The texture.
    pub texture: wgpu::Texture,
    /// All layers, for sampling (a cube-array view for point lights).
    pub array_view: wgpu::TextureView,
    /// All layers as a 2D array (the same as `array_view` except for point lights), for
    /// passes that read layers by index.
    pub flat_view: wgpu::TextureView,
    /// One view per layer, for rendering a shadow view.
    pub layer_views: Vec<wgpu::TextureView>,
    /// Texels per side of a layer.
    pub side: u32,
    /// True for the 1×1 stand-in bound while the kind has no view.
    pub placeholder: bool,
    /// Unique number of this allocation: what its layers hold is lost when it changes.
    pub id: u64,
}

impl DepthArray {
    /// Allocates `layers` layers of `side`² texels of `format`; with `cube`, sampled as a cube
    /// array (the layers rounded up to whole cubes).
    pub fn new(
        device: &wgpu::Device,
        label: &str,
        (side, layers): (u32, u32),
        cube: bool,
        format: wgpu::TextureFormat,
    ) -> Self {
        let layers = if cube {
            layers.max(1).div_ceil(6) * 6
        } else {
            layers.max(1)
        };
        let texture = texture_2d(device, label, (side, side, layers), format, DEPTH_USAGE);
        let array_view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some(label),
            dimension: Some(if cube {
                wgpu::TextureViewDimension::CubeArray
            } else {
                wgpu::TextureViewDimension::D2Array
            }),
            ..Default::default()
        });
        let flat_view = if cube {
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some(label),
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        } else {
            array_view.clone()
        };
        let layer_views = (0..layers)
            .map(|layer| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some(label),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        Self {
            texture,
            array_view,
            flat_view,
            layer_views,
            side,
            placeholder: false,
            id: CREATED.fetch_add(1, Ordering::Relaxed),
        }
    }

    /// The 1×1 stand-in (one layer, or one cube) bound while a kind has no shadow view.
    pub fn placeholder(device: &wgpu::Device, label: &str, cube: bool) -> Self {
        Self {
            placeholder: true,
            ..Self::new(device, label, (1, 1), cube, SHADOW_FORMAT)
        }
    }

    /// Number of layers.
    pub fn layers(&self) -> u32 {
        self.layer_views.len() as u32
    }

    /// True when views of `side` texels in `layers` layers of `format` need a new array: the
    /// side or the format differs or there are too few layers. A kind with no views keeps what
    /// it has.
    pub fn needs(&self, side: u32, layers: u32, format: wgpu::TextureFormat) -> bool {
        layers > 0 && (self.placeholder || self.side != side || self.layers() < layers || self.format() != format)
    }

    /// Its depth format.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.texture.format()
    }

    /// Copies layer `layer` to the CPU (row by row, `side`² reverse-Z depths; None past the
    /// last layer). For tests and debugging: it waits for the GPU.
    pub fn read_layer(&self, device: &wgpu::Device, queue: &wgpu::Queue, layer: u32) -> Option<Vec<f32>> {
        read_depth_layer(device, queue, &self.texture, layer)
    }

    /// Bytes of GPU memory the array occupies (0 for the stand-in).
    pub fn memory_bytes(&self) -> u64 {
        if self.placeholder {
            return 0;
        }
        let texel = u64::from(depth_texel_bytes(self.format()));
        u64::from(self.side) * u64::from(self.side) * texel * u64::from(self.layers())
    }
}

/// What shadow depth textures are used for: rendered into, sampled, copied back.
pub(crate) const DEPTH_USAGE: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::COPY_DST)
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);

/// Copies layer `layer` of a `Depth32Float` or `Depth16Unorm` texture to the CPU as depths
/// in 0–1 (row by row; None past the last layer). For tests, tools and debugging: it waits
/// for the GPU.
pub fn read_depth_layer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    layer: u32,
) -> Option<Vec<f32>> {
    if layer >= texture.depth_or_array_layers() {
        return None;
    }
    let source = wgpu::TexelCopyTextureInfo {
        texture,
        mip_level: 0,
        origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
        aspect: wgpu::TextureAspect::DepthOnly,
    };
    if texture.format() == wgpu::TextureFormat::Depth16Unorm {
        let bytes = read_texture_layer(device, queue, source, 2);
        let unorm = |b: &[u8]| f32::from(u16::from_le_bytes([b[0], b[1]])) / f32::from(u16::MAX);
        return Some(bytes.chunks_exact(2).map(unorm).collect());
    }
    let bytes = read_texture_layer(device, queue, source, 4);
    Some(
        bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect(),
    )
}
