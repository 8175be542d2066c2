//! [`RenderOptions`]: how frames are rendered, as an ECS resource the application (or the
//! viewer's inspector) changes between frames.

use bevy_ecs::resource::Resource;

/// Whether the camera's depth is written in a prepass before the lighting pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DepthPrepass {
    /// On while the camera's view has fewer triangles than the target has pixels
    /// ([`prepass_pays`]): then the lighting pass's saved shading outweighs drawing the
    /// geometry twice; past it the view is bound by its vertices and the prepass would double
    /// that work.
    #[default]
    Auto,
    /// Always.
    On,
    /// Never: the lighting pass writes depth itself and may shade a pixel more than once.
    Off,
}

/// Samples per pixel of the camera's colour and depth (multisample anti-aliasing), resolved
/// to the single-sample target at the end of the lighting pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Msaa {
    /// One sample, the default: no anti-aliasing; alpha-masked materials are alpha-tested.
    #[default]
    Off,
    /// Two samples (where the adapter has them for the target's format, else one).
    Sample2,
    /// Four samples: edges get intermediate coverage and alpha-masked materials use
    /// alpha-to-coverage. Alpha-masked materials then filter their own shadows in the lighting
    /// pass (the depth prepass cannot match their coverage, so the compute resolve has no
    /// surface for them): on the H100 the default scene's frame went from 1.08 to 8.09 ms,
    /// most of it the foliage's filtering (see `docs/benchmarks.md`).
    Sample4,
}

impl Msaa {
    /// Samples per pixel: 1, 2 or 4.
    pub fn samples(self) -> u32 {
        match self {
            Self::Off => 1,
            Self::Sample2 => 2,
            Self::Sample4 => 4,
        }
    }

    /// The largest setting up to this one whose sample count `supported` accepts (one sample
    /// always is): what a device that cannot multisample a format this many times falls
    /// back to.
    pub fn fallback(self, supported: impl Fn(u32) -> bool) -> Self {
        [Self::Sample4, Self::Sample2]
            .into_iter()
            .find(|m| m.samples() <= self.samples() && supported(m.samples()))
            .unwrap_or(Self::Off)
    }

    /// The setting of `samples` samples per pixel (1, 2 or 4); None for any other count.
    pub fn from_samples(samples: u32) -> Option<Self> {
        match samples {
            1 => Some(Self::Off),
            2 => Some(Self::Sample2),
            4 => Some(Self::Sample4),
            _ => None,
        }
    }
}

impl std::str::FromStr for Msaa {
    type Err = String;

    /// Parses a sample count, `1`, `2` or `4` (the command line's `--msaa`).
    fn from_str(text: &str) -> Result<Self, String> {
        text.trim()
            .parse::<u32>()
            .ok()
            .and_then(Self::from_samples)
            .ok_or_else(|| format!("expected 1 (off), 2 or 4 samples per pixel, found `{text}`"))
    }
}

/// Whether the prepass's pixels of opaque, untextured materials are lit in one full-screen
/// pass instead of drawing those materials again in the lighting pass
/// ([`crate::render::deferred`]). Only where the frame allows it: the prepass runs and writes
/// normals (the visibility resolve is on), one sample per pixel, no analysis outputs, the
/// shipped forward shader; and only where some material is opaque and untextured (else there
/// is nothing for it to light).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DeferredLighting {
    /// On where it runs in compute (a target with a storage view: headless renders), which
    /// costs less than drawing any view's geometry again; elsewhere (a window) while the
    /// camera's view has at least as many triangles as the target has pixels
    /// ([`deferred_pays`]): then drawing the geometry again costs more than a full-screen
    /// render pass over the pixels.
    #[default]
    Auto,
    /// Always.
    On,
    /// Never: the lighting pass draws every material.
    Off,
}

