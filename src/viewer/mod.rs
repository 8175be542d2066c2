//! The viewer: a window on a scene with a fly camera (drag with the right mouse button to
//! look, W/A/S/D/Q/E to move, Shift for speed) and an egui inspector that edits every shadow
//! setting live. The window itself needs the `viewer` feature; the camera control is plain
//! math and always built (and tested).

pub mod fly_camera;
#[cfg(feature = "viewer")]
mod inspector;
#[cfg(feature = "viewer")]
mod window;

pub use fly_camera::{FlyCamera, MoveKeys};
#[cfg(feature = "viewer")]
pub use window::{ViewerError, ViewerOptions, run};
