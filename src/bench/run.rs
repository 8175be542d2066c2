//! The benchmark run: for every scene, the ray-traced reference at the analysis resolution,
//! then for every preset its error against the reference, its temporal stability under
//! sub-texel camera moves and in-place turns, and its GPU and CPU cost at the timing
//! resolution.

use std::path::{Path, PathBuf};
use std::time::Duration;

use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use thiserror::Error;

use crate::analysis::metrics::{ErrorMetrics, Thresholds, error_metrics, per_cascade};
use crate::analysis::report::{BenchReport, GpuTimes, PresetResult, SceneResult};
use crate::analysis::shimmer::{Shimmer, shimmer};
use crate::app::SpawnError;
use crate::bench::presets::Preset;
use crate::bench::session::SceneSession;
use crate::reference::{ReferencePoint, ReferenceSettings, sun_visibility};
use crate::render::frame::FrameInputs;
use crate::render::probe::ProbeGpu;
use crate::render::target::AnalysisImage;
use crate::render::{FrameReport, GpuError, Renderer};
use crate::scene::{SceneDesc, SceneError};

/// Anything that stops a benchmark.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum BenchError {
    /// A scene file is invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A scene could not be spawned.
    #[error(transparent)]
    Spawn(#[from] SpawnError),
    /// No GPU.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// A scene has no camera or no sun.
    #[error("{0}: the benchmark needs a camera and a sun")]
    NoSun(String),
}