/// Whether [`DeferredLighting::Auto`] lights the prepass's pixels in a full-screen render
/// pass for a view of `triangles` visible triangles on a target of `pixels` pixels.
pub fn deferred_pays(triangles: u64, pixels: u64) -> bool {
    triangles >= pixels
}

impl DeferredLighting {
    /// Whether it runs (where the frame allows it) for a view of `triangles` triangles on
    /// `pixels` pixels, in `compute` or in a full-screen render pass.
    pub fn runs(self, triangles: impl FnOnce() -> u64, pixels: u64, compute: bool) -> bool {
        match self {
            Self::On => true,
            Self::Off => false,
            Self::Auto => compute || deferred_pays(triangles(), pixels),
        }
    }
}

/// Render-wide switches; a world without this resource renders with the defaults.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// The depth prepass (default [`DepthPrepass::Auto`]). A forward material with its own
    /// vertex stage (instead of `penumbra::forward_io::forward_vertex`) must turn it off, or
    /// its pixels may not match the prepass depth.
    pub depth_prepass: DepthPrepass,
    /// Keep shadow maps whose view and casters did not change instead of drawing them again
    /// (default on). Off, every view is drawn every frame, as when everything moves: what
    /// the benchmark times.
    pub shadow_cache: bool,
    /// Evaluate every shadowed light's filter per pixel in a compute pass after the depth
    /// prepass, and let the lighting pass read the result (`penumbra::lights::
    /// shadow_visibility` does it for any material). Only when the prepass runs. Default on:
    /// on the H100 it takes the boxes scene's PCSS High frame from 5.59 to 2.64 ms (every map
    /// drawn) — fragment-shader filtering is far slower there than the same work in compute.
    pub visibility_resolve: bool,
    /// Render the cascades of a sun that must be drawn again in one multiview pass, one
    /// instanced draw per batch, where the device has `MULTIVIEW` (each cascade in its own
    /// pass elsewhere, or while off). Each instance is still drawn only into the cascades
    /// whose casters it is: the vertex stage drops it from the others. Default off: on the
    /// H100 it saved draw calls but no GPU time on small scenes and took the 100k field's
    /// shadow maps from 17.4 to 90.3 ms (every view runs the vertices of the whole list).
    /// lavapipe draws primitives its clipper splits into the pass's first layer, so casters
    /// crossing a cascade's bounds land in the wrong cascade there.
    pub single_pass_cascades: bool,
    /// Multisample anti-aliasing of the camera view (default [`Msaa::Off`]): the colour
    /// and depth the prepass and the lighting pass draw into have this many samples per
    /// pixel, resolved into the target. Where the adapter cannot multisample the target's
    /// format that many times, the largest count it can is used, with a logged warning. A
    /// renderer with analysis targets ([`Renderer::headless_with_analysis`](crate::render::Renderer::headless_with_analysis))
    /// always renders one sample per pixel, so every analysis pixel holds one surface's values
    /// (what the bench scores).
    pub msaa: Msaa,
    /// Record a pass's consecutive batches that bind nothing between them as one
    /// `multi_draw_indexed_indirect` (default on), where the device draws indirect with a
    /// first instance; off (or without it), one `draw_indexed` per batch.
    pub multi_draw: bool,
    /// Cull the camera view's instances hidden behind others on the GPU, in two phases
    /// around the depth prepass (default on; see [`crate::render::occlusion`]), for views of
    /// at least [`MIN_INSTANCES`](crate::render::occlusion::MIN_INSTANCES) instances. Where it
    /// runs (one sample per pixel, [`multi_draw`](Self::multi_draw) on, a device that draws
    /// indirect with a first instance) it turns the automatic prepass on.
    pub occlusion_culling: bool,
    /// Cull the camera view's instances one by one on the GPU (default on): the CPU then only
    /// tests culling chunks against the frustum and lists their runs
    /// ([`crate::ecs::camera_runs`]), for views whose chunks hold at least
    /// [`GPU_CAMERA_MIN_INSTANCES`](crate::ecs::camera_runs::GPU_CAMERA_MIN_INSTANCES); needs
    /// [`multi_draw`](Self::multi_draw) and a device that draws indirect with a first
    /// instance. The cascades' casters likewise in scenes of at least
    /// [`GPU_SHADOW_MIN_CASTERS`](crate::ecs::shadow_runs::GPU_SHADOW_MIN_CASTERS) casters
    /// ([`crate::ecs::shadow_runs`], [`crate::render::shadow_cull`]; not single-pass or
    /// clipmap cascades). Off, the CPU culls every instance and caster.
    pub gpu_culling: bool,
    /// Light the pixels of opaque, untextured materials from the depth prepass (its depth,
    /// normals and each pixel's instance) in one full-screen pass, and draw only the other
    /// materials again in the lighting pass (default [`DeferredLighting::Auto`]).
    pub deferred_lighting: DeferredLighting,
    /// Keep the depth prepass's depth, normals and shading ids from the last frame when
    /// nothing it draws changed (the camera, the target, the instances, the view's lists,
    /// meshes, materials, these options; no skinned mesh posed), one sample per pixel:
    /// the frame then draws no prepass (default on; see [`crate::render::prepass_keep`]).
    pub prepass_reuse: bool,
    /// Draw opaque shadow casters from each mesh's position-only index list, where every
    /// corner is the first vertex at its position (default on; see
    /// [`crate::mesh::position_indices`]): the same depth, from fewer vertices shaded (a
    /// box's 8 instead of 24). Off, they read the mesh's own indices.
    pub position_indices: bool,
    /// The depth format of the suns' cascade and clipmap layers (default
    /// [`SunDepth::Unorm16`]). Spot and point lights, whose perspective depth needs the
    /// float's precision near the light, and paged suns always draw 32-bit floats.
    pub sun_depth: SunDepth,
}

