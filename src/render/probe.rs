//! Shadow probes: evaluates one light's shadow at fixed world points with a compute pass
//! that calls the same `shadow_visibility` as every material. Used to measure temporal
//! stability: the same points are evaluated while the camera moves.

use std::collections::HashMap;
use std::num::NonZeroU64;

use bytemuck::{Pod, Zeroable};
use glam::{Vec3, Vec4};
use wgpu::util::DeviceExt;

use crate::render::context::GpuContext;
use crate::render::layouts::{Layouts, main_compute_pipeline};
use crate::render::readback::read_buffer;
use crate::shader::{ForwardVariant, ShaderLibrary};

/// Mirror of WGSL `Probe` in `probe.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ProbeGpu {
    /// xyz: world position, w: pixel x (seeds the per-pixel noise as in the forward pass).
    pub position: Vec4,
    /// xyz: unit normal, w: pixel y.
    pub normal: Vec4,
}

impl ProbeGpu {
    /// A probe at `position` with `normal`, seen at pixel `(x, y)`.
    pub fn new(position: Vec3, normal: Vec3, (x, y): (u32, u32)) -> Self {
        Self {
            position: position.extend(x as f32),
            normal: normal.extend(y as f32),
        }
    }
}

/// Pipelines (one per shadow filter) and the bind group layout of the probe pass.
pub struct ProbePass {
    layout: wgpu::BindGroupLayout,
    pipelines: HashMap<ForwardVariant, wgpu::ComputePipeline>,
}

impl ProbePass {
    /// Creates the bind group layout; pipelines are built on first use.
    pub fn new(device: &wgpu::Device) -> Self {
        let storage = |binding, read_only, size: u64| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: NonZeroU64::new(size),
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("probes"),
            entries: &[storage(0, true, size_of::<ProbeGpu>() as u64), storage(1, false, 4)],
        });
        Self {
            layout,
            pipelines: HashMap::new(),
        }
    }

    /// Evaluates the focus light's shadow at every probe with the filters of `variant`, using
    /// the view and shadow groups of the frame just rendered, and waits for the results.
    pub fn evaluate(
        &mut self,
        gpu: &GpuContext,
        layouts: &Layouts,
        library: &mut ShaderLibrary,
        variant: ForwardVariant,
        groups: [&wgpu::BindGroup; 2],
        probes: &[ProbeGpu],
    ) -> Vec<f32> {
        if probes.is_empty() {
            return Vec::new();
        }
        let device = &gpu.device;
        let key = ForwardVariant {
            debug_cascades: false,
            alpha_mask: false,
            analysis: false,
            ..variant
        };
        let probe_layout = &self.layout;
        let pipeline = self.pipelines.entry(key).or_insert_with(|| {
            let module = library
                .probe(key)
                .expect("the shipped probe shader composes (checked by tests)");
            main_compute_pipeline(
                device,
                "probe",
                module,
                &[Some(&layouts.view), Some(probe_layout), None, Some(&layouts.shadows)],
            )
        });
        let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("probes"),
            contents: bytemuck::cast_slice(probes),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let size = (probes.len() * 4) as u64;
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("probe results"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("probe readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("probes"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: input.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: output.as_entire_binding(),
                },
            ],
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("probes") });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("probes"),
                timestamp_writes: None,
            });
            pass.set_pipeline(pipeline);
            let [view_group, shadow_group] = groups;
            pass.set_bind_group(0, view_group, &[]);
            pass.set_bind_group(1, &group, &[]);
            pass.set_bind_group(3, shadow_group, &[]);
            pass.dispatch_workgroups((probes.len() as u32).div_ceil(64), 1, 1);
        }
        encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, size);
        gpu.queue.submit([encoder.finish()]);
        match read_buffer(device, &readback, size) {
            Some(bytes) => bytes
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
            None => vec![f32::NAN; probes.len()],
        }
    }
}
