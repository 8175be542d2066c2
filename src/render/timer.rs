//! GPU pass timings from timestamp queries, read back without waiting: each timed pass writes
//! a begin and an end timestamp into the current slot of a small ring; after the frame's
//! submission the slot's readback buffer is mapped asynchronously, and a later frame (or
//! [`GpuTimer::wait`]) collects it. The frame loop never blocks on the GPU for timings; when
//! every slot is still in flight, the frame goes untimed and is counted.

use std::sync::Arc;

use crate::render::readback::{QueryReadback, poll_device};
use std::sync::atomic::{AtomicU8, Ordering};

/// Slots in the ring: a frame's timings arrive within this many frames.
const SLOTS: usize = 3;
/// Arrived timings kept for [`GpuTimer::take_completed`]; older ones are dropped (a caller
/// that never takes them, like a window, keeps only the newest).
const KEPT: usize = 256;
/// Passes reserved in a slot before a frame asks for more.
const INITIAL_PASSES: u32 = 16;

/// Map states of a slot's readback buffer.
const IDLE: u8 = 0;
const MAPPING: u8 = 1;
const MAPPED: u8 = 2;
const FAILED: u8 = 3;

/// The time one pass took on the GPU.
#[derive(Clone, Debug, PartialEq)]
pub struct PassTiming {
    /// Pass name.
    pub name: String,
    /// Milliseconds between the pass's begin and end timestamps.
    pub ms: f64,
}

/// The timed passes of one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameTimings {
    /// The frame's number (counted by the renderer from 0).
    pub frame: u64,
    /// Its passes, in recording order.
    pub passes: Vec<PassTiming>,
}

/// Timed passes per query set: wgpu's most queries in one set, two per pass.
const SET_PASSES: u32 = wgpu::QUERY_SET_MAX_QUERIES / 2;

/// One frame's queries (as many sets as its passes need) and buffers.
struct Slot {
    query_sets: Vec<wgpu::QuerySet>,
    buffers: QueryReadback,
    capacity: u32,
    /// Pass names of the frame in flight (the first `used`), keeping their allocations.
    names: Vec<String>,
    used: usize,
    frame: u64,
    state: Arc<AtomicU8>,
    in_flight: bool,
}

impl Slot {
    fn new(device: &wgpu::Device, passes: u32) -> Self {
        let query_sets = (0..passes.div_ceil(SET_PASSES))
            .map(|k| {
                device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("pass timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: (passes - k * SET_PASSES).min(SET_PASSES) * 2,
                })
            })
            .collect();
        Self {
            query_sets,
            buffers: QueryReadback::new(device, "pass timestamps", passes * 2),
            capacity: passes,
            names: Vec::new(),
            used: 0,
            frame: 0,
            state: Arc::new(AtomicU8::new(IDLE)),
            in_flight: false,
        }
    }

    /// Reads the mapped ticks into timings and frees the slot.
    fn take(&mut self, period_ns: f32) -> FrameTimings {
        let bytes = self.used as u64 * 16;
        let readback = &self.buffers.readback;
        let passes = match readback.slice(..bytes).get_mapped_range() {
            Ok(data) => {
                let tick = |i: usize| u64::from_le_bytes(data[i * 8..i * 8 + 8].try_into().unwrap_or([0; 8]));
                self.names[..self.used]
                    .iter()
                    .enumerate()
                    .map(|(i, name)| PassTiming {
                        name: name.clone(),
                        ms: tick(i * 2 + 1).saturating_sub(tick(i * 2)) as f64 * f64::from(period_ns) / 1e6,
                    })
                    .collect()
            }
            Err(_) => Vec::new(),
        };
        readback.unmap();
        self.in_flight = false;
        self.state.store(IDLE, Ordering::Release);
        FrameTimings {
            frame: self.frame,
            passes,
        }
    }
}

/// Collects timestamp pairs for named passes, one frame per ring slot.
pub struct GpuTimer {
    enabled: bool,
    period_ns: f32,
    slots: Vec<Slot>,
    /// The slot recording this frame, if the frame is timed.
    current: Option<usize>,
    next: usize,
    overflowed: bool,
    /// Timings read back and not yet taken, oldest first.
    completed: Vec<FrameTimings>,
    /// The newest timings read back.
    latest: FrameTimings,
    /// Frames left untimed because every slot was still in flight.
    pub untimed_frames: u64,
}