/// The depth format of a sun's cascade and clipmap layers ([`RenderOptions::sun_depth`]).
/// Their depth is linear in the distance along the light (an orthographic view), so 16 bits
/// step evenly through the view's depth range.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SunDepth {
    /// `Depth32Float`: for a sun whose cascades span kilometres of depth, where a 16-bit step
    /// would grow past a few centimetres.
    Float32,
    /// `Depth16Unorm` (the default): half the memory and the bandwidth of a layer's clear and its casters'
    /// depth writes; a depth rounds to one of 65 536 steps of the view's depth range, and the
    /// casters are drawn half a step further from the light so that rounding never brings one
    /// nearer ([`caster_clip_from_clip`](crate::render::shadows::casters::caster_clip_from_clip)).
    #[default]
    Unorm16,
}

impl SunDepth {
    /// Its texture format.
    pub fn format(self) -> wgpu::TextureFormat {
        match self {
            Self::Float32 => wgpu::TextureFormat::Depth32Float,
            Self::Unorm16 => wgpu::TextureFormat::Depth16Unorm,
        }
    }

    /// Bits per texel.
    pub fn bits(self) -> u32 {
        match self {
            Self::Float32 => 32,
            Self::Unorm16 => 16,
        }
    }
}

impl std::str::FromStr for SunDepth {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        match text.trim() {
            "32" => Ok(Self::Float32),
            "16" => Ok(Self::Unorm16),
            _ => Err(format!("expected 16 or 32 bits of sun shadow depth, found `{text}`")),
        }
    }
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            depth_prepass: DepthPrepass::Auto,
            shadow_cache: true,
            visibility_resolve: true,
            single_pass_cascades: false,
            msaa: Msaa::Off,
            multi_draw: true,
            occlusion_culling: true,
            gpu_culling: true,
            deferred_lighting: DeferredLighting::Auto,
            prepass_reuse: true,
            position_indices: true,
            sun_depth: SunDepth::Unorm16,
        }
    }
}

