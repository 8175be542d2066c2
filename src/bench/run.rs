//! The benchmark run: for every scene, the scores of every preset on the scene's scored
//! light ([`score`](crate::bench::score): error against the ray-traced
//! reference and temporal stability), then their GPU and CPU cost at the timing resolution.

use std::path::Path;

use crate::analysis::results::{BenchReport, GpuTimes, PresetResult, SceneResult, ScoredLight};
use crate::bench::config::short;
pub use crate::bench::config::{BenchConfig, BenchError};
use crate::bench::gallery::SceneShots;
use crate::bench::progress::{Progress, total_units};
pub use crate::bench::score::{Points, evaluated_points};
use crate::bench::score::{SceneScores, score_scene};
use crate::bench::session::SceneSession;
use crate::reference::ReferenceSettings;
use crate::render::frame_inputs::FrameInputs;
use crate::render::timer::median;
use crate::render::{FrameReport, Msaa, RenderOptions, Renderer};
use crate::scene::SceneDesc;
use crate::settings::{CascadeFit, ContactShadows, ShadowSettings};

/// One preset's cost on one scene: GPU times, CPU ms per frame, and the last frame's report.
type Timing = (GpuTimes, f64, FrameReport);

/// GPU and CPU cost of every preset on one scene at the timing resolution.
fn time_scene(
    path: &Path,
    desc: &SceneDesc,
    config: &BenchConfig,
    overall: &Progress,
) -> Result<Vec<Timing>, BenchError> {
    let mut session = SceneSession::new(desc, config.width, config.height)?;
    session.pages = config.pages;
    // NOTE: every shadow map and the prepass are drawn every frame, as when the camera or the
    // casters move; a still frame's cost is measured apart (`penumbra render`). One sample per pixel: the
    // bench compares shadow techniques, and its figures stay comparable with those before
    // MSAA (which adds the same cost to every preset).
    session.app.insert_resource(RenderOptions {
        shadow_cache: false,
        msaa: Msaa::Off,
        prepass_reuse: false,
        sun_depth: config.sun_depth,
        ..RenderOptions::default()
    });
    let mut renderer = Renderer::headless(config.width, config.height)?;
    renderer.set_focus_light(session.focus_light_index());
    let progress = overall.stage(config.presets.len() as u64, format!("timing {}", short(path)));
    let mut out = Vec::new();
    for preset in &config.presets {
        session.apply_settings(preset.apply);
        let (mut shadow, mut forward, mut total, mut cpu) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut last = FrameReport::default();
        for frame in 0..config.warmup_frames + config.timing_frames.max(1) {
            session.update();
            let number = renderer.frames_rendered();
            let report = renderer
                .render(&FrameInputs::from_world(session.app.world(), frame))
                .clone();
            // NOTE: the benchmark waits for each frame's timings so that every timed frame
            // counts (a game's frame loop does not wait).
            let timings = renderer.wait_for_timings();
            session.take_seen_depths(&mut renderer);
            if frame >= config.warmup_frames {
                let stats = session.stats();
                cpu.push((stats.cascades_cpu + stats.culling_cpu).as_secs_f64() * 1e3);
                if let Some(t) = timings.iter().find(|t| t.frame == number) {
                    let report = FrameReport {
                        passes: t.passes.clone(),
                        ..FrameReport::default()
                    };
                    shadow.push(report.shadow_ms());
                    forward.push(report.passes.iter().filter(|p| p.name == "forward").map(|p| p.ms).sum());
                    total.push(report.passes.iter().map(|p| p.ms).sum());
                }
                last = report;
            }
        }
        out.push((
            GpuTimes {
                shadow_ms: median(shadow),
                forward_ms: median(forward),
                total_ms: median(total),
            },
            median(cpu),
            last,
        ));
        progress.inc(1);
        overall.advance(1);
    }
    progress.finish_and_clear();
    Ok(out)
}

