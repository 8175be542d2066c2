//! Scoring and reporting of shadow technique presets: pure CPU, no GPU and no ECS.
//!
//! [`metrics`] compares a technique's shadow factors with a ray-traced reference (per pixel
//! and per cascade), [`shimmer`](mod@shimmer) measures temporal stability at fixed world
//! points over camera poses, [`pareto`] finds the presets that no other beats in both cost and
//! error, [`report`] holds the results and writes them as Markdown, and [`plot`] draws GPU
//! time against penumbra error as a PNG with an embedded font, so no system font is needed.
//!
//! Shadow factors are in `[0, 1]`: 1 is fully lit, 0 fully shadowed.

mod axis;
mod font;
pub mod metrics;
pub mod pareto;
pub mod plot;
mod raster;
pub mod report;
pub mod shimmer;

pub use metrics::{ErrorMetrics, Thresholds, error_metrics, per_cascade};
pub use pareto::pareto_front;
pub use plot::{PlotError, plot_png};
pub use report::{BenchReport, GpuTimes, PresetResult, SceneResult, markdown};
pub use shimmer::{Shimmer, UNSTABLE_SPREAD, shimmer};
