//! The egui inspector: the sun, every shadow setting (with the ranges of the runtime table),
//! the debug views, a panel per spot light and extra sun, play and speed of the animated
//! meshes, per-view statistics, the
//! shadow-memory budget and account, GPU and CPU timings with a history plot,
//! and "save settings to RON". It edits the ECS world directly, so it runs the same with a
//! window or headless (the tests drive it through egui's accessibility tree).

mod animation;
mod lights;
mod memory;
mod render;
mod settings;
mod stats;
mod sun;

use std::path::{Path, PathBuf};

use bevy_ecs::world::World;
use egui::{Button, CollapsingHeader, Color32, Slider, Ui};

use crate::ecs::components::DirectionalLight;
use crate::ecs::light_views::FrameLights;
use crate::ecs::stats::{ShadowDiagnostics, ShadowStats};
use crate::ecs::view_list::ShadowViews;
use crate::ecs::view_lod::CameraLod;
use crate::render::{FrameReport, RenderOptions};
use crate::scene::save_settings;
use crate::settings::ShadowSettings;
use crate::viewer::fly_camera::FlyCamera;
use crate::viewer::history::{FrameSample, TimingHistory};

/// Frames kept for the timing plot.
const HISTORY_FRAMES: usize = 240;

/// What the inspector shows about the last frame besides the world.
#[derive(Clone, Debug, Default)]
pub struct FrameInfo<'a> {
    /// The renderer's report of the last frame.
    pub report: Option<&'a FrameReport>,
    /// Errors to show in red (a rejected reload, a failed pipeline build).
    pub errors: &'a [String],
}

/// The inspector's own state: the timing history and where settings are saved.
#[derive(Debug)]
pub struct Inspector {
    history: TimingHistory,
    /// Where "save settings" writes.
    pub settings_path: PathBuf,
    /// The result of the last save, for the status line.
    status: Option<Result<String, String>>,
}

impl Inspector {
    /// An inspector that saves settings to `settings_path`.
    pub fn new(settings_path: impl Into<PathBuf>) -> Self {
        Self {
            history: TimingHistory::new(HISTORY_FRAMES),
            settings_path: settings_path.into(),
            status: None,
        }
    }

    /// The timing history (one sample per [`record`](Self::record)).
    pub fn history(&self) -> &TimingHistory {
        &self.history
    }

    /// Adds one rendered frame to the timing history.
    pub fn record(&mut self, report: &FrameReport, stats: &ShadowStats) {
        let ms = |d: std::time::Duration| d.as_secs_f32() * 1e3;
        self.history.push(FrameSample {
            gpu_ms: report.passes.iter().map(|p| p.ms as f32).sum(),
            cpu_ms: ms(stats.cascades_cpu) + ms(stats.culling_cpu) + ms(stats.view_culling_cpu),
        });
    }

    /// Draws the inspector and writes edits back to the world (the sun's components and its
    /// [`ShadowSettings`]); `camera` adds the free camera's speed control.
    pub fn ui(&mut self, ui: &mut Ui, world: &mut World, frame: &FrameInfo<'_>, camera: Option<&mut FlyCamera>) {
        for error in frame.errors {
            ui.colored_label(Color32::from_rgb(255, 110, 100), error);
        }
        if let Some(camera) = camera {
            ui.add(
                Slider::new(&mut camera.speed, 0.5..=200.0)
                    .logarithmic(true)
                    .text("camera speed m/s"),
            );
        }
        CollapsingHeader::new("Sun").default_open(true).show(ui, |ui| {
            if !sun::sun_ui(ui, world) {
                ui.label("no directional light");
            }
        });
        CollapsingHeader::new("Shadows").default_open(true).show(ui, |ui| {
            self.settings_section(ui, world);
        });
        CollapsingHeader::new("Lights").default_open(true).show(ui, |ui| {
            if lights::lights_ui(ui, world) == 0 {
                ui.label("no spot light or second sun");
            }
        });
        CollapsingHeader::new("Animation").default_open(false).show(ui, |ui| {
            animation::animation_ui(ui, world);
        });
        CollapsingHeader::new("Rendering").default_open(true).show(ui, |ui| {
            if let Some(mut options) = world.get_resource_mut::<RenderOptions>() {
                // NOTE: edited on a copy, so the resource changes only when a switch does.
                let mut edited = *options;
                if render::render_options_ui(ui, &mut edited) {
                    *options = edited;
                }
            }
            if let Some(mut lod) = world.get_resource_mut::<CameraLod>() {
                let mut edited = *lod;
                if render::camera_lod_ui(ui, &mut edited) {
                    *lod = edited;
                }
            }
        });
        CollapsingHeader::new("Shadow views").default_open(true).show(ui, |ui| {
            stats::shadow_views_ui(
                ui,
                world.resource::<FrameLights>(),
                world.resource::<ShadowViews>(),
                world.resource::<ShadowStats>(),
            );
        });
        CollapsingHeader::new("Shadow memory")
            .default_open(true)
            .show(ui, |ui| {
                memory::memory_ui(ui, world);
            });
        CollapsingHeader::new("Timings").default_open(true).show(ui, |ui| {
            let empty = FrameReport::default();
            let report = frame.report.unwrap_or(&empty);
            stats::timings_ui(ui, report, world.resource::<ShadowStats>(), &self.history);
        });
        for warning in &world.resource::<ShadowDiagnostics>().current {
            ui.colored_label(Color32::YELLOW, warning);
        }
    }

    /// The settings controls of the first shadowed light, and the save button.
    fn settings_section(&mut self, ui: &mut Ui, world: &mut World) {
        let mut query = world.query::<(&DirectionalLight, &mut ShadowSettings)>();
        let Some((_, mut settings)) = query.iter_mut(world).next() else {
            ui.label("the light has no ShadowSettings");
            return;
        };
        // NOTE: edit a copy and write back only on change, so change detection (and the
        // renderer) only sees real edits.
        let mut edited = *settings;
        settings::settings_ui(ui, &mut edited);
        if edited != *settings {
            *settings = edited;
        }
        let save = ui
            .add(Button::new("save settings"))
            .on_hover_text(self.settings_path.display().to_string());
        if save.clicked() {
            self.status = Some(save_to(&self.settings_path, &edited));
        }
        match &self.status {
            Some(Ok(message)) => {
                ui.label(message);
            }
            Some(Err(message)) => {
                ui.colored_label(Color32::from_rgb(255, 110, 100), message);
            }
            None => {}
        }
    }
}

fn save_to(path: &Path, settings: &ShadowSettings) -> Result<String, String> {
    save_settings(path, settings)
        .map(|()| format!("saved to {}", path.display()))
        .map_err(|e| e.to_string())
}
