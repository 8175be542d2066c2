//! The viewer: a window on a scene with a fly camera (drag with the right mouse button to
//! look, W/A/S/D/Q/E to move, Shift for speed) and an egui inspector that edits every shadow
//! setting live, and live reload of the scene and settings files. The window and the
//! inspector need the `viewer` feature (on by default); the camera control and the reload
//! logic are always built (and tested).

#[cfg(feature = "viewer")]
mod args;
pub mod exercise;
pub mod fly_camera;
pub mod history;
#[cfg(feature = "viewer")]
pub mod inspector;
#[cfg(feature = "viewer")]
mod options;
#[cfg(feature = "viewer")]
mod presenter;
pub mod reload;
#[cfg(feature = "viewer")]
mod surface;
#[cfg(feature = "viewer")]
mod window;

#[cfg(feature = "viewer")]
pub use args::ViewerArgs;
pub use fly_camera::{FlyCamera, MoveKeys};
#[cfg(feature = "viewer")]
pub use inspector::{FrameInfo, Inspector};
#[cfg(feature = "viewer")]
pub use options::{ViewerError, ViewerOptions, ViewerSummary};
pub use reload::{LiveReload, ReloadOutcome};
#[cfg(feature = "viewer")]
pub use window::{default_settings_path, run};
