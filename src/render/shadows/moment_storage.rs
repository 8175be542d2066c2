//! Variance-shadow-map storage: the moments `(z, z²)` of every layer of one depth storage (spot
//! lights: a 2D array; point lights: a cube array), in the device's
//! [`moments_format`](crate::render::GpuContext::moments_format), and a scratch of one light's
//! layers (a cube, or one layer) for the separable blur, which runs one light at a time.
//! Allocated only while a light of that storage filters moments; a 1×1 stand-in is bound
//! otherwise. The suns' cascade moments may have mip levels (contact hardening filters a wider
//! footprint at a coarser level).

use std::sync::atomic::{AtomicU64, Ordering};

use crate::render::target::texture_2d_mips;

/// Numbers every array ever created, so the moments pass can tell its layers were replaced.
static CREATED: AtomicU64 = AtomicU64::new(1);

/// One texture of moments with the views the passes need.
pub struct MomentTexture {
    /// The texture.
    pub texture: wgpu::Texture,
    /// All layers for sampling (a cube-array view for point lights).
    pub sampled: wgpu::TextureView,
    /// All layers of the first mip level as a 2D array, for compute writes.
    pub storage: wgpu::TextureView,
    /// Each mip level from the second on: a 2D-array view to write it and one of the level
    /// before it to read (empty without mips).
    pub levels: Vec<(wgpu::TextureView, wgpu::TextureView)>,
}

impl MomentTexture {
    fn new(
        device: &wgpu::Device,
        label: &str,
        format: wgpu::TextureFormat,
        side: u32,
        layers: u32,
        cube: bool,
        mips: u32,
    ) -> Self {
        let usage =
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC;
        let texture = texture_2d_mips(device, label, (side, side, layers), format, usage, mips);
        let view = |dimension, levels: Option<(u32, u32)>| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some(label),
                dimension: Some(dimension),
                base_mip_level: levels.map_or(0, |l| l.0),
                mip_level_count: levels.map(|l| l.1),
                ..Default::default()
            })
        };
        let sampled = view(
            if cube {
                wgpu::TextureViewDimension::CubeArray
            } else {
                wgpu::TextureViewDimension::D2Array
            },
            None,
        );
        let flat = wgpu::TextureViewDimension::D2Array;
        let storage = view(flat, Some((0, 1)));
        let levels = (1..texture.mip_level_count())
            .map(|level| (view(flat, Some((level, 1))), view(flat, Some((level - 1, 1)))))
            .collect();
        Self {
            texture,
            sampled,
            storage,
            levels,
        }
    }
}

/// The moments of one depth storage and the blur's scratch.
pub struct MomentArray {
    /// The moments the materials sample.
    pub moments: MomentTexture,
    /// Where the first blur axis writes: one light's layers (1×1 texels while no light of
    /// the storage blurs).
    pub scratch: MomentTexture,
    /// Texels per side of the scratch: `side`, or 1 without a blur.
    pub scratch_side: u32,
    /// Texels per side of a layer.
    pub side: u32,
    /// Layers (whole cubes for point lights).
    pub layers: u32,
    /// Sampled as a cube array.
    pub cube: bool,
    /// True for the 1×1 stand-in.
    pub placeholder: bool,
    /// Unique number of this allocation.
    pub id: u64,
}

impl MomentArray {
    /// Allocates `layers` layers of `side`² texels (rounded up to whole cubes with `cube`) and
    /// `mips` mip levels, with a full-size scratch only when a light will `blur`.
    pub fn new(
        device: &wgpu::Device,
        label: &str,
        format: wgpu::TextureFormat,
        (side, layers, mips): (u32, u32, u32),
        cube: bool,
        blur: bool,
    ) -> Self {
        let layers = if cube {
            layers.max(1).div_ceil(6) * 6
        } else {
            layers.max(1)
        };
        let scratch_side = if blur { side } else { 1 };
        let scratch_layers = if cube { 6 } else { 1 };
        Self {
            moments: MomentTexture::new(device, label, format, side, layers, cube, mips),
            scratch: MomentTexture::new(device, label, format, scratch_side, scratch_layers, cube, 1),
            scratch_side,
            side,
            layers,
            cube,
            placeholder: false,
            id: CREATED.fetch_add(1, Ordering::Relaxed),
        }
    }

    /// The 1×1 stand-in bound while no light of the storage uses VSM.
    pub fn placeholder(device: &wgpu::Device, label: &str, format: wgpu::TextureFormat, cube: bool) -> Self {
        Self {
            placeholder: true,
            ..Self::new(device, label, format, (1, 1, 1), cube, false)
        }
    }

    /// True when `layers` layers of `side` texels (and a scratch, for a `blur`) need a new
    /// allocation (none needed for 0 layers: the array is kept).
    pub fn needs(&self, side: u32, layers: u32, blur: bool) -> bool {
        let scratch_short = blur && self.scratch_side != side;
        layers > 0 && (self.placeholder || self.side != side || self.layers < layers || scratch_short)
    }

    /// Mip levels of the moments.
    pub fn mips(&self) -> u32 {
        self.moments.texture.mip_level_count()
    }

    /// Bytes of GPU memory (moments and scratch; 0 for the stand-in).
    pub fn memory_bytes(&self) -> u64 {
        if self.placeholder {
            return 0;
        }
        let texel = u64::from(self.moments.texture.format().block_copy_size(None).unwrap_or(8));
        let scratch = if self.cube { 6 } else { 1 };
        let level_texels: u64 = (0..self.mips())
            .map(|l| u64::from((self.side >> l).max(1)).pow(2))
            .sum();
        texel * (level_texels * u64::from(self.layers) + u64::from(self.scratch_side).pow(2) * scratch)
    }
}