/// What to measure.
#[derive(Clone, Debug)]
pub struct BenchConfig {
    /// Scene files.
    pub scenes: Vec<PathBuf>,
    /// Presets to score.
    pub presets: Vec<Preset>,
    /// Resolution of the GPU timings.
    pub width: u32,
    /// Resolution of the GPU timings.
    pub height: u32,
    /// Resolution at which errors are scored against the reference.
    pub analysis_width: u32,
    /// Resolution at which errors are scored against the reference.
    pub analysis_height: u32,
    /// Frames timed per preset (after `warmup_frames`).
    pub timing_frames: u32,
    /// Frames rendered before timing.
    pub warmup_frames: u32,
    /// Reference ray budget.
    pub reference: ReferenceSettings,
    /// Camera poses per stability path.
    pub shimmer_steps: u32,
    /// Most world points followed for stability.
    pub max_probes: usize,
    /// Show progress bars.
    pub progress: bool,
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn bar(len: u64, message: String, show: bool) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len).with_message(message);
    bar.set_style(
        ProgressStyle::with_template("{msg:32} [{bar:30}] {pos}/{len} {elapsed_precise} eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.enable_steady_tick(Duration::from_millis(250));
    bar
}

/// Renders one analysis frame of the session with the given renderer.
fn analysis_frame(session: &mut SceneSession, renderer: &mut Renderer) -> AnalysisImage {
    session.update();
    renderer.render(&FrameInputs::from_world(session.app.world(), 0));
    renderer.read_analysis().unwrap_or_default()
}

/// The points (and the pixels they were seen at) where the shadow was evaluated.
pub struct Points {
    /// Pixel index of each point.
    pub pixels: Vec<usize>,
    /// The points, for the ray-traced reference.
    pub reference: Vec<ReferencePoint>,
    /// The points, for the shadow-probe pass.
    pub probes: Vec<ProbeGpu>,
}

/// Every pixel of an analysis frame where the shadow was evaluated, as reference points and
/// shadow probes.
pub fn evaluated_points(a: &AnalysisImage) -> Points {
    let pixels: Vec<usize> = (0..a.shadow.len())
        .filter(|&i| a.evaluated[i] && a.position[i].is_finite() && a.normal[i].is_finite())
        .collect();
    let reference = pixels
        .iter()
        .map(|&i| ReferencePoint {
            position: a.position[i],
            normal: a.normal[i],
        })
        .collect();
    let probes = pixels
        .iter()
        .map(|&i| ProbeGpu::new(a.position[i], a.normal[i], ((i as u32) % a.width, (i as u32) / a.width)))
        .collect();
    Points {
        pixels,
        reference,
        probes,
    }
}

/// Shadow values at `probes` for each pose of a camera path.
fn path_values(
    session: &mut SceneSession,
    renderer: &mut Renderer,
    probes: &[ProbeGpu],
    poses: &[(Vec3, f32)],
) -> Vec<Vec<f32>> {
    let values = poses
        .iter()
        .map(|&(offset, yaw)| {
            session.move_camera(offset, yaw);
            session.update();
            renderer.render(&FrameInputs::from_world(session.app.world(), 0));
            renderer.evaluate_probes(&FrameInputs::from_world(session.app.world(), 0), probes)
        })
        .collect();
    session.move_camera(Vec3::ZERO, 0.0);
    values
}

/// Errors and stability of every preset on one scene.
struct SceneScores {
    errors: Vec<(ErrorMetrics, [ErrorMetrics; 4])>,
    shimmer: Vec<(Shimmer, Shimmer)>,
}

fn score_scene(path: &Path, desc: &SceneDesc, config: &BenchConfig) -> Result<SceneScores, BenchError> {
    let name = path.display().to_string();
    let (w, h) = (config.analysis_width, config.analysis_height);
    let mut session = SceneSession::new(desc, w, h)?;
    let mut renderer = Renderer::headless_with_analysis(w, h)?;
    let first = analysis_frame(&mut session, &mut renderer);
    let points = evaluated_points(&first);
    let sun = session.sun_disc().ok_or_else(|| BenchError::NoSun(name.clone()))?;

    let reference_scene = session.reference_scene();
    let progress = bar(
        points.reference.len() as u64,
        format!("reference {}", short(path)),
        config.progress,
    );
    let reference = sun_visibility(&reference_scene, &sun, &points.reference, &config.reference, &|n| {
        progress.set_position(n as u64)
    });
    progress.finish_and_clear();
    let reference_values: Vec<f32> = reference.iter().map(|v| v.value).collect();

    // Stability paths: sub-texel moves of the start camera (within one texel of cascade 0)
    // and small in-place turns.
    let texel = session
        .lights()
        .sun()
        .map_or(0.01, |s| s.cascades.cascades[0].texel_world_size);
    let start = session.start_camera();
    let (right, up) = (start.rotation * Vec3::X, start.rotation * Vec3::Y);
    let steps = config.shimmer_steps.max(2);
    let translations: Vec<(Vec3, f32)> = (0..steps)
        .map(|k| {
            let t = k as f32 / steps as f32 * 0.95 * texel;
            (right * t + up * (0.37 * t), 0.0)
        })
        .collect();
    let rotations: Vec<(Vec3, f32)> = (0..steps)
        .map(|k| (Vec3::ZERO, (k as f32 * 0.1).to_radians()))
        .collect();
    let stride = points.probes.len().div_ceil(config.max_probes.max(1)).max(1);
    let followed: Vec<ProbeGpu> = points.probes.iter().step_by(stride).copied().collect();

    let mut scores = SceneScores {
        errors: Vec::new(),
        shimmer: Vec::new(),
    };
    let progress = bar(
        config.presets.len() as u64,
        format!("presets {}", short(path)),
        config.progress,
    );
    let thresholds = Thresholds::default();
    for preset in &config.presets {
        session.apply_settings(preset.apply);
        let image = analysis_frame(&mut session, &mut renderer);
        let technique = renderer.evaluate_probes(&FrameInputs::from_world(session.app.world(), 0), &points.probes);
        let cascade: Vec<u8> = points.pixels.iter().map(|&i| image.cascade[i]).collect();
        let all = |_: usize| true;
        scores.errors.push((
            error_metrics(&technique, &reference_values, all, &thresholds),
            per_cascade(&technique, &reference_values, &cascade, all, &thresholds),
        ));
        let moved = path_values(&mut session, &mut renderer, &followed, &translations);
        let turned = path_values(&mut session, &mut renderer, &followed, &rotations);
        scores.shimmer.push((shimmer(&moved), shimmer(&turned)));
        progress.inc(1);
    }
    progress.finish_and_clear();
    Ok(scores)
}

/// GPU and CPU cost of every preset on one scene at the timing resolution.
fn time_scene(
    path: &Path,
    desc: &SceneDesc,
    config: &BenchConfig,
) -> Result<Vec<(GpuTimes, f64, FrameReport)>, BenchError> {
    let mut session = SceneSession::new(desc, config.width, config.height)?;
    let mut renderer = Renderer::headless(config.width, config.height)?;
    let progress = bar(
        config.presets.len() as u64,
        format!("timing {}", short(path)),
        config.progress,
    );
    let mut out = Vec::new();
    for preset in &config.presets {
        session.apply_settings(preset.apply);
        let (mut shadow, mut forward, mut total, mut cpu) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut last = FrameReport::default();
        for frame in 0..config.warmup_frames + config.timing_frames.max(1) {
            session.update();
            let report = renderer
                .render(&FrameInputs::from_world(session.app.world(), frame))
                .clone();
            if frame >= config.warmup_frames {
                let stats = session.stats();
                cpu.push((stats.cascades_cpu + stats.culling_cpu).as_secs_f64() * 1e3);
                shadow.push(report.shadow_ms());
                forward.push(report.passes.iter().filter(|p| p.name == "forward").map(|p| p.ms).sum());
                total.push(report.passes.iter().map(|p| p.ms).sum());
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
    }
    progress.finish_and_clear();
    Ok(out)
}

fn short(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| path.display().to_string(), |s| s.to_string_lossy().to_string())
}

/// Bias settings forced onto every scene before the presets apply (for tuning sweeps).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SettingsOverrides {
    /// Normal offset in texels.
    pub normal_offset: Option<f32>,
    /// Hardware slope bias.
    pub slope_bias: Option<f32>,
}

impl SettingsOverrides {
    fn apply(&self, desc: &mut SceneDesc) {
        if let Some(v) = self.normal_offset {
            desc.shadows.normal_offset = v;
        }
        if let Some(v) = self.slope_bias {
            desc.shadows.slope_bias = v;
        }
    }

    fn notes(&self) -> Option<String> {
        (*self != Self::default()).then(|| format!("Settings forced on every scene: {self:?}."))
    }
}

/// Runs the whole benchmark and returns the report (without writing files).
pub fn run_bench(config: &BenchConfig) -> Result<BenchReport, BenchError> {
    run_bench_with(config, &SettingsOverrides::default())
}

/// [`run_bench`] with bias settings forced onto every scene.
pub fn run_bench_with(config: &BenchConfig, overrides: &SettingsOverrides) -> Result<BenchReport, BenchError> {
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
    for path in &config.scenes {
        let mut desc = SceneDesc::load(path)?;
        overrides.apply(&mut desc);
        let scores = score_scene(path, &desc, config)?;
        let times = time_scene(path, &desc, config)?;
        for (i, result) in presets.iter_mut().enumerate() {
            let (gpu, cpu_ms, report) = times[i].clone();
            let (errors, per_cascade) = scores.errors[i];
            let (shimmer_translation, shimmer_rotation) = scores.shimmer[i];
            result.scenes.push(SceneResult {
                scene: short(path),
                gpu,
                cpu_ms,
                draw_calls: report.draw_calls,
                shadow_memory_bytes: report.shadow_memory,
                errors,
                per_cascade,
                shimmer_translation,
                shimmer_rotation,
            });
        }
    }
    let mut notes = vec![
        format!(
            "Errors are scored at {}×{} against a Monte-Carlo reference of the sun disc ({}); GPU times at {}×{}, median of {} frames after {} warm-up frames.",
            config.analysis_width,
            config.analysis_height,
            reference_description(&config.reference),
            config.width,
            config.height,
            config.timing_frames,
            config.warmup_frames
        ),
        "Shimmer: spread (max − min) of the shadow at fixed world points while the camera moves by sub-texel steps of cascade 0, or turns in place in 0.1° steps.".to_string(),
    ];
    notes.extend(overrides.notes());
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
        commit: commit(),
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

fn reference_description(r: &ReferenceSettings) -> String {
    format!(
        "{}–{} rays per point, adaptive, seed {}",
        r.min_samples, r.max_samples, r.seed
    )
}

/// The commit being measured: `PENUMBRA_COMMIT` if set, else `git rev-parse`, else "unknown".
fn commit() -> String {
    if let Ok(c) = std::env::var("PENUMBRA_COMMIT") {
        return c;
    }
    std::process::Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".to_string())
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
    fn median_of_odd_and_even_lengths() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), 3.0);
        assert!(median(Vec::new()).is_nan());
    }

    #[test]
    fn dates_from_day_counts() {
        assert_eq!(date_from_days(0), "1970-01-01");
        assert_eq!(date_from_days(59), "1970-03-01");
        assert_eq!(date_from_days(11_016), "2000-02-29");
        assert_eq!(date_from_days(20_779), "2026-11-22");
        assert_eq!(today().len(), 10);
    }
}
