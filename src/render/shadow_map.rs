//! The directional shadow map: one Depth32Float 2D array with a layer per cascade, owned
//! across frames and recreated only when the resolution changes.

use crate::settings::MAX_CASCADES;

/// Depth format of the shadow map.
pub const SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The shadow map texture and its views.
pub struct ShadowMap {
    /// The texture (MAX_CASCADES layers).
    pub texture: wgpu::Texture,
    /// All layers, for sampling.
    pub array_view: wgpu::TextureView,
    /// One view per layer, for rendering a cascade.
    pub layer_views: Vec<wgpu::TextureView>,
    /// Texels per side.
    pub resolution: u32,
}

impl ShadowMap {
    /// Allocates a shadow map of `resolution`² texels per cascade.
    pub fn new(device: &wgpu::Device, resolution: u32) -> Self {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("directional shadow map"),
            size: wgpu::Extent3d {
                width: resolution,
                height: resolution,
                depth_or_array_layers: MAX_CASCADES as u32,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: SHADOW_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let array_view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("shadow map array"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let layer_views = (0..MAX_CASCADES as u32)
            .map(|layer| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some("shadow map cascade"),
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
            layer_views,
            resolution,
        }
    }

    /// Bytes of GPU memory the map occupies.
    pub fn memory_bytes(&self) -> u64 {
        self.resolution as u64 * self.resolution as u64 * 4 * MAX_CASCADES as u64
    }
}
