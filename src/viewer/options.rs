//! What a viewer run is asked to do ([`ViewerOptions`]), what it did ([`ViewerSummary`]),
//! and why it can stop ([`ViewerError`]).

use std::path::PathBuf;

use thiserror::Error;

use crate::app::SpawnError;
use crate::render::{GpuError, Msaa};
use crate::scene::SceneError;

/// Why the viewer stopped with an error.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ViewerError {
    /// The window system is not available.
    #[error("cannot open a window: {0}")]
    Window(String),
    /// No GPU.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// The scene or settings file is invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The scene could not be spawned.
    #[error(transparent)]
    Spawn(#[from] SpawnError),
    /// The options contradict each other.
    #[error("invalid viewer options: {0}")]
    Options(String),
    /// The screenshot could not be written.
    #[error("cannot write the screenshot `{path}`: {message}")]
    Screenshot {
        /// Output path.
        path: String,
        /// Why.
        message: String,
    },
}

impl ViewerError {
    /// A [`ViewerError::Screenshot`] for `path`.
    pub fn screenshot(path: &std::path::Path, message: impl Into<String>) -> Self {
        ViewerError::Screenshot {
            path: path.display().to_string(),
            message: message.into(),
        }
    }
}

/// Viewer options.
#[derive(Clone, Debug)]
pub struct ViewerOptions {
    /// Initial window width.
    pub width: u32,
    /// Initial window height.
    pub height: u32,
    /// Close after this many rendered frames (for scripted runs).
    pub exit_after: Option<u32>,
    /// Write the last frame (scene and inspector) to this PNG before closing.
    pub screenshot: Option<PathBuf>,
    /// Shadow settings file applied over the scene's and watched for edits; "save settings"
    /// writes here too. Default: `<scene>.settings.ron` (used for saving only, unless it
    /// exists).
    pub settings: Option<PathBuf>,
    /// A forward (material) shader to use instead of the shipped one, watched for edits.
    pub shader: Option<PathBuf>,
    /// Run the scripted robustness steps (resize, minimise, lost surface, settings changes).
    pub exercise: bool,
    /// Samples per pixel to start with (the inspector's "MSAA" changes it).
    pub msaa: Msaa,
    /// Draw into an offscreen frame made like a swapchain image instead of a window (for
    /// machines without a display); needs `exit_after`.
    pub offscreen: bool,
    /// Move the camera this many metres forward (where it looks) every frame.
    pub walk: Option<f32>,
}

impl Default for ViewerOptions {
    fn default() -> Self {
        Self {
            width: 1280,
            height: 720,
            exit_after: None,
            screenshot: None,
            settings: None,
            shader: None,
            exercise: false,
            msaa: Msaa::default(),
            offscreen: false,
            walk: None,
        }
    }
}

/// What a viewer run did, for scripted runs and tests.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ViewerSummary {
    /// Frames drawn and presented.
    pub frames: u32,
    /// Event-loop ticks (frames drawn plus frames skipped).
    pub ticks: u32,
    /// Times the surface was reconfigured after an error.
    pub surface_recoveries: u32,
    /// The screenshot written, if any.
    pub screenshot: Option<PathBuf>,
    /// The adapter used.
    pub adapter: String,
    /// Errors shown in the inspector on the last tick (rejected reloads, shader errors).
    pub errors: Vec<String>,
    /// In a run with a frame count (`exit_after`), the GPU time of the newest timed frame
    /// after each frame drawn, ms (the sum of its timed passes; 0 until a frame's timings
    /// have arrived); empty otherwise.
    pub gpu_ms: Vec<f32>,
    /// Offscreen: the wall time from the first frame's start to the GPU finishing the last.
    pub elapsed: std::time::Duration,
}

impl ViewerSummary {
    /// The median of [`gpu_ms`](Self::gpu_ms) over the frames after the first `skip` (None
    /// without such frames).
    pub fn median_gpu_ms(&self, skip: usize) -> Option<f32> {
        let mut ms: Vec<f32> = self.gpu_ms.iter().skip(skip).copied().filter(|m| *m > 0.0).collect();
        ms.sort_by(f32::total_cmp);
        ms.get(ms.len() / 2).copied()
    }
}
