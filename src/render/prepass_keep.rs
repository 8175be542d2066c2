//! The depth prepass kept from frame to frame: where a frame draws its prepass with one
//! sample per pixel ([`RenderOptions::prepass_reuse`]), it draws into textures the renderer
//! keeps (not the graph's transients), and a later frame whose prepass would draw exactly
//! the same ([`PrepassKey`]: the same camera, target, instances, view lists, meshes,
//! materials and options, no skinned mesh posed) draws none and reads what is there. A still
//! camera over a still scene then costs the prepass nothing on the GPU.
//!
//! Nothing else writes these textures: with a prepass the lighting pass tests the depth
//! without writing it, and the normals and shading ids are the prepass's alone. The camera's
//! occlusion culling then skips its late phase too: the early phase lists last frame's seen
//! instances, which the kept depth was drawn from.

use crate::ecs::ActiveView;
use crate::math::frustum::CameraView;
use crate::render::frame_inputs::FrameInputs;
use crate::render::options::RenderOptions;
use crate::render::prepass::{NORMAL_FORMAT, SHADING_ID_FORMAT};
use crate::render::target::{DEPTH_FORMAT, texture_2d};

/// Everything a prepass's output depends on: two frames of equal keys draw the same prepass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrepassKey {
    /// The camera (its transform and projection).
    camera: CameraView,
    /// The target's size in pixels.
    size: (u32, u32),
    /// Normals and shading ids drawn too.
    targets: (bool, bool),
    /// The render origin instances are relative to.
    origin: glam::Vec3,
    /// Generations of the instance list and of the camera view's draw lists.
    instances: u64,
    view_lists: u64,
    /// The camera's LOD error at unit depth (the GPU's choice of mesh levels).
    lod_error_bits: u32,
    /// Generations of the meshes, the materials and the images.
    assets: (u64, u64, u64),
    /// The render switches.
    options: RenderOptions,
}

impl PrepassKey {
    /// The key of a frame of `inputs` on a `size` target drawing normals and shading ids
    /// (`targets`), or None where the prepass cannot be kept: no camera, or skinned meshes
    /// posed this frame (they rewrite vertices the prepass draws).
    pub fn of(inputs: &FrameInputs<'_>, size: (u32, u32), targets: (bool, bool)) -> Option<Self> {
        let ActiveView {
            camera: Some((camera, _)),
        } = inputs.view
        else {
            return None;
        };
        if inputs.skinning.is_some_and(|s| s.any_changed()) {
            return None;
        }
        Some(Self {
            camera: *camera,
            size,
            targets,
            origin: inputs.origin,
            instances: inputs.instances.generation,
            view_lists: inputs.view_groups.generation,
            lod_error_bits: inputs.view_groups.lod_error_per_depth.to_bits(),
            assets: (
                inputs.meshes.generation(),
                inputs.materials.generation(),
                inputs.images.generation(),
            ),
            options: inputs.options,
        })
    }
}

/// The kept prepass's textures, made for one size and set of targets.
pub struct KeptTextures {
    size: (u32, u32),
    targets: (bool, bool),
    /// The camera depth's view.
    pub depth: wgpu::TextureView,
    /// The normals' view, where drawn.
    pub normals: Option<wgpu::TextureView>,
    /// The shading ids' view, where drawn.
    pub ids: Option<wgpu::TextureView>,
}

impl KeptTextures {
    fn new(device: &wgpu::Device, (width, height): (u32, u32), (normals, ids): (bool, bool)) -> Self {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let make = |label, format| {
            texture_2d(device, label, (width, height, 1), format, usage)
                .create_view(&wgpu::TextureViewDescriptor::default())
        };
        Self {
            size: (width, height),
            targets: (normals, ids),
            depth: make("kept camera depth", DEPTH_FORMAT),
            normals: normals.then(|| make("kept camera normals", NORMAL_FORMAT)),
            ids: (normals && ids).then(|| make("kept camera shading ids", SHADING_ID_FORMAT)),
        }
    }
}

/// The renderer's kept prepass: its textures and the key of what they hold.
#[derive(Default)]
pub struct PrepassKeep {
    textures: Option<KeptTextures>,
    /// The key of the prepass the textures hold, once a frame drew it whole.
    held: Option<PrepassKey>,
    /// This frame's key, until [`end`](Self::end).
    frame: Option<PrepassKey>,
}

impl PrepassKeep {
    /// Starts a frame whose prepass is kept, with `key`: returns its textures (made anew for
    /// another size or set of targets) and whether they already hold this frame's prepass.
    pub fn begin(&mut self, device: &wgpu::Device, key: PrepassKey) -> (&KeptTextures, bool) {
        let fits = |t: &KeptTextures| t.size == key.size && t.targets == key.targets;
        if !self.textures.as_ref().is_some_and(fits) {
            self.textures = Some(KeptTextures::new(device, key.size, key.targets));
            self.held = None;
        }
        let held = self.held == Some(key);
        self.frame = Some(key);
        let textures = self.textures.as_ref().expect("made above");
        (textures, held)
    }

    /// Ends the frame: `drawn` when its prepass was recorded whole (or kept), so the
    /// textures hold its key; otherwise they hold nothing known.
    pub fn end(&mut self, drawn: bool) {
        self.held = self.frame.take().filter(|_| drawn);
    }

    /// Whether this frame reads the prepass held from an earlier one (until [`end`](Self::end)).
    pub fn reused(&self) -> bool {
        self.frame.is_some() && self.frame == self.held
    }

    /// Frees the textures (a frame whose prepass is not kept).
    pub fn release(&mut self) {
        *self = Self::default();
    }
}
