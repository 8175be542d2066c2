//! `penumbra bench`: scores every preset against the ray-traced reference of each scene's
//! scored light (its first sun, or its first shadowed spot light when it has no sun: see
//! [`focus`]) and measures its cost, then writes a Markdown report and a plot of GPU time
//! against error; with `--gallery`, pictures of every preset beside the truth ([`gallery`]).

pub mod config;
pub mod focus;
pub mod gallery;
pub mod presets;
mod progress;
pub mod run;
pub mod score;
pub mod session;

pub use config::PagesOverride;
pub use gallery::{SceneShots, write_gallery};
pub use presets::{Preset, presets};
pub use run::{BenchConfig, BenchError, SettingsOverrides, run_bench, run_bench_collecting, run_bench_with};

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::analysis::plot::{PlotError, plot_png};
use crate::analysis::report::{BenchReport, markdown};
use crate::analysis::sweep::{SweepRun, sweep_markdown, sweep_png};
use crate::export::write_file;

/// The report could not be written.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ReportError {
    /// The plot failed.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// A file or folder could not be written.
    #[error("{path}: {message}")]
    Io {
        /// Path.
        path: String,
        /// Why.
        message: String,
    },
}

/// Writes `report.md`, `report.json` (the whole report, machine-readable) and `plot.png` into
/// `dir` (created if needed); returns the Markdown report's path.
pub fn write_report(report: &BenchReport, dir: &Path) -> Result<PathBuf, ReportError> {
    let io = |path: &Path, message: String| ReportError::Io {
        path: path.display().to_string(),
        message,
    };
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e.to_string()))?;
    plot_png(report, &dir.join("plot.png"))?;
    let json_path = dir.join("report.json");
    let json = report_json(report).map_err(|e| io(&json_path, e.to_string()))?;
    write_file(&json_path, json.as_bytes()).map_err(|e| io(&json_path, e.to_string()))?;
    let path = dir.join("report.md");
    write_file(&path, markdown(report, Some("plot.png")).as_bytes()).map_err(|e| io(&path, e.to_string()))?;
    Ok(path)
}

/// The whole report as pretty-printed JSON (every preset, scene, timing and error metric;
/// non-finite numbers, such as the error of a scene nothing was scored on, become `null`).
pub fn report_json(report: &BenchReport) -> Result<String, serde_json::Error> {
    serde_json::to_string_pretty(report)
}

/// Writes `sweep.md` and `sweep.png` (cost against the sun's angular diameter) into `dir`
/// (created if needed); returns the table's path.
pub fn write_sweep(runs: &[SweepRun], dir: &Path) -> Result<PathBuf, ReportError> {
    std::fs::create_dir_all(dir).map_err(|e| ReportError::Io {
        path: dir.display().to_string(),
        message: e.to_string(),
    })?;
    sweep_png(runs, &dir.join("sweep.png"))?;
    let path = dir.join("sweep.md");
    write_file(&path, sweep_markdown(runs, Some("sweep.png")).as_bytes()).map_err(|e| ReportError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::report::tests::sample_report;

    #[test]
    fn the_report_is_written_as_json_too() {
        let report = sample_report();
        let json: serde_json::Value = serde_json::from_str(&report_json(&report).unwrap()).unwrap();
        let presets = json["presets"].as_array().unwrap();
        assert_eq!(presets.len(), report.presets.len());
        assert_eq!(presets[0]["preset"], "hard");
        assert_eq!(presets[0]["scenes"][0]["gpu"]["total_ms"], 0.5);
        assert_eq!(json["adapter"], "Test GPU 9000");
        let dir = std::env::temp_dir().join(format!("penumbra-report-json-{}", std::process::id()));
        write_report(&report, &dir).unwrap();
        let names = ["plot.png", "report.json", "report.md"];
        assert!(
            names.iter().all(|n| dir.join(n).is_file()),
            "{names:?} in {}",
            dir.display()
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