/// Settings forced onto every scene before the presets apply (for tuning sweeps).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SettingsOverrides {
    /// Normal offset in texels.
    pub normal_offset: Option<f32>,
    /// Hardware slope bias.
    pub slope_bias: Option<f32>,
    /// The scene sun's angular diameter, degrees (for sweeps of penumbra width).
    pub sun_diameter: Option<f32>,
    /// How every scene's cascades are fitted.
    pub fit: Option<CascadeFit>,
    /// Cells per side of the grid every scene's cascade boxes snap to.
    pub snap_cells: Option<u32>,
    /// Whether every scene's cascades scroll.
    pub cascade_scroll: Option<bool>,
    /// Every scene's shadow-map resolution (texels per side).
    pub resolution: Option<u32>,
    /// Every light's contact shadows (the `-contact` presets use them instead of the
    /// defaults).
    pub contact: Option<ContactShadows>,
}

impl SettingsOverrides {
    /// Forces the overrides on the scene's settings and on every light's own settings.
    fn apply(&self, desc: &mut SceneDesc) {
        if let (Some(v), Some(sun)) = (self.sun_diameter, desc.sun.as_mut()) {
            sun.angular_diameter = v;
        }
        desc.settings_mut().for_each(|s| self.apply_to(s));
    }

    fn apply_to(&self, s: &mut ShadowSettings) {
        if let Some(v) = self.normal_offset {
            s.bias.normal_offset = v;
        }
        if let Some(v) = self.slope_bias {
            s.bias.slope_bias = v;
        }
        if let Some(fit) = self.fit {
            s.map.cascades.fit = fit;
        }
        if let Some(cells) = self.snap_cells {
            s.map.cascades.snap_cells = cells;
        }
        if let Some(on) = self.cascade_scroll {
            s.map.cascades.scroll = on;
        }
        if let Some(resolution) = self.resolution {
            s.map.resolution = resolution;
        }
        if let Some(contact) = self.contact {
            s.filter.contact = contact;
        }
    }

    fn notes(&self) -> Option<String> {
        (*self != Self::default()).then(|| format!("Settings forced on every scene: {self:?}."))
    }
}

/// Runs the whole benchmark and returns the report (without writing files). Each scene is
/// scored on its focus light ([`choose_focus`](crate::bench::focus::choose_focus)), every
/// preset on every scene, so each preset's means are over the same scenes.
pub fn run_bench(config: &BenchConfig) -> Result<BenchReport, BenchError> {
    run_bench_with(config, &SettingsOverrides::default())
}

/// [`run_bench`] with bias settings forced onto every scene.
pub fn run_bench_with(config: &BenchConfig, overrides: &SettingsOverrides) -> Result<BenchReport, BenchError> {
    run_bench_collecting(config, overrides, None)
}

