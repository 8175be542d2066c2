//! The statistics sections: per shadow view its range, texel density and casters drawn; GPU
//! and CPU timings per pass with a small history plot.

use egui::{Color32, Grid, Sense, Stroke, Ui, pos2, vec2};

use crate::ecs::light_views::FrameLights;
use crate::ecs::stats::ShadowStats;
use crate::ecs::view_list::ShadowViews;
use crate::render::FrameReport;
use crate::render::shadows::depth_pass::view_name;
use crate::viewer::history::TimingHistory;

/// GPU-time line colour in the plot.
const GPU_COLOR: Color32 = Color32::from_rgb(110, 190, 255);
/// CPU-time line colour in the plot.
const CPU_COLOR: Color32 = Color32::from_rgb(255, 170, 80);

/// One row per shadow view: its light, what it covers (a cascade's view-depth range, a spot
/// light's near and far planes), shadow texels per metre, casters drawn.
pub(crate) fn shadow_views_ui(ui: &mut Ui, lights: &FrameLights, views: &ShadowViews, stats: &ShadowStats) {
    if views.views.is_empty() {
        ui.label("no shadowed light in view");
        return;
    }
    let mut name = String::new();
    Grid::new("shadow view stats").striped(true).show(ui, |ui| {
        ui.label("view");
        ui.label("range m");
        ui.label("texels/m");
        ui.label("casters");
        ui.end_row();
        for (i, view) in views.views.iter().enumerate() {
            view_name(lights, view, &mut name);
            ui.label(name.trim_start_matches("shadow "));
            let shading = &view.shading;
            let (range, texel) = ((shading.near, shading.far), shading.texel_world_size);
            ui.label(format!("{:.1} – {:.1}", range.0, range.1));
            let density = if texel > 0.0 {
                format!("{:.1}", 1.0 / texel)
            } else {
                "—".to_string()
            };
            ui.label(density);
            ui.label(stats.casters_per_view.get(i).copied().unwrap_or(0).to_string());
            ui.end_row();
        }
    });
}

/// GPU passes, CPU systems and the plot of the last frames.
pub(crate) fn timings_ui(ui: &mut Ui, report: &FrameReport, stats: &ShadowStats, history: &TimingHistory) {
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    Grid::new("timings").show(ui, |ui| {
        for p in &report.passes {
            ui.label(format!("GPU {}", p.name));
            ui.label(format!("{:.3} ms", p.ms));
            ui.end_row();
        }
        if report.passes.is_empty() {
            ui.label("GPU");
            ui.label("no timestamp queries");
            ui.end_row();
        }
        for (name, d) in [
            ("CPU lights and views", stats.cascades_cpu),
            ("CPU caster culling", stats.culling_cpu),
            ("CPU view culling", stats.view_culling_cpu),
        ] {
            ui.label(name);
            ui.label(format!("{:.3} ms", ms(d)));
            ui.end_row();
        }
    });
    ui.label(format!(
        "draw calls {}, visible {}, shadow memory {:.1} MiB",
        report.draw_calls,
        stats.visible_instances,
        report.shadow_memory as f64 / (1024.0 * 1024.0)
    ));
    if let Some(p) = report.pages {
        ui.label(format!(
            "pages needed {}, resident {} of {}, drawn {}, evicted {}, overflowed {}",
            p.needed, p.resident, p.pool, p.drawn, p.evicted, p.overflowed
        ));
    }
    let mean = history.mean();
    ui.horizontal(|ui| {
        ui.colored_label(GPU_COLOR, format!("GPU {:.2} ms", mean.gpu_ms));
        ui.colored_label(CPU_COLOR, format!("CPU {:.2} ms", mean.cpu_ms));
        ui.label(format!("(mean of {} frames)", history.len()));
    });
    plot(ui, history);
}

/// A small line plot of GPU and CPU time, newest on the right, scaled to the peak.
fn plot(ui: &mut Ui, history: &TimingHistory) {
    let (response, painter) = ui.allocate_painter(vec2(ui.available_width().min(280.0), 60.0), Sense::hover());
    let rect = response.rect;
    painter.rect_filled(rect, 2.0, Color32::from_gray(24));
    let peak = history.peak_ms().max(0.1);
    let n = history.len();
    if n < 2 {
        return;
    }
    let point = |i: usize, v: f32| {
        let x = rect.left() + rect.width() * i as f32 / (n - 1) as f32;
        let y = rect.bottom() - rect.height() * (v / peak).clamp(0.0, 1.0);
        pos2(x, y)
    };
    let gpu: Vec<_> = history.iter().enumerate().map(|(i, s)| point(i, s.gpu_ms)).collect();
    let cpu: Vec<_> = history.iter().enumerate().map(|(i, s)| point(i, s.cpu_ms)).collect();
    painter.line(gpu, Stroke::new(1.5, GPU_COLOR));
    painter.line(cpu, Stroke::new(1.5, CPU_COLOR));
    painter.text(
        rect.left_top() + vec2(4.0, 2.0),
        egui::Align2::LEFT_TOP,
        format!("{peak:.2} ms"),
        egui::FontId::monospace(10.0),
        Color32::GRAY,
    );
}
