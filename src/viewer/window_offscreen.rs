//! The viewer without a window: frames drawn in a loop into an offscreen frame, at most two
//! ahead of the GPU, timed from the first frame's start to the GPU finishing the last.

use std::time::Instant;

use super::Viewer;
use crate::viewer::options::ViewerError;

impl Viewer {
    /// Draws frames into an offscreen frame until the scripted frame count is reached, at
    /// most two frames ahead of the GPU (as a swapchain of latency 2), and records the time
    /// they took, the GPU's last frame included.
    pub(super) fn run_offscreen(&mut self) -> Result<(), ViewerError> {
        if self.options.exit_after.is_none() {
            return Err(ViewerError::Options(
                "an offscreen viewer needs a frame count (`--exit-after N`)".into(),
            ));
        }
        let state = self.open_offscreen()?;
        self.adopt(state);
        let start = Instant::now();
        let mut in_flight = None;
        while !self.finished() && self.error.is_none() {
            self.frame();
            let Some(state) = &self.window else { break };
            let gpu = &state.renderer.gpu;
            // NOTE: an empty submission marks the end of this frame's work.
            let done = gpu.queue.submit([]);
            if let Some(previous) = in_flight.replace(done) {
                let _ = gpu.device.poll(wgpu::PollType::Wait {
                    submission_index: Some(previous),
                    timeout: None,
                });
            }
        }
        if let Some(state) = &self.window {
            let _ = state.renderer.gpu.device.poll(wgpu::PollType::wait_indefinitely());
        }
        self.summary.elapsed = start.elapsed();
        Ok(())
    }
}
