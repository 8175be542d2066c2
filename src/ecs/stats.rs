//! Frame statistics (CPU timings, casters per cascade) and diagnostics (warnings about bad
//! input that was repaired), both readable by tools, tests and the inspector.

use std::time::Duration;

use bevy_ecs::resource::Resource;
use log::warn;

/// What the shadow systems did in the last frame.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct ShadowStats {
    /// CPU time of collecting the lights and computing their shadow views (cascades, spot
    /// views).
    pub cascades_cpu: Duration,
    /// CPU time of per-view caster culling and draw-group building.
    pub culling_cpu: Duration,
    /// CPU time of camera culling.
    pub view_culling_cpu: Duration,
    /// Casters drawn into each shadow view, in the order of
    /// [`ShadowViews`](crate::ecs::shadow_views::ShadowViews).
    pub casters_per_view: Vec<u32>,
    /// Draw calls issued for each shadow view.
    pub draws_per_view: Vec<u32>,
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