/// [`run_bench_with`] that also keeps, when `gallery` is given, each scene's pictures for
/// [`write_gallery`](crate::bench::gallery::write_gallery).
pub fn run_bench_collecting(
    config: &BenchConfig,
    overrides: &SettingsOverrides,
    mut gallery: Option<&mut Vec<SceneShots>>,
) -> Result<BenchReport, BenchError> {
    let mut presets: Vec<PresetResult> = config
        .presets
        .iter()
        .map(|p| PresetResult {
            preset: p.name.to_string(),
            description: p.description.to_string(),
            scenes: Vec::new(),
        })
        .collect();
    let probe = Renderer::headless(1, 1)?;
    let info = probe.gpu.adapter_info.clone();
    let timestamps = probe.gpu.timestamps;
    drop(probe);
    let mut scene_notes = Vec::new();
    let progress = Progress::new(total_units(config.scenes.len(), config.presets.len()), config.progress);
    for path in &config.scenes {
        let mut desc = SceneDesc::load(path)?;
        overrides.apply(&mut desc);
        let scores = score_scene(path, &desc, config, &progress, gallery.as_deref_mut())?;
        let times = time_scene(path, &desc, config, &progress)?;
        for ((result, score), (gpu, cpu_ms, report)) in presets.iter_mut().zip(&scores.presets).zip(times) {
            result.scenes.push(SceneResult {
                scene: short(path),
                gpu,
                cpu_ms,
                draw_calls: report.draw_calls,
                shadow_memory_bytes: report.shadow_memory,
                light: scores.light,
                errors: score.errors,
                per_cascade: score.per_cascade,
                shimmer_translation: score.shimmer_translation,
                shimmer_rotation: score.shimmer_rotation,
                edges: score.edges,
                image_errors: score.image,
                contact_band: score.contact_band,
            });
        }
        scene_notes.extend(scene_light_notes(&short(path), &scores));
    }
    progress.finish();
    let mut notes = vec![
        format!(
            "Errors are scored at {}×{} against a Monte-Carlo reference of each scene's scored light ({}): the visible fraction of the sun's disc, or of a spot light's emitter sphere; GPU times at {}×{}, median of {} frames after {} warm-up frames.",
            config.analysis_width,
            config.analysis_height,
            reference_description(&config.reference),
            config.width,
            config.height,
            config.timing_frames,
            config.warmup_frames
        ) + " Frames are timed at one sample per pixel (no MSAA).",
        "Shimmer: spread (max − min) of the shadow at fixed world points while the camera moves by sub-texel steps of cascade 0 (of a spot light's map at the camera's target, for a spot-light scene), or turns in place in 0.1° steps.".to_string(),
    ];
    notes.append(&mut scene_notes);
    notes.extend(overrides.notes());
    notes.extend(
        config
            .pages
            .map(|p| format!("The paged presets' virtual clipmap is given {p:?}.")),
    );
    if !timestamps {
        notes.push("This adapter has no timestamp queries: GPU times are missing (NaN).".to_string());
    }
    if info.device_type == wgpu::DeviceType::Cpu {
        notes.push(
            "Measured on a software rasteriser: GPU times are only meaningful as ratios between presets.".to_string(),
        );
    }
    Ok(BenchReport {
        title: "penumbra: shadow quality against cost".to_string(),
        adapter: info.name.clone(),
        driver: format!("{} {}", info.driver, info.driver_info),
        backend: format!("{:?}", info.backend),
        commit: crate::BUILD_COMMIT.to_string(),
        date: today(),
        width: config.width,
        height: config.height,
        analysis_width: config.analysis_width,
        analysis_height: config.analysis_height,
        reference_samples: reference_description(&config.reference),
        timing_frames: config.timing_frames,
        presets,
        notes,
    })
}

/// What a scene scored; for a spot or point light, that the cascade-blending presets score
/// as their base presets; for a sun, that the VSM presets score as PCF.
fn scene_light_notes(scene: &str, scores: &SceneScores) -> Vec<String> {
    let mut notes = vec![format!(
        "Scene {scene}: {} ({} points scored; shimmer step {:.1} mm).",
        scores.light.describe(),
        scores.points,
        scores.texel * 1e3
    )];
    match scores.light {
        ScoredLight::Spot { .. } => notes.push(format!(
            "Scene {scene}: a spot light has one view and nothing to blend, so the -no-blend presets render as their base presets there."
        )),
        ScoredLight::Point { .. } => notes.push(format!(
            "Scene {scene}: a point light's cube faces are filtered across their edges and have nothing to blend, so the -no-blend presets render as their base presets there."
        )),
        ScoredLight::Sun { .. } => notes.push(format!(
            "Scene {scene}: a sun has no VSM, so the vsm presets render with EVSM2 there (a sun's `Vsm` is filtered as `Evsm`)."
        )),
    }
    notes
}

fn reference_description(r: &ReferenceSettings) -> String {
    format!(
        "{}–{} rays per point, adaptive, seed {}",
        r.min_samples, r.max_samples, r.seed
    )
}

/// Today's date (UTC) as YYYY-MM-DD, from the system clock.
fn today() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    date_from_days((secs / 86_400) as i64)
}

/// The civil date `days` after 1970-01-01 (Howard Hinnant's days-to-civil algorithm).
fn date_from_days(days: i64) -> String {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_from_day_counts() {
        assert_eq!(date_from_days(0), "1970-01-01");
        assert_eq!(date_from_days(59), "1970-03-01");
        assert_eq!(date_from_days(11_016), "2000-02-29");
        assert_eq!(date_from_days(20_779), "2026-11-22");
        assert_eq!(today().len(), 10);
    }
}
