//! What a benchmark is asked to measure ([`BenchConfig`]) and what stops it ([`BenchError`]).

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::app::SpawnError;
use crate::bench::presets::Preset;
use crate::reference::ReferenceSettings;
use crate::render::{GpuError, SunDepth};
use crate::scene::SceneError;

/// Anything that stops a benchmark.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum BenchError {
    /// A scene file is invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A scene could not be spawned.
    #[error(transparent)]
    Spawn(#[from] SpawnError),
    /// No GPU.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// A scene has no light to score: neither a directional light nor a shadowed spot light.
    #[error("{0}: the benchmark needs a directional light, or a shadowed spot light and no directional light")]
    NoLight(String),
}

/// What to measure.
#[derive(Clone, Debug)]
pub struct BenchConfig {
    /// Scene files.
    pub scenes: Vec<PathBuf>,
    /// Presets to score.
    pub presets: Vec<Preset>,
    /// Resolution of the GPU timings.
    pub width: u32,
    /// Resolution of the GPU timings.
    pub height: u32,
    /// Resolution at which errors are scored against the reference.
    pub analysis_width: u32,
    /// Resolution at which errors are scored against the reference.
    pub analysis_height: u32,
    /// Frames timed per preset (after `warmup_frames`).
    pub timing_frames: u32,
    /// Frames rendered before timing.
    pub warmup_frames: u32,
    /// Reference ray budget.
    pub reference: ReferenceSettings,
    /// Camera poses per stability path.
    pub shimmer_steps: u32,
    /// Most world points followed for stability.
    pub max_probes: usize,
    /// Show progress bars.
    pub progress: bool,
    /// The virtual clipmap's levels and pool in the presets that page the sun (None: the
    /// presets' own).
    pub pages: Option<PagesOverride>,
    /// The depth format of the suns' cascade and clipmap layers, timed and scored.
    pub sun_depth: SunDepth,
}

/// What the paged presets' virtual clipmap is given instead of its defaults.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PagesOverride {
    /// Texels per side of each level.
    pub virtual_resolution: Option<u32>,
    /// Pages of the pool.
    pub pool_pages: Option<u32>,
}

/// A scene's short name in progress lines and reports: its file stem.
pub(crate) fn short(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| path.display().to_string(), |s| s.to_string_lossy().to_string())
}