impl GpuTimer {
    /// A timer that times passes when `enabled` (the adapter supports timestamps).
    pub fn new(queue: &wgpu::Queue, enabled: bool) -> Self {
        Self {
            enabled,
            period_ns: queue.get_timestamp_period(),
            slots: Vec::new(),
            current: None,
            next: 0,
            overflowed: false,
            completed: Vec::new(),
            latest: FrameTimings::default(),
            untimed_frames: 0,
        }
    }

    /// True when passes are actually timed.
    pub fn enabled(&self) -> bool {
        self.enabled
    }

    /// Starts frame `frame` with room for `passes` timed passes: collects what has arrived
    /// (without waiting) and takes a free slot, growing it if needed. When none is free the
    /// frame is not timed.
    pub fn begin_frame(&mut self, device: &wgpu::Device, frame: u64, passes: usize) {
        self.current = None;
        if !self.enabled {
            return;
        }
        self.collect(device, false);
        if self.slots.len() < SLOTS {
            self.slots.push(Slot::new(device, INITIAL_PASSES));
        }
        let index = self.next % self.slots.len();
        if self.slots[index].in_flight {
            self.untimed_frames += 1;
            return;
        }
        self.next = index + 1;
        let passes = u32::try_from(passes).unwrap_or(u32::MAX / 4);
        let slot = &mut self.slots[index];
        if passes > slot.capacity {
            *slot = Slot::new(device, passes.next_power_of_two());
        }
        slot.used = 0;
        slot.frame = frame;
        self.current = Some(index);
    }

    /// Reserves the timestamp pair of a pass named `name`: the query set and the pair's
    /// index, or `None` when this frame is not timed. A pass beyond the number reserved by
    /// [`begin_frame`](Self::begin_frame) is not timed, and says so in the log (once).
    fn reserve(&mut self, name: &str) -> Option<(&wgpu::QuerySet, u32)> {
        let slot = &mut self.slots[self.current?];
        let index = slot.used as u32;
        if index >= slot.capacity {
            if !self.overflowed {
                log::error!(
                    "pass `{name}` is not timed: the frame reserved {} timed passes (a bug in the renderer)",
                    slot.capacity
                );
                self.overflowed = true;
            }
            return None;
        }
        if slot.names.len() <= slot.used {
            slot.names.push(String::new());
        }
        slot.names[slot.used].clear();
        slot.names[slot.used].push_str(name);
        slot.used += 1;
        Some((&slot.query_sets[(index / SET_PASSES) as usize], index % SET_PASSES))
    }

    /// Timestamp writes for a render pass named `name`, or `None` when this frame is not
    /// timed (or the pass is beyond those reserved, which is logged once).
    pub fn pass(&mut self, name: &str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let (query_set, index) = self.reserve(name)?;
        Some(wgpu::RenderPassTimestampWrites {
            query_set,
            beginning_of_pass_write_index: Some(index * 2),
            end_of_pass_write_index: Some(index * 2 + 1),
        })
    }

    /// Timestamp writes for a compute pass named `name`.
    pub fn compute_pass(&mut self, name: &str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let (query_set, index) = self.reserve(name)?;
        Some(wgpu::ComputePassTimestampWrites {
            query_set,
            beginning_of_pass_write_index: Some(index * 2),
            end_of_pass_write_index: Some(index * 2 + 1),
        })
    }

