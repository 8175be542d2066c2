//! Scoring and reporting of shadow technique presets: pure CPU, no GPU and no ECS.
//!
//! [`metrics`] compares a technique's shadow factors with a ray-traced reference (per pixel
//! and per cascade), [`shimmer`](mod@shimmer) measures temporal stability at fixed world
//! points over camera poses, [`pareto`] finds the presets that no other beats in both cost and
//! error, [`results`] holds the results (and which light each scene scores), [`report`] writes
//! them as Markdown, [`plot`] draws GPU time against penumbra error as a PNG with an
//! embedded font, so no system font is needed, and [`sweep`](mod@sweep) tabulates and plots
//! runs at several sun diameters; [`gallery`](mod@gallery) draws a technique's shadow, the
//! reference and their difference over the window with the most penumbra.
//!
//! Shadow factors are in `[0, 1]`: 1 is fully lit, 0 fully shadowed.

mod axis;
pub mod edges;
mod font;
pub mod gallery;
pub mod metrics;
pub mod pareto;
pub mod plot;
mod raster;
pub mod report;
pub mod results;
pub mod shimmer;
pub mod sweep;

pub use metrics::{ErrorMetrics, Thresholds, error_metrics, per_cascade};
pub use pareto::pareto_front;
pub use plot::{PlotError, plot_png};
pub use report::markdown;
pub use results::{BenchReport, GpuTimes, PresetResult, SceneResult, ScoredLight};
pub use shimmer::{Shimmer, UNSTABLE_SPREAD, shimmer};
pub use sweep::{SweepRun, sweep_markdown, sweep_png};
