//! The resolved visibility: one `R32Float` layer per shadowed light, at the target's size,
//! written by the compute resolve ([`crate::render::resolve`]) and read by the lighting pass
//! through `penumbra::lights::shadow_visibility`. Owned across frames; recreated when the
//! target's size or the number of shadowed lights changes. A 1×1 stand-in is bound while
//! nothing is resolved (and in the group the resolve itself binds, which cannot sample what
//! it writes).

use crate::render::frame_inputs::FrameInputs;
use crate::render::target::texture_2d;

/// Format of the resolved visibility (storage-writable in core WebGPU).
pub const VISIBILITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// What the compute resolve writes this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ResolvePlan {
    /// The target's size, pixels.
    pub size: (u32, u32),
    /// It writes every shadowed light's filtered shadow (`RenderOptions::visibility_resolve`);
    /// else only the contact shadows of the lights that have them.
    pub filters: bool,
}

impl ResolvePlan {
    /// What the resolve writes this frame on a target of `size` pixels, where `normals`
    /// says the prepass runs with normals the resolve can read: every shadowed light's
    /// filter with [`RenderOptions::visibility_resolve`](crate::render::RenderOptions), else
    /// only contact shadows; nothing without shadow views or without either.
    pub fn for_frame(input: &FrameInputs<'_>, size: (u32, u32), normals: bool) -> Option<ResolvePlan> {
        let filters = input.options.visibility_resolve;
        let wanted = filters || input.lights.any_contact_shadows();
        (normals && wanted && !input.shadow_views.views.is_empty()).then_some(ResolvePlan { size, filters })
    }
}

/// The texture, its views, and what it was made for.
pub struct VisibilityTarget {
    /// All layers, for sampling in the lighting pass.
    pub view: wgpu::TextureView,
    /// All layers, for the resolve's storage writes.
    pub storage_view: wgpu::TextureView,
    /// Width, height, layers.
    pub extent: (u32, u32, u32),
}

impl VisibilityTarget {
    /// A `width`×`height` target of `layers` layers (each at least 1).
    pub fn new(device: &wgpu::Device, (width, height, layers): (u32, u32, u32)) -> Self {
        let extent = (width.max(1), height.max(1), layers.max(1));
        let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING;
        let texture = texture_2d(device, "resolved visibility", extent, VISIBILITY_FORMAT, usage);
        let array = || wgpu::TextureViewDescriptor {
            label: Some("resolved visibility"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        };
        Self {
            view: texture.create_view(&array()),
            storage_view: texture.create_view(&array()),
            extent,
        }
    }

    /// Bytes of GPU memory.
    pub fn memory_bytes(&self) -> u64 {
        let (w, h, l) = self.extent;
        u64::from(w) * u64::from(h) * u64::from(l) * 4
    }
}
