//! The depth-bounds reduction of the sample-distribution (SDSM) cascade fit: after the camera's
//! depth is complete, one compute pass reduces it to the view-depth range and per-band world
//! boxes the frame covered ([`SeenDepths`]), into a buffer copied to one slot of a small
//! ring of mappable buffers. After submission the slot is mapped without waiting; a later
//! frame decodes whichever slot has come back ([`SeenReadback::latest`]), so the CPU never
//! stalls on the GPU. It runs only while a shadowed sun fits its cascades with
//! [`CascadeFit::DepthBounds`]; otherwise it declares nothing and is culled.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

use glam::Vec3;

use crate::math::seen_depths::{SEEN_WORDS, SeenDepths, initial_words};
use crate::render::frame::{FrameContext, FrameInputs};
use crate::render::graph::{FrameResources, GraphResources, PassBuilder, RenderNode, TextureId};
use crate::render::layouts::{Layouts, camera_texture_entry, entry, main_compute_pipeline};
use crate::render::readback::poll_device;
use crate::settings::CascadeFit;
use crate::shader::ShaderLibrary;

/// Name of the reduction in GPU timings and the graph.
pub const DEPTH_BOUNDS_NAME: &str = "depth bounds";

/// Readback buffers in flight at most: a slot is reused once its words have been read.
const SLOTS: usize = 3;

const BYTES: u64 = (SEEN_WORDS * 4) as u64;

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
    reduce: Option<wgpu::Buffer>,
    /// The words it starts from, and the band limits they were written for (uploaded only
    /// when the camera's near or far plane changes).
    init: Option<(wgpu::Buffer, (f32, f32))>,
    buffers: Vec<wgpu::Buffer>,
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
    fn reset(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        encoder: &mut wgpu::CommandEncoder,
        planes: (f32, f32),
    ) {
        let buffer = |usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(DEPTH_BOUNDS_NAME),
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
    fn take_slot(&mut self, device: &wgpu::Device, origin: Vec3) -> Option<usize> {
        if self.buffers.is_empty() {
            self.buffers = (0..SLOTS)
                .map(|_| {
                    device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some(DEPTH_BOUNDS_NAME),
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

/// What the reduction reads this frame.
#[derive(Clone, Copy)]
struct Handles {
    depth: TextureId,
    samples: u32,
    /// The depth's size in pixels.
    size: (u32, u32),
    /// The camera's near and far planes (the bands' limits).
    planes: (f32, f32),
    origin: Vec3,
}

/// The reduction node: a layout and a pipeline per depth kind (single-sample, multisampled).
#[derive(Default)]
pub struct DepthBoundsPass {
    layouts: [Option<wgpu::BindGroupLayout>; 2],
    pipelines: [Option<wgpu::ComputePipeline>; 2],
    handles: Option<Handles>,
}

fn create_layout(device: &wgpu::Device, multisampled: bool) -> wgpu::BindGroupLayout {
    let entry = |binding, ty| entry(binding, wgpu::ShaderStages::COMPUTE, ty);
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(DEPTH_BOUNDS_NAME),
        entries: &[
            camera_texture_entry(0, wgpu::TextureSampleType::Depth, multisampled),
            entry(
                1,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: false },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
            ),
        ],
    })
}

fn create_pipeline(
    device: &wgpu::Device,
    layouts: &Layouts,
    library: &mut ShaderLibrary,
    layout: &wgpu::BindGroupLayout,
    multisampled: bool,
) -> wgpu::ComputePipeline {
    let module = library
        .depth_bounds(multisampled)
        .expect("the shipped depth-bounds shader composes (checked by tests)");
    main_compute_pipeline(device, DEPTH_BOUNDS_NAME, module, &[Some(&layouts.view), Some(layout)])
}

/// Whether a shadowed sun of the frame fits its cascades to the depths seen.
pub fn wants_depth_bounds(inputs: &FrameInputs<'_>) -> bool {
    inputs
        .lights
        .suns
        .iter()
        .any(|sun| sun.settings.fit == CascadeFit::DepthBounds && sun.cascades.count > 0)
}

impl RenderNode for DepthBoundsPass {
    fn name(&self) -> &'static str {
        DEPTH_BOUNDS_NAME
    }

    /// Reads the camera's depth; kept for its readback. Nothing when no sun fits to it.
    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, inputs: &FrameInputs<'_>) {
        self.handles = None;
        let (Some(depth), Some((camera, _))) = (frame.depth, inputs.view.camera) else {
            return;
        };
        if !wants_depth_bounds(inputs) {
            return;
        }
        pass.read(depth);
        pass.side_effect();
        self.handles = Some(Handles {
            depth,
            samples: frame.samples.max(1),
            size: frame.size,
            planes: (camera.near, camera.far),
            origin: inputs.origin,
        });
    }

    fn record(&mut self, ctx: &mut FrameContext<'_>, resources: &GraphResources, encoder: &mut wgpu::CommandEncoder) {
        let Some(handles) = self.handles else {
            return;
        };
        let (near, far) = handles.planes;
        if !(near > 0.0 && far > near && far.is_finite()) {
            return;
        }
        let device = &ctx.gpu.device;
        let Some(slot) = ctx.seen.take_slot(device, handles.origin) else {
            return;
        };
        let multisampled = handles.samples > 1;
        let layout = self.layouts[multisampled as usize].get_or_insert_with(|| create_layout(device, multisampled));
        let pipeline = self.pipelines[multisampled as usize]
            .get_or_insert_with(|| create_pipeline(device, ctx.layouts, ctx.library, layout, multisampled));
        ctx.seen.reset((device, &ctx.gpu.queue), encoder, (near, far));
        let seen = &*ctx.seen;
        let Some(reduce) = &seen.reduce else {
            return;
        };
        // NOTE: the depth is a transient of this frame, so the group is made per frame.
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(DEPTH_BOUNDS_NAME),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(resources.view(handles.depth)),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: reduce.as_entire_binding(),
                },
            ],
        });
        let (width, height) = handles.size;
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(DEPTH_BOUNDS_NAME),
                timestamp_writes: ctx.timer.compute_pass(DEPTH_BOUNDS_NAME),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &ctx.scene.view_group, &[]);
            pass.set_bind_group(1, &group, &[]);
            pass.dispatch_workgroups(width.div_ceil(16), height.div_ceil(16), 1);
        }
        encoder.copy_buffer_to_buffer(reduce, 0, &seen.buffers[slot], 0, BYTES);
    }
}
