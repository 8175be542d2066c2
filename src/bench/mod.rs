//! `penumbra bench`: scores every preset against the ray-traced reference of each scene's
//! scored light (its first sun, or its first shadowed spot light when it has no sun: see
//! [`focus`]) and measures its cost, then writes a Markdown report and a plot of GPU time
//! against error.

pub mod focus;
pub mod presets;
pub mod run;
pub mod score;
pub mod session;

pub use presets::{Preset, presets};
pub use run::{BenchConfig, BenchError, SettingsOverrides, run_bench, run_bench_with};

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

/// Writes `report.md` and `plot.png` into `dir` (created if needed); returns the report path.
pub fn write_report(report: &BenchReport, dir: &Path) -> Result<PathBuf, ReportError> {
    let io = |path: &Path, e: std::io::Error| ReportError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    plot_png(report, &dir.join("plot.png"))?;
    let path = dir.join("report.md");
    write_file(&path, markdown(report, Some("plot.png")).as_bytes()).map_err(|e| ReportError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    Ok(path)
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
