//! The benchmark's results: one [`PresetResult`] per shadow technique preset, each with one
//! [`SceneResult`] per scene it applies to, gathered in a [`BenchReport`]; and
//! [`ScoredLight`], the light each scene's errors are scored against.
//! [`report`](crate::analysis::report) writes them as Markdown.

use serde::Serialize;

use crate::analysis::edges::EdgeSplit;
use crate::analysis::metrics::ErrorMetrics;
use crate::analysis::pareto::pareto_front;
use crate::analysis::shimmer::Shimmer;

/// The light a scene's errors are scored against, and so the reference they are scored with.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum ScoredLight {
    /// The scene's first directional light, against the visible fraction of its disc; its
    /// errors are also split by the cascade that shaded each pixel.
    Sun {
        /// Full angular diameter of the disc, degrees.
        angular_diameter: f32,
    },
    /// A spot light, against the visible fraction of its emitter sphere (casters count only
    /// between the point and the light); it has one shadow view, reported as cascade 0.
    Spot {
        /// Its number among the scene's spot lights, in the renderer's order.
        index: usize,
        /// Radius of the emitter sphere, metres.
        radius: f32,
    },
    /// A point light, against the visible fraction of its emitter sphere; its six cube faces
    /// are reported together as cascade 0.
    Point {
        /// Its number among the scene's point lights, in the renderer's order.
        index: usize,
        /// Radius of the emitter sphere, metres.
        radius: f32,
    },
}

impl ScoredLight {
    /// How many of the per-cascade columns can hold this light's errors: 4 for a sun (a
    /// cascade it does not have shows as empty), 1 for a spot or point light.
    pub fn views(&self) -> usize {
        match self {
            Self::Sun { .. } => 4,
            Self::Spot { .. } | Self::Point { .. } => 1,
        }
    }

    /// The light and its reference in words, e.g. "spot light 0, radius 0.25 m, against the
    /// sphere-light reference (...)".
    pub fn describe(&self) -> String {
        match *self {
            Self::Sun { angular_diameter } => format!(
                "the first sun, disc {angular_diameter:.2}°, against the sun-disc reference (the visible fraction of the disc)"
            ),
            Self::Spot { index, radius } => format!(
                "spot light {index}, radius {radius:.2} m, against the sphere-light reference (the visible fraction of the emitter sphere, casters only up to the light), over the points inside its shadow view"
            ),
            Self::Point { index, radius } => format!(
                "point light {index}, radius {radius:.2} m, against the sphere-light reference (the visible fraction of the emitter sphere, casters only up to the light), over the points within its range"
            ),
        }
    }
}

/// GPU time of one frame, from timestamp queries, averaged over the timed frames.
#[derive(Clone, Debug, Serialize)]
pub struct GpuTimes {
    /// The shadow passes (all cascades).
    pub shadow_ms: f64,
    /// The forward pass that samples the shadows.
    pub forward_ms: f64,
    /// The whole frame.
    pub total_ms: f64,
}

/// One preset's results on one scene.
#[derive(Clone, Debug, Serialize)]
pub struct SceneResult {
    /// The scene's name.
    pub scene: String,
    /// GPU time at the timing resolution.
    pub gpu: GpuTimes,
    /// CPU time of cascade fitting and culling per frame.
    pub cpu_ms: f64,
    /// Draw calls per frame (shadow and forward).
    pub draw_calls: u32,
    /// Memory of the shadow maps and their auxiliary textures.
    pub shadow_memory_bytes: u64,
    /// The light the errors are scored against.
    pub light: ScoredLight,
    /// Error against the reference over the analysed pixels.
    pub errors: ErrorMetrics,
    /// The same error split by the cascade that shaded each pixel (a spot light's one view is
    /// cascade 0; see [`ScoredLight::views`]).
    pub per_cascade: [ErrorMetrics; 4],
    /// Temporal stability while the camera translates.
    pub shimmer_translation: Shimmer,
    /// Temporal stability while the camera rotates.
    pub shimmer_rotation: Shimmer,
    /// The acne and leak rates split by their distance to a shadow edge of the reference:
    /// a shadow a texel off, or a surface shadowing itself.
    pub edges: EdgeSplit,
    /// The error of the image's own shadow factor (the resolved filter times contact
    /// shadows; [`errors`](Self::errors) filters the maps at the same points, without them).
    pub image_errors: ErrorMetrics,
    /// [`image_errors`](Self::image_errors) over the contact band: the analysed points within
    /// 0.3 m of a caster (on the side their normal faces), where a caster meets its receiver.
    pub contact_band: ErrorMetrics,
}

/// One shadow technique preset's results on every scene.
#[derive(Clone, Debug, Serialize)]
pub struct PresetResult {
    /// The preset's name.
    pub preset: String,
    /// What the preset does, in a line.
    pub description: String,
    /// One entry per scene the preset applies to.
    pub scenes: Vec<SceneResult>,
}

impl PresetResult {
    /// Total GPU ms per frame, mean over the scenes (NaN without scenes).
    pub fn mean_gpu_ms(&self) -> f64 {
        self.mean(|s| s.gpu.total_ms)
    }

    /// Penumbra MAE, mean over the scenes (NaN without scenes).
    pub fn mean_penumbra_mae(&self) -> f64 {
        self.mean(|s| s.errors.penumbra_mae)
    }

    /// Mean of `f` over the scenes; NaN without scenes.
    pub(crate) fn mean(&self, f: impl Fn(&SceneResult) -> f64) -> f64 {
        self.scenes.iter().map(f).sum::<f64>() / self.scenes.len() as f64
    }
}

/// A whole benchmark run: where it ran, at which settings, and every preset's results.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// The report's title.
    pub title: String,
    /// The GPU adapter's name.
    pub adapter: String,
    /// The driver's name and version.
    pub driver: String,
    /// The graphics API (Vulkan, Metal, DX12).
    pub backend: String,
    /// The source commit that was measured.
    pub commit: String,
    /// When it ran.
    pub date: String,
    /// Width of the timed frames.
    pub width: u32,
    /// Height of the timed frames.
    pub height: u32,
    /// Width of the frames compared with the reference.
    pub analysis_width: u32,
    /// Height of the frames compared with the reference.
    pub analysis_height: u32,
    /// How the reference was sampled, e.g. "1024 rays per pixel".
    pub reference_samples: String,
    /// Frames averaged per GPU timing.
    pub timing_frames: u32,
    /// One entry per preset.
    pub presets: Vec<PresetResult>,
    /// Free-form remarks, written as a bullet list.
    pub notes: Vec<String>,
}

impl BenchReport {
    /// For each preset, whether it is on the Pareto front of (mean GPU ms, mean penumbra MAE).
    pub fn pareto_front(&self) -> Vec<bool> {
        let points: Vec<(f64, f64)> = self
            .presets
            .iter()
            .map(|p| (p.mean_gpu_ms(), p.mean_penumbra_mae()))
            .collect();
        pareto_front(&points)
    }
}
