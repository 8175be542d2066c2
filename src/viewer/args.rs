//! Command-line arguments of the viewer, shared by `penumbra view` and
//! `cargo run --example viewer`.

use std::path::PathBuf;

use clap::Args;

use crate::render::Msaa;
use crate::render::limits::MAX_TEXTURE_SIDE;
use crate::viewer::options::ViewerOptions;

/// Arguments of the viewer.
#[derive(Args, Clone, Debug)]
pub struct ViewerArgs {
    /// Scene file (RON); edits to it are applied live.
    pub scene: PathBuf,
    /// Shadow settings file (RON) applied over the scene's and watched for edits; "save
    /// settings" writes here. Default: `<scene>.settings.ron`.
    #[arg(long)]
    pub settings: Option<PathBuf>,
    /// A material's own forward shader (WGSL that may `#import penumbra::lights`), watched for
    /// edits; a broken edit keeps the last good pipeline.
    #[arg(long)]
    pub shader: Option<PathBuf>,
    /// Window width.
    #[arg(long, default_value_t = 1600, value_parser = side())]
    pub width: u32,
    /// Window height.
    #[arg(long, default_value_t = 900, value_parser = side())]
    pub height: u32,
    /// Close after this many frames.
    #[arg(long)]
    pub exit_after: Option<u32>,
    /// Write the last frame, inspector included, to this PNG (with `--exit-after`).
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Run the scripted robustness steps: resize, minimise and restore, a lost surface,
    /// settings changes that recreate GPU resources.
    #[arg(long)]
    pub exercise: bool,
    /// Samples per pixel (MSAA): 1 (off), 2 or 4; falls back, with a warning, to what the
    /// GPU supports. The inspector changes it live.
    #[arg(long, default_value = "1")]
    pub msaa: Msaa,
    /// Draw into an offscreen image made like a window's (plain BGRA, drawn through its sRGB
    /// view) instead of a window, for machines without a display: the same frames, inspector
    /// included, unpresented; prints how long they took. Needs `--exit-after`.
    #[arg(long, requires = "exit_after")]
    pub offscreen: bool,
    /// Move the camera this many metres forward every frame, level, the way it faces
    /// (0.001-1000): a scripted walk, as `render --camera-step` for the viewer.
    #[arg(long, value_parser = walk)]
    pub walk: Option<f32>,
}

/// Metres per frame `--walk` accepts: 0.001 to 1000.
fn walk(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(m) if (0.001..=1000.0).contains(&m) => Ok(m),
        _ => Err(format!("expected metres from 0.001 to 1000, found `{text}`")),
    }
}

/// Window sides accepted: 1 to the largest texture side of any adapter (the surface is
/// clamped to the device's own limit).
fn side() -> clap::builder::RangedI64ValueParser<u32> {
    clap::value_parser!(u32).range(1..=MAX_TEXTURE_SIDE as i64)
}

impl ViewerArgs {
    /// The viewer options these arguments ask for.
    pub fn options(&self) -> ViewerOptions {
        ViewerOptions {
            width: self.width,
            height: self.height,
            exit_after: self.exit_after,
            screenshot: self.screenshot.clone(),
            settings: self.settings.clone(),
            shader: self.shader.clone(),
            exercise: self.exercise,
            msaa: self.msaa,
            offscreen: self.offscreen,
            walk: self.walk,
        }
    }
}
