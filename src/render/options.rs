//! [`RenderOptions`]: how frames are rendered, as an ECS resource the application (or the
//! viewer's inspector) changes between frames.

use bevy_ecs::resource::Resource;

/// Render-wide switches; a world without this resource renders with the defaults.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// Write the camera's depth in a prepass before the lighting pass, so each covered pixel
    /// is shaded once (default on). A forward material with its own vertex stage (instead of
    /// `penumbra::forward_io::forward_vertex`) must turn it off, or its pixels may not match
    /// the prepass depth.
    pub depth_prepass: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self { depth_prepass: true }
    }
}