/// Whether [`DepthPrepass::Auto`] runs the prepass for a view of `triangles` visible
/// triangles on a target of `pixels` pixels.
pub fn prepass_pays(triangles: u64, pixels: u64) -> bool {
    triangles < pixels
}

impl DepthPrepass {
    /// Whether the prepass runs for a view of `triangles` triangles on `pixels` pixels.
    pub fn runs(self, triangles: impl FnOnce() -> u64, pixels: u64) -> bool {
        match self {
            Self::On => true,
            Self::Off => false,
            Self::Auto => prepass_pays(triangles(), pixels),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_runs_the_prepass_only_below_one_triangle_per_pixel() {
        let pixels = 1920 * 1080;
        assert!(DepthPrepass::Auto.runs(|| 60_000, pixels));
        assert!(!DepthPrepass::Auto.runs(|| 20_000_000, pixels));
        assert!(DepthPrepass::On.runs(|| u64::MAX, pixels));
        assert!(!DepthPrepass::Off.runs(|| 0, pixels));
    }

    #[test]
    fn auto_lights_from_the_prepass_in_compute_or_from_one_triangle_per_pixel() {
        let pixels = 1920 * 1080;
        assert!(!DeferredLighting::Auto.runs(|| 60_000, pixels, false));
        assert!(DeferredLighting::Auto.runs(|| pixels, pixels, false));
        assert!(DeferredLighting::Auto.runs(|| 6_000_000, pixels, false));
        assert!(DeferredLighting::Auto.runs(|| 0, pixels, true), "in compute always");
        assert!(DeferredLighting::On.runs(|| 0, pixels, false));
        assert!(!DeferredLighting::Off.runs(|| u64::MAX, pixels, true));
    }

    #[test]
    fn msaa_settings_round_trip_through_their_sample_counts() {
        for msaa in [Msaa::Off, Msaa::Sample2, Msaa::Sample4] {
            assert_eq!(Msaa::from_samples(msaa.samples()), Some(msaa));
        }
        assert_eq!("2".parse::<Msaa>(), Ok(Msaa::Sample2));
        assert!("3".parse::<Msaa>().unwrap_err().contains("`3`"));
        assert!("four".parse::<Msaa>().is_err());
        assert_eq!(Msaa::from_samples(3), None);
        assert_eq!(Msaa::from_samples(8), None);
        assert_eq!(RenderOptions::default().msaa, Msaa::Off);
    }

    #[test]
    fn sun_depth_parses_its_bits() {
        for depth in [SunDepth::Float32, SunDepth::Unorm16] {
            assert_eq!(depth.bits().to_string().parse::<SunDepth>(), Ok(depth));
        }
        assert_eq!(SunDepth::Unorm16.format(), wgpu::TextureFormat::Depth16Unorm);
        let default_bytes = crate::render::shadows::storage::depth_texel_bytes(SunDepth::default().format());
        assert_eq!(
            u64::from(default_bytes),
            crate::math::shadow_memory::DEFAULT_SUN_DEPTH_TEXEL_BYTES,
            "the budget's default sun texel is the default format's"
        );
        assert!("24".parse::<SunDepth>().unwrap_err().contains("`24`"));
    }

    #[test]
    fn msaa_falls_back_to_the_largest_supported_count_below_the_request() {
        let only = |counts: &'static [u32]| move |n: u32| counts.contains(&n);
        assert_eq!(Msaa::Sample4.fallback(only(&[2, 4])), Msaa::Sample4);
        assert_eq!(Msaa::Sample4.fallback(only(&[2])), Msaa::Sample2);
        assert_eq!(Msaa::Sample4.fallback(only(&[])), Msaa::Off);
        assert_eq!(Msaa::Sample2.fallback(only(&[4])), Msaa::Off, "never more than asked");
        assert_eq!(Msaa::Sample2.fallback(only(&[2, 4])), Msaa::Sample2);
        assert_eq!(Msaa::Off.fallback(only(&[2, 4])), Msaa::Off);
    }
}
