//! Frame statistics (CPU timings, casters per cascade) and diagnostics (warnings about bad
//! input that was repaired), both readable by tools, tests and the inspector.

use std::time::Duration;

use bevy_ecs::resource::Resource;
use log::warn;

use crate::settings::MAX_CASCADES;

/// What the shadow systems did in the last frame.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct ShadowStats {
    /// CPU time of cascade computation.
    pub cascades_cpu: Duration,
    /// CPU time of per-cascade caster culling and draw-group building.
    pub culling_cpu: Duration,
    /// CPU time of camera culling.
    pub view_culling_cpu: Duration,
    /// Casters drawn into each cascade.
    pub casters_per_cascade: [u32; MAX_CASCADES],
    /// Draw calls issued for each cascade.
    pub draws_per_cascade: [u32; MAX_CASCADES],
    /// Instances the camera sees.
    pub visible_instances: u32,
    /// Frames run so far.
    pub frames: u64,
}

/// Warnings about input that was repaired or skipped. Each distinct message is logged once,
/// the first frame it appears; `current` holds those of the last frame.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct ShadowDiagnostics {
    /// Warnings raised during the last frame.
    pub current: Vec<String>,
    logged: Vec<String>,
}

impl ShadowDiagnostics {
    /// Starts a frame: forgets the previous frame's warnings (not which were logged).
    pub fn begin_frame(&mut self) {
        self.current.clear();
    }

    /// Records a warning, logging it if it is new.
    pub fn warn(&mut self, message: String) {
        if !self.logged.contains(&message) {
            warn!("{message}");
            self.logged.push(message.clone());
        }
        self.current.push(message);
    }
}
