//! GPU pass timings from timestamp queries: each timed pass writes a begin and an end
//! timestamp; after the frame's submission the pairs are read back and turned into
//! milliseconds.

use crate::render::readback::read_buffer;

/// Most passes that can be timed in one frame.
const MAX_PASSES: u32 = 16;

/// Collects timestamp pairs for named passes of one frame.
pub struct GpuTimer {
    query_set: Option<wgpu::QuerySet>,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    names: Vec<&'static str>,
    period_ns: f32,
}

/// The time one pass took on the GPU.
#[derive(Clone, Debug, PartialEq)]
pub struct PassTiming {
    /// Pass name.
    pub name: &'static str,
    /// Milliseconds between the pass's begin and end timestamps.
    pub ms: f64,
}

impl GpuTimer {
    /// Creates the query set when `enabled` (the adapter supports timestamps).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, enabled: bool) -> Self {
        let size = (MAX_PASSES * 2) as u64 * 8;
        let query_set = enabled.then(|| {
            device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: MAX_PASSES * 2,
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
        Self {
            query_set,
            resolve,
            readback,
            names: Vec::new(),
            period_ns: queue.get_timestamp_period(),
        }
    }

    /// True when passes are actually timed.
    pub fn enabled(&self) -> bool {
        self.query_set.is_some()
    }

    /// Forgets last frame's passes.
    pub fn begin_frame(&mut self) {
        self.names.clear();
    }

    /// Timestamp writes for a pass named `name`, or `None` when timing is off or full.
    pub fn pass(&mut self, name: &'static str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let query_set = self.query_set.as_ref()?;
        let index = self.names.len() as u32;
        if index >= MAX_PASSES {
            return None;
        }
        self.names.push(name);
        Some(wgpu::RenderPassTimestampWrites {
            query_set,
            beginning_of_pass_write_index: Some(index * 2),
            end_of_pass_write_index: Some(index * 2 + 1),
        })
    }

    /// Records the resolve and the copy to the readback buffer; call once, last.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some(query_set) = &self.query_set
            && !self.names.is_empty()
        {
            let count = self.names.len() as u32 * 2;
            encoder.resolve_query_set(query_set, 0..count, &self.resolve, 0);
            encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, count as u64 * 8);
        }
    }

    /// Reads the timings back after the frame's submission (waits for the GPU).
    pub fn read(&self, device: &wgpu::Device) -> Vec<PassTiming> {
        if self.query_set.is_none() || self.names.is_empty() {
            return Vec::new();
        }
        let Some(bytes) = read_buffer(device, &self.readback, self.names.len() as u64 * 16) else {
            return Vec::new();
        };
        let ticks: Vec<u64> = bytes
            .chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
            .collect();
        self.names
            .iter()
            .enumerate()
            .map(|(i, &name)| {
                let delta = ticks[i * 2 + 1].saturating_sub(ticks[i * 2]);
                PassTiming {
                    name,
                    ms: delta as f64 * self.period_ns as f64 / 1e6,
                }
            })
            .collect()
    }
}
