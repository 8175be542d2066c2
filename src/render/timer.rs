//! GPU pass timings from timestamp queries: each timed pass writes a begin and an end
//! timestamp; after the frame's submission the pairs are read back and turned into
//! milliseconds.

use crate::render::readback::read_buffer;

/// Passes reserved before the first frame asks for more.
const INITIAL_PASSES: u32 = 16;

/// Collects timestamp pairs for named passes of one frame.
pub struct GpuTimer {
    query_set: Option<wgpu::QuerySet>,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// Pass names of this frame (the first `used`), keeping their allocations.
    names: Vec<String>,
    used: usize,
    capacity: u32,
    overflowed: bool,
    period_ns: f32,
}

/// The time one pass took on the GPU.
#[derive(Clone, Debug, PartialEq)]
pub struct PassTiming {
    /// Pass name.
    pub name: String,
    /// Milliseconds between the pass's begin and end timestamps.
    pub ms: f64,
}

/// The query set and buffers for `passes` timed passes.
fn create(device: &wgpu::Device, enabled: bool, passes: u32) -> (Option<wgpu::QuerySet>, wgpu::Buffer, wgpu::Buffer) {
    let size = u64::from(passes * 2) * 8;
    let query_set = enabled.then(|| {
        device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: passes * 2,
        })
    });
    let resolve = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("timestamp resolve"),
        size,
        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("timestamp readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    (query_set, resolve, readback)
}

impl GpuTimer {
    /// Creates the query set when `enabled` (the adapter supports timestamps).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, enabled: bool) -> Self {
        let (query_set, resolve, readback) = create(device, enabled, INITIAL_PASSES);
        Self {
            query_set,
            resolve,
            readback,
            names: Vec::new(),
            used: 0,
            capacity: INITIAL_PASSES,
            overflowed: false,
            period_ns: queue.get_timestamp_period(),
        }
    }

    /// True when passes are actually timed.
    pub fn enabled(&self) -> bool {
        self.query_set.is_some()
    }

    /// Forgets last frame's passes and makes room for `passes` timed passes this frame (the
    /// query set grows; it never shrinks).
    pub fn begin_frame(&mut self, device: &wgpu::Device, passes: usize) {
        self.used = 0;
        let passes = u32::try_from(passes).unwrap_or(u32::MAX / 4);
        if self.query_set.is_some() && passes > self.capacity {
            let capacity = passes.next_power_of_two();
            (self.query_set, self.resolve, self.readback) = create(device, true, capacity);
            self.capacity = capacity;
        }
    }

    /// Timestamp writes for a pass named `name`, or `None` when timing is off. A pass beyond
    /// the number reserved by [`begin_frame`](Self::begin_frame) is not timed, and says so in
    /// the log (once).
    pub fn pass(&mut self, name: &str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let query_set = self.query_set.as_ref()?;
        let index = self.used as u32;
        if index >= self.capacity {
            if !self.overflowed {
                log::error!(
                    "pass `{name}` is not timed: the frame reserved {} timed passes (a bug in the renderer)",
                    self.capacity
                );
                self.overflowed = true;
            }
            return None;
        }
        if self.names.len() <= self.used {
            self.names.push(String::new());
        }
        self.names[self.used].clear();
        self.names[self.used].push_str(name);
        self.used += 1;
        Some(wgpu::RenderPassTimestampWrites {
            query_set,
            beginning_of_pass_write_index: Some(index * 2),
            end_of_pass_write_index: Some(index * 2 + 1),
        })
    }

    /// Records the resolve and the copy to the readback buffer; call once, last.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some(query_set) = &self.query_set
            && self.used > 0
        {
            let count = self.used as u32 * 2;
            encoder.resolve_query_set(query_set, 0..count, &self.resolve, 0);
            encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, count as u64 * 8);
        }
    }

    /// Reads the timings back after the frame's submission (waits for the GPU).
    pub fn read(&self, device: &wgpu::Device) -> Vec<PassTiming> {
        if self.query_set.is_none() || self.used == 0 {
            return Vec::new();
        }
        let Some(bytes) = read_buffer(device, &self.readback, self.used as u64 * 16) else {
            return Vec::new();
        };
        let ticks: Vec<u64> = bytes
            .chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
            .collect();
        self.names[..self.used]
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let delta = ticks[i * 2 + 1].saturating_sub(ticks[i * 2]);
                PassTiming {
                    name: name.clone(),
                    ms: delta as f64 * self.period_ns as f64 / 1e6,
                }
            })
            .collect()
    }
}
