//! The benchmark's progress display: one overall bar with an ETA across every scene and
//! preset, and below it a bar for the stage under way (the reference rays, the presets
//! scored, the presets timed). Hidden when the run asks for no progress.

use std::time::Duration;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

/// The bars of one run.
pub(crate) struct Progress {
    multi: MultiProgress,
    overall: ProgressBar,
}

/// Units of work of a run: per scene, the reference counts as much as scoring every preset
/// (their times are alike), then one unit per preset scored and one per preset timed.
pub(crate) fn total_units(scenes: usize, presets: usize) -> u64 {
    (scenes * presets.max(1) * 3) as u64
}

impl Progress {
    /// The overall bar of `total` units, drawn when `show`.
    pub fn new(total: u64, show: bool) -> Self {
        let target = if show {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let multi = MultiProgress::with_draw_target(target);
        let overall = multi.add(ProgressBar::new(total).with_message("bench"));
        overall.set_style(
            ProgressStyle::with_template("{msg:32} [{bar:30}] {percent:>3}% {elapsed_precise} eta {eta_precise}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        overall.enable_steady_tick(Duration::from_millis(250));
        Self { multi, overall }
    }

    /// A bar of `len` steps for one stage, under the overall bar.
    pub fn stage(&self, len: u64, message: String) -> ProgressBar {
        let bar = self.multi.add(ProgressBar::new(len).with_message(message));
        bar.set_style(
            ProgressStyle::with_template("{msg:32} [{bar:30}] {pos}/{len} {elapsed_precise} eta {eta}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar
    }

    /// Counts `units` of the run as done.
    pub fn advance(&self, units: u64) {
        self.overall.inc(units);
    }

    /// Units done so far.
    #[cfg(test)]
    pub fn done(&self) -> u64 {
        self.overall.position()
    }

    /// Clears the bars.
    pub fn finish(&self) {
        self.overall.finish_and_clear();
        // NOTE: clearing a hidden or already cleared display cannot fail in a way that matters.
        let _ = self.multi.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_counts_every_unit_once() {
        let (scenes, presets) = (3, 4);
        let progress = Progress::new(total_units(scenes, presets), false);
        for _ in 0..scenes {
            progress.advance(presets as u64); // the reference
            for _ in 0..presets {
                progress.advance(1); // scored
            }
            for _ in 0..presets {
                progress.advance(1); // timed
            }
        }
        assert_eq!(progress.done(), total_units(scenes, presets));
        progress.finish();
    }
}
