//! The egui inspector: every shadow setting of the sun, the sun's direction and size, and
//! the last frame's statistics and GPU timings.

use bevy_ecs::world::World;
use egui::{ComboBox, Slider, Ui};
use glam::Vec3;

use crate::ecs::components::{DirectionalLight, Transform};
use crate::ecs::stats::{ShadowDiagnostics, ShadowStats};
use crate::render::FrameReport;
use crate::settings::{CascadeFit, PcssQuality, ShadowDebugView, ShadowMode, ShadowSettings};

/// Sun direction as azimuth and elevation, in degrees, for the sliders.
fn sun_angles(direction: Vec3) -> (f32, f32) {
    let to_sun = -direction.normalize_or(Vec3::NEG_Y);
    let elevation = to_sun.y.clamp(-1.0, 1.0).asin().to_degrees();
    let azimuth = to_sun.x.atan2(to_sun.z).to_degrees();
    (azimuth, elevation)
}

/// Direction the light travels for an azimuth and elevation in degrees.
fn sun_direction(azimuth: f32, elevation: f32) -> Vec3 {
    let (a, e) = (azimuth.to_radians(), elevation.to_radians());
    -Vec3::new(e.cos() * a.sin(), e.sin(), e.cos() * a.cos())
}

/// Draws the inspector and writes changes back to the sun's components.
pub fn inspector_ui(ui: &mut Ui, world: &mut World, report: &FrameReport) {
    let mut query = world.query::<(&mut DirectionalLight, &mut Transform, Option<&mut ShadowSettings>)>();
    if let Some((mut light, mut transform, settings)) = query.iter_mut(world).next() {
        ui.heading("Sun");
        let (mut azimuth, mut elevation) = sun_angles(transform.forward());
        let mut changed = ui
            .add(Slider::new(&mut azimuth, -180.0..=180.0).text("azimuth °"))
            .changed();
        changed |= ui
            .add(Slider::new(&mut elevation, -5.0..=90.0).text("elevation °"))
            .changed();
        if changed {
            *transform = Transform::default().looking_at(sun_direction(azimuth, elevation), Vec3::Y);
        }
        let mut diameter = light.angular_diameter.to_degrees();
        if ui
            .add(Slider::new(&mut diameter, 0.1..=5.0).text("angular diameter °"))
            .changed()
        {
            light.angular_diameter = diameter.to_radians();
        }
        ui.checkbox(&mut light.shadows_enabled, "casts shadows");
        if let Some(mut settings) = settings {
            ui.separator();
            settings_ui(ui, &mut settings);
        }
    } else {
        ui.label("no directional light");
    }
    ui.separator();
    stats_ui(ui, world.resource::<ShadowStats>(), report);
    let warnings = &world.resource::<ShadowDiagnostics>().current;
    for w in warnings {
        ui.colored_label(egui::Color32::YELLOW, w);
    }
}

fn settings_ui(ui: &mut Ui, s: &mut ShadowSettings) {
    ui.heading("Shadows");
    ComboBox::from_label("mode")
        .selected_text(format!("{:?}", s.mode))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut s.mode, ShadowMode::Pcf, "PCF");
            ui.selectable_value(&mut s.mode, ShadowMode::Pcss, "PCSS");
        });
    match s.mode {
        ShadowMode::Pcf => {
            ui.add(Slider::new(&mut s.pcf_radius, 0..=5).text("PCF radius"));
        }
        ShadowMode::Pcss => {
            ComboBox::from_label("PCSS quality")
                .selected_text(format!("{:?}", s.pcss_quality))
                .show_ui(ui, |ui| {
                    for q in [PcssQuality::Low, PcssQuality::Medium, PcssQuality::High] {
                        ui.selectable_value(&mut s.pcss_quality, q, format!("{q:?}"));
                    }
                });
            ui.checkbox(&mut s.blocker_early_out, "blocker early-out");
            ui.checkbox(&mut s.temporal_rotation, "temporal rotation");
        }
    }
    ui.checkbox(&mut s.receiver_plane_bias, "receiver-plane bias");
    ui.add(Slider::new(&mut s.cascade_count, 1..=4).text("cascades"));
    ComboBox::from_label("resolution")
        .selected_text(s.resolution.to_string())
        .show_ui(ui, |ui| {
            for r in [512, 1024, 2048, 4096] {
                ui.selectable_value(&mut s.resolution, r, r.to_string());
            }
        });
    ComboBox::from_label("fit")
        .selected_text(format!("{:?}", s.fit))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut s.fit, CascadeFit::Tight, "Tight");
            ui.selectable_value(&mut s.fit, CascadeFit::Stable, "Stable");
        });
    ui.add(Slider::new(&mut s.split_lambda, 0.0..=1.0).text("split λ"));
    ui.add(
        Slider::new(&mut s.max_distance, 1.0..=2000.0)
            .logarithmic(true)
            .text("max distance"),
    );
    ui.add(Slider::new(&mut s.slope_bias, 0.0..=10.0).text("slope bias"));
    ui.add(Slider::new(&mut s.bias_clamp, 0.0..=0.05).text("bias clamp"));
    ui.add(Slider::new(&mut s.normal_offset, 0.0..=5.0).text("normal offset"));
    ui.add(Slider::new(&mut s.blend_width, 0.0..=0.5).text("cascade blend"));
    ui.add(Slider::new(&mut s.distance_fade_width, 0.0..=0.5).text("distance fade"));
    ui.checkbox(&mut s.depth_clamp, "depth clamp");
    let mut debug = s.debug_view == ShadowDebugView::Cascades;
    if ui.checkbox(&mut debug, "debug: cascade colours").changed() {
        s.debug_view = if debug {
            ShadowDebugView::Cascades
        } else {
            ShadowDebugView::None
        };
    }
}

fn stats_ui(ui: &mut Ui, stats: &ShadowStats, report: &FrameReport) {
    ui.heading("Frame");
    ui.label(format!(
        "CPU: cascades {:.3} ms, culling {:.3} ms, view {:.3} ms",
        stats.cascades_cpu.as_secs_f64() * 1e3,
        stats.culling_cpu.as_secs_f64() * 1e3,
        stats.view_culling_cpu.as_secs_f64() * 1e3
    ));
    ui.label(format!("casters per cascade {:?}", stats.casters_per_cascade));
    ui.label(format!(
        "draw calls {}, visible {}",
        report.draw_calls, stats.visible_instances
    ));
    ui.label(format!(
        "shadow memory {:.1} MiB",
        report.shadow_memory as f64 / (1024.0 * 1024.0)
    ));
    for p in &report.passes {
        ui.label(format!("GPU {:<17} {:7.3} ms", p.name, p.ms));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sun_angles_round_trip() {
        for (a, e) in [(30.0, 45.0), (-120.0, 10.0), (0.0, 89.0)] {
            let (a2, e2) = sun_angles(sun_direction(a, e));
            assert!((a - a2).abs() < 1e-3 && (e - e2).abs() < 1e-3, "{a} {e} -> {a2} {e2}");
        }
    }
}