    /// Records the resolve and the copy to the slot's readback buffer; call once, last.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        let Some(slot) = self.current.map(|i| &self.slots[i]) else {
            return;
        };
        let used = slot.used as u32;
        for (k, set) in (0..).zip(&slot.query_sets) {
            let passes = used.saturating_sub(k * SET_PASSES).min(SET_PASSES);
            if passes > 0 {
                slot.buffers
                    .resolve(encoder, set, passes * 2, u64::from(k * SET_PASSES) * 16);
            }
        }
        if used > 0 {
            slot.buffers.copy(encoder, u64::from(used) * 16);
        }
    }

    /// After the frame's submission: starts mapping the slot's readback (no waiting).
    pub fn submitted(&mut self) {
        let Some(slot) = self.current.take().map(|i| &mut self.slots[i]) else {
            return;
        };
        if slot.used == 0 {
            return;
        }
        slot.in_flight = true;
        slot.state.store(MAPPING, Ordering::Release);
        let state = Arc::clone(&slot.state);
        slot.buffers
            .readback
            .slice(..slot.used as u64 * 16)
            .map_async(wgpu::MapMode::Read, move |result| {
                state.store(if result.is_ok() { MAPPED } else { FAILED }, Ordering::Release);
            });
    }

    /// Reads back every slot whose mapping has finished, polling the device once (or, with
    /// `wait`, until every frame in flight has arrived).
    fn collect(&mut self, device: &wgpu::Device, wait: bool) {
        if !self.slots.iter().any(|s| s.in_flight) {
            return;
        }
        // NOTE: a failed poll leaves the slots in flight; they are looked at again next time.
        poll_device(device, wait);
        // NOTE: oldest arrived slot first, found again each time (three slots; no list).
        while let Some(i) = (0..self.slots.len())
            .filter(|&i| self.slots[i].in_flight && self.slots[i].state.load(Ordering::Acquire) >= MAPPED)
            .min_by_key(|&i| self.slots[i].frame)
        {
            let timings = self.slots[i].take(self.period_ns);
            if self.completed.len() >= KEPT {
                self.completed.remove(0);
            }
            self.latest.clone_from(&timings);
            self.completed.push(timings);
        }
    }

    /// Reads back what has arrived, without waiting.
    pub fn poll(&mut self, device: &wgpu::Device) {
        self.collect(device, false);
    }

    /// The newest timings read back (empty before any has arrived).
    pub fn latest(&self) -> &FrameTimings {
        &self.latest
    }

    /// The timings that have arrived since the last call, oldest first (without waiting).
    pub fn take_completed(&mut self, device: &wgpu::Device) -> Vec<FrameTimings> {
        self.collect(device, false);
        std::mem::take(&mut self.completed)
    }

    /// Waits for every frame in flight and returns the timings not yet taken, oldest first.
    pub fn wait(&mut self, device: &wgpu::Device) -> Vec<FrameTimings> {
        self.collect(device, true);
        std::mem::take(&mut self.completed)
    }
}

/// The median of `v` (the upper middle value of an even count; NaN when empty).
pub fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The median time of each pass over the frames after the first (which builds pipelines),
/// for the passes of the last timed frame, in its order.
pub fn median_passes(frames: &[Vec<PassTiming>]) -> Vec<(String, f64)> {
    let steady = if frames.len() > 1 { &frames[1..] } else { frames };
    let Some(last) = steady.iter().rev().find(|f| !f.is_empty()) else {
        return Vec::new();
    };
    last.iter()
        .map(|p| {
            let samples = steady
                .iter()
                .filter_map(|f| f.iter().find(|q| q.name == p.name))
                .map(|q| q.ms)
                .collect();
            (p.name.clone(), median(samples))
        })
        .collect()
}

/// The spread of whole-frame GPU times (each frame's passes summed) over the frames after
/// the first that have timings: what a frame costs where passes run only some frames (a
/// shadow map drawn again only when its view moved), which per-pass medians hide.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSpread {
    /// Median frame, ms.
    pub median: f64,
    /// Mean frame, ms.
    pub mean: f64,
    /// Slowest frame, ms.
    pub max: f64,
    /// Frames counted.
    pub frames: usize,
}

/// The [`FrameSpread`] of `frames` (None where no frame after the first has timings).
pub fn frame_spread(frames: &[Vec<PassTiming>]) -> Option<FrameSpread> {
    let steady = if frames.len() > 1 { &frames[1..] } else { frames };
    let totals: Vec<f64> = steady
        .iter()
        .filter(|f| !f.is_empty())
        .map(|f| f.iter().map(|p| p.ms).sum())
        .collect();
    if totals.is_empty() {
        return None;
    }
    Some(FrameSpread {
        mean: totals.iter().sum::<f64>() / totals.len() as f64,
        max: totals.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        frames: totals.len(),
        median: median(totals),
    })
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
    fn pass_medians_skip_the_first_frame() {
        let pass = |ms| {
            vec![PassTiming {
                name: "shadow".into(),
                ms,
            }]
        };
        let frames = [pass(9.0), pass(1.0), pass(3.0), pass(2.0)];
        assert_eq!(median_passes(&frames), [("shadow".to_string(), 2.0)]);
        assert!(median_passes(&[]).is_empty());
    }

    #[test]
    fn frame_spread_sums_each_frame_and_skips_the_first() {
        let pass = |name: &str, ms| PassTiming { name: name.into(), ms };
        let frames = [
            vec![pass("shadow", 50.0)],
            vec![pass("shadow", 4.0), pass("main", 1.0)],
            vec![pass("main", 1.0)],
            vec![],
            vec![pass("main", 2.0)],
        ];
        let s = frame_spread(&frames).unwrap();
        assert_eq!((s.frames, s.median, s.max), (3, 2.0, 5.0));
        assert!((s.mean - 8.0 / 3.0).abs() < 1e-12);
        assert_eq!(frame_spread(&[vec![], vec![]]), None);
    }
}
