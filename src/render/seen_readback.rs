//! The depth-bounds reduction's readback ring ([`SeenReadback`]): a few mappable buffers, each
//! taking one frame's reduced words; a slot is mapped after submission without waiting, and a
//! later frame decodes whichever slot has come back, so the CPU never stalls on the GPU.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

use glam::Vec3;

use crate::math::seen_depths::{SEEN_WORDS, SeenDepths, initial_words};
use crate::render::readback::poll_device;

/// Label of the ring's buffers.
const LABEL: &str = "depth bounds readback";

/// Readback buffers in flight at most: a slot is reused once its words have been read.
const SLOTS: usize = 3;

/// Bytes of one reduction's words.
pub(crate) const BYTES: u64 = (SEEN_WORDS * 4) as u64;

/// Where a slot's mapping stands (shared with the map callback).
const MAP_PENDING: u8 = 0;
const MAP_DONE: u8 = 1;
const MAP_FAILED: u8 = 2;

/// One readback buffer and what it holds.
enum Slot {
    /// Free to take this frame's words.
    Free,
    /// Holds the copy of reduction `serial`, recorded in a frame not yet submitted, or
    /// submitted and not yet mapped.
    Copied { serial: u64, origin: Vec3 },
    /// Being mapped; `state` turns to done or failed in the callback.
    Mapping {
        serial: u64,
        origin: Vec3,
        state: Arc<AtomicU8>,
    },
}

/// The reduction's buffers and the latest depths that came back.
pub struct SeenReadback {
    /// The words the reduction accumulates into, reset from `init` each frame.
    pub(crate) reduce: Option<wgpu::Buffer>,
    /// The words it starts from, and the band limits they were written for (uploaded only
    /// when the camera's near or far plane changes).
    init: Option<(wgpu::Buffer, (f32, f32))>,
    pub(crate) buffers: Vec<wgpu::Buffer>,
    slots: [Slot; SLOTS],
    serial: u64,
    latest: Option<(u64, SeenDepths, Vec3)>,
}

impl Default for SeenReadback {
    fn default() -> Self {
        Self {
            reduce: None,
            init: None,
            buffers: Vec::new(),
            slots: std::array::from_fn(|_| Slot::Free),
            serial: 0,
            latest: None,
        }
    }
}

impl SeenReadback {
    /// The most recent reduction that came back: what the camera saw, and the render origin
    /// its world boxes are relative to. None until one has (or when no pixel was covered).
    pub fn latest(&self) -> Option<(SeenDepths, Vec3)> {
        self.latest.map(|(_, seen, origin)| (seen, origin))
    }

    /// After the frame's submission: starts mapping the slot copied this frame, then reads
    /// every slot whose mapping has finished (polling the device once; with `wait`, waiting
    /// for all of them).
    pub fn after_submit(&mut self, device: &wgpu::Device, wait: bool) {
        for (slot, buffer) in self.slots.iter_mut().zip(&self.buffers) {
            if let Slot::Copied { serial, origin } = *slot {
                let state = Arc::new(AtomicU8::new(MAP_PENDING));
                let done = state.clone();
                buffer.slice(..BYTES).map_async(wgpu::MapMode::Read, move |result| {
                    done.store(if result.is_ok() { MAP_DONE } else { MAP_FAILED }, Ordering::Release);
                });
                *slot = Slot::Mapping { serial, origin, state };
            }
        }
        if !self.slots.iter().any(|s| matches!(s, Slot::Mapping { .. })) {
            return;
        }
        // NOTE: a failed poll leaves the slots mapping; they are looked at again next frame.
        poll_device(device, wait);
        for (slot, buffer) in self.slots.iter_mut().zip(&self.buffers) {
            let Slot::Mapping { serial, origin, state } = slot else {
                continue;
            };
            match state.load(Ordering::Acquire) {
                MAP_PENDING => continue,
                MAP_DONE => {
                    let mut words = [0u32; SEEN_WORDS];
                    let read = buffer.slice(..BYTES).get_mapped_range().ok().map(|data| {
                        for (w, b) in words.iter_mut().zip(data.chunks_exact(4)) {
                            *w = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                        }
                    });
                    buffer.unmap();
                    let newer = self.latest.is_none_or(|(s, _, _)| s < *serial);
                    if newer && read.is_some() {
                        // NOTE: a frame that covered no pixel leaves no depths.
                        self.latest = SeenDepths::from_words(&words).map(|seen| (*serial, seen, *origin));
                    }
                }
                _ => buffer.unmap(),
            }
            *slot = Slot::Free;
        }
    }

    /// Records the reset of the reduction's words (`reduce`) to their start for bands between
    /// `planes`, uploading the start only when the planes changed.
    pub(crate) fn reset(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        encoder: &mut wgpu::CommandEncoder,
        planes: (f32, f32),
    ) {
        let buffer = |usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(LABEL),
                size: BYTES,
                usage,
                mapped_at_creation: false,
            })
        };
        if self.init.as_ref().is_none_or(|(_, written)| *written != planes) {
            let init = match self.init.take() {
                Some((init, _)) => init,
                None => buffer(wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST),
            };
            let words = initial_words(planes.0, planes.1);
            queue.write_buffer(&init, 0, bytemuck::cast_slice(&words));
            self.init = Some((init, planes));
        }
        let reduce = self.reduce.get_or_insert_with(|| {
            buffer(wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST)
        });
        if let Some((init, _)) = &self.init {
            encoder.copy_buffer_to_buffer(init, 0, reduce, 0, BYTES);
        }
    }

    /// Takes a free slot for this frame's copy (None when every slot is still in flight:
    /// this frame's depths are skipped).
    pub(crate) fn take_slot(&mut self, device: &wgpu::Device, origin: Vec3) -> Option<usize> {
        if self.buffers.is_empty() {
            self.buffers = (0..SLOTS)
                .map(|_| {
                    device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some(LABEL),
                        size: BYTES,
                        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                        mapped_at_creation: false,
                    })
                })
                .collect();
        }
        let index = self.slots.iter().position(|s| matches!(s, Slot::Free))?;
        self.serial += 1;
        self.slots[index] = Slot::Copied {
            serial: self.serial,
            origin,
        };
        Some(index)
    }
}
