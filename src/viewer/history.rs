//! A short history of frame timings for the inspector's plot: a fixed-capacity ring of
//! samples, oldest first.

use std::collections::VecDeque;

/// One frame's timings, in milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameSample {
    /// Sum of the GPU passes (0 without timestamp queries).
    pub gpu_ms: f32,
    /// CPU time of the shadow systems (cascades and culling).
    pub cpu_ms: f32,
}

/// The last `capacity` frame samples.
#[derive(Clone, Debug)]
pub struct TimingHistory {
    samples: VecDeque<FrameSample>,
    capacity: usize,
}

impl TimingHistory {
    /// An empty history that keeps at most `capacity` samples (at least one).
    pub fn new(capacity: usize) -> Self {
        let capacity = capacity.max(1);
        Self {
            samples: VecDeque::with_capacity(capacity),
            capacity,
        }
    }

    /// Adds a sample, dropping the oldest when full.
    pub fn push(&mut self, sample: FrameSample) {
        if self.samples.len() == self.capacity {
            self.samples.pop_front();
        }
        self.samples.push_back(sample);
    }

    /// The samples, oldest first.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = &FrameSample> {
        self.samples.iter()
    }

    /// Number of samples held.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// True before the first sample.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The largest GPU or CPU time held (0 when empty): the plot's vertical scale.
    pub fn peak_ms(&self) -> f32 {
        self.samples.iter().map(|s| s.gpu_ms.max(s.cpu_ms)).fold(0.0, f32::max)
    }

    /// Mean GPU and CPU time over the samples held.
    pub fn mean(&self) -> FrameSample {
        let n = self.samples.len().max(1) as f32;
        let (g, c) = self
            .samples
            .iter()
            .fold((0.0, 0.0), |(g, c), s| (g + s.gpu_ms, c + s.cpu_ms));
        FrameSample {
            gpu_ms: g / n,
            cpu_ms: c / n,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(gpu_ms: f32) -> FrameSample {
        FrameSample { gpu_ms, cpu_ms: 0.5 }
    }

    #[test]
    fn keeps_the_newest_samples_in_order() {
        let mut h = TimingHistory::new(3);
        assert!(h.is_empty());
        assert_eq!(h.peak_ms(), 0.0);
        for v in [1.0, 2.0, 3.0, 4.0] {
            h.push(sample(v));
        }
        let kept: Vec<f32> = h.iter().map(|s| s.gpu_ms).collect();
        assert_eq!(kept, [2.0, 3.0, 4.0]);
        assert_eq!(h.peak_ms(), 4.0);
        assert_eq!(h.mean().gpu_ms, 3.0);
        assert_eq!(h.mean().cpu_ms, 0.5);
        assert_eq!(TimingHistory::new(0).capacity, 1);
    }
}
