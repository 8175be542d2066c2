//! Frame statistics (CPU timings, casters per cascade) and diagnostics (warnings about bad
//! input that was repaired), both readable by tools, tests and the inspector.

use std::collections::{HashMap, HashSet};
use std::time::{Duration, Instant};

use bevy_ecs::resource::Resource;
use bevy_ecs::system::{Res, ResMut};
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
    /// CPU time of all the shadow systems of the frame, from transform propagation to the
    /// end of culling ([`ShadowSystems`](crate::ecs::plugin::ShadowSystems)).
    pub frame_cpu: Duration,
    /// Casters drawn into each shadow view, in the order of
    /// [`ShadowViews`](crate::ecs::view_list::ShadowViews) (for a view the GPU culls, the
    /// casters of its runs, which it tests).
    pub casters_per_view: Vec<u32>,
    /// Draw calls issued for each shadow view.
    pub draws_per_view: Vec<u32>,
    /// Instances the camera sees.
    pub visible_instances: u32,
    /// Frames run so far.
    pub frames: u64,
}

/// When this frame's shadow systems started (see [`ShadowStats::frame_cpu`]).
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct FrameClock(Option<Instant>);

/// Starts [`FrameClock`] (before transform propagation).
pub fn start_frame_clock(mut clock: ResMut<FrameClock>) {
    clock.0 = Some(Instant::now());
}

/// Stops [`FrameClock`] into [`ShadowStats::frame_cpu`] (after culling).
pub fn stop_frame_clock(clock: Res<FrameClock>, mut stats: ResMut<ShadowStats>) {
    if let Some(start) = clock.0 {
        stats.frame_cpu = start.elapsed();
    }
}

/// Most entity names a grouped warning lists.
const GROUP_NAMES: usize = 4;
/// Most distinct messages remembered as logged; past it the memory starts again (a message
/// may then be logged a second time).
const MAX_LOGGED: usize = 4096;

/// Warnings about input that was repaired or skipped. A frame's warnings are logged together
/// after the shadow systems ([`flush`](Self::flush)), each distinct message once. The same
/// warning about many entities is one line: the first entity's message, then how many more
/// and the first few of their names; a message repeated word for word is counted.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct ShadowDiagnostics {
    /// Warnings raised during the last frame, grouped.
    pub current: Vec<String>,
    /// This frame's groups, one per entry of `current`, and where each shape is.
    groups: Vec<Group>,
    shapes: HashMap<String, usize>,
    logged: HashSet<String>,
}

/// Warnings that differ only in the entity they name.
#[derive(Clone, Debug, PartialEq)]
struct Group {
    first: String,
    names: Vec<String>,
    count: usize,
}

impl Group {
    fn text(&self) -> String {
        match (self.count, self.names.is_empty()) {
            (1, _) => self.first.clone(),
            (n, true) => format!("{} ({n} times)", self.first),
            (n, false) => {
                let more = n - 1;
                let listed = self.names.join(", ");
                let rest = more - self.names.len();
                let tail = if rest > 0 {
                    format!(" and {rest} others")
                } else {
                    String::new()
                };
                format!("{} (the same for {more} more: {listed}{tail})", self.first)
            }
        }
    }
}

impl ShadowDiagnostics {
    /// Starts a frame: forgets the previous frame's warnings (not which were logged).
    pub fn begin_frame(&mut self) {
        self.current.clear();
        self.groups.clear();
        self.shapes.clear();
    }

    /// Records a warning (counted when the frame already has it word for word).
    pub fn warn(&mut self, message: String) {
        self.record(message.clone(), None, message);
    }

    /// Records a warning about the entity named `name` (its display form, which `message`
    /// contains): warnings that differ only in that name are grouped.
    pub fn warn_about(&mut self, name: &str, message: String) {
        let shape = message.replacen(name, "\u{1}", 1);
        self.record(shape, Some(name), message);
    }

    fn record(&mut self, shape: String, name: Option<&str>, message: String) {
        if let Some(&i) = self.shapes.get(&shape) {
            let group = &mut self.groups[i];
            group.count += 1;
            if let Some(name) = name.filter(|_| group.names.len() < GROUP_NAMES) {
                group.names.push(name.to_owned());
            }
            self.current[i] = group.text();
            return;
        }
        self.shapes.insert(shape, self.groups.len());
        self.groups.push(Group {
            first: message.clone(),
            names: Vec::new(),
            count: 1,
        });
        self.current.push(message);
    }

    /// Logs this frame's warnings that were not logged before.
    pub fn flush(&mut self) {
        for message in &self.current {
            if self.logged.len() >= MAX_LOGGED {
                self.logged.clear();
            }
            // NOTE: checked first, so a message already logged costs no copy each frame.
            if !self.logged.contains(message) {
                warn!("{message}");
                self.logged.insert(message.clone());
            }
        }
    }
}

/// Logs the frame's warnings ([`ShadowDiagnostics::flush`]), after the shadow systems.
pub fn log_diagnostics(mut diagnostics: ResMut<ShadowDiagnostics>) {
    diagnostics.flush();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warnings_about_many_entities_are_one_line_with_a_count_and_the_first_names() {
        let mut d = ShadowDiagnostics::default();
        for i in 0..10 {
            d.warn_about(&format!("{i}v0"), format!("spot light {i}v0 gets no shadow"));
        }
        d.warn_about("3v1", "point light 3v1 has range 0".to_string());
        for _ in 0..3 {
            d.warn("shadow settings: pcf_radius 9; clamped".to_string());
        }
        assert_eq!(
            d.current,
            [
                "spot light 0v0 gets no shadow (the same for 9 more: 1v0, 2v0, 3v0, 4v0 and 5 others)",
                "point light 3v1 has range 0",
                "shadow settings: pcf_radius 9; clamped (3 times)",
            ]
        );
        d.begin_frame();
        d.warn_about("1v0", "spot light 1v0 gets no shadow".to_string());
        d.warn_about("2v0", "spot light 2v0 gets no shadow".to_string());
        assert_eq!(d.current, ["spot light 1v0 gets no shadow (the same for 1 more: 2v0)"]);
    }
}
