//! The paged clipmap's marking on the GPU (`shaders/pages_mark.wgsl`): one compute dispatch
//! over the camera's depth sets a bit for every page some receiver's filter reads, by the
//! rules of [`mark_receiver`](crate::math::pages::mark_receiver) (the mirror the tests
//! compare it with), into the bitset [`PageAllocator`](crate::render::shadows::page_allocate::PageAllocator)
//! reads.

use std::borrow::Cow;

use bytemuck::{Pod, Zeroable};
use glam::{Mat3, Mat4, UVec2};

use crate::math::pages::{MarkRule, PageLayout, PagedLevel};
use crate::render::layouts::camera_texture_entry;
use crate::render::shadows::jobs::{compute_pipeline, storage_entry, uniform_entry};
use crate::render::shadows::page_allocate::MAX_PAGED_LEVELS;
use crate::shader::ShaderLibrary;

/// Mirror of WGSL `Mark`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct MarkGpu {
    world_from_clip: Mat4,
    light_from_world: Mat4,
    size: UVec2,
    levels: u32,
    pages_per_side: u32,
    page_size: f32,
    virtual_resolution: f32,
    radius: f32,
    margin: f32,
    blend: f32,
    pixel: f32,
    _pad: [f32; 2],
    level: [[f32; 4]; MAX_PAGED_LEVELS],
}

/// What one marking reads besides the depth.
#[derive(Clone, Copy, Debug)]
pub struct MarkInput<'a> {
    /// World (relative to the render origin) from the camera's clip space (reverse-Z).
    pub world_from_clip: Mat4,
    /// The light's frame from world.
    pub light_rotation: Mat3,
    /// How the levels are cut into pages.
    pub layout: PageLayout,
    /// The levels' windows, finest first (at most [`MAX_PAGED_LEVELS`]).
    pub levels: &'a [PagedLevel],
    /// The receivers' footprint and the levels' margins.
    pub rule: MarkRule,
}

/// The marking pipeline and its uniforms.
pub struct PageMark {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
}

impl PageMark {
    /// The pipeline, composed from the shader library, reading a single-sample or
    /// (`multisampled`) a multisampled camera depth at sample 0.
    pub fn new(device: &wgpu::Device, library: &mut ShaderLibrary, multisampled: bool) -> Self {
        let module = library
            .pages_mark(multisampled)
            .expect("the shipped marking shader composes (checked by tests)");
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("page marking"),
            source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
        });
        let compute = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("page marking"),
            entries: &[
                camera_texture_entry(0, wgpu::TextureSampleType::Depth, multisampled),
                uniform_entry(1, compute, false, size_of::<MarkGpu>() as u64),
                storage_entry(2, compute, false),
            ],
        });
        let pipeline = compute_pipeline(device, "page marking", &shader, &layout, "main");
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("page marking"),
            size: size_of::<MarkGpu>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            pipeline,
            layout,
            uniforms,
        }
    }

    /// The group a marking reads `depth` through and writes `needed` through: made once
    /// per depth allocation by the caller, not per frame.
    pub fn group(&self, device: &wgpu::Device, depth: &wgpu::TextureView, needed: &wgpu::Buffer) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("page marking"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(depth),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: self.uniforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: needed.as_entire_binding(),
                },
            ],
        })
    }

    /// Records the marking of the depth `group` reads (`size` pixels) into its bitset
    /// `needed` (cleared first), timed by `timestamps`.
    pub fn record(
        &self,
        (queue, encoder): (&wgpu::Queue, &mut wgpu::CommandEncoder),
        (group, size): (&wgpu::BindGroup, UVec2),
        input: &MarkInput<'_>,
        needed: &wgpu::Buffer,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let mut level = [[0.0; 4]; MAX_PAGED_LEVELS];
        for (l, paged) in level.iter_mut().zip(input.levels) {
            let first = paged.first_texel.as_vec2();
            *l = [first.x, first.y, paged.texel as f32, 0.0];
        }
        let data = MarkGpu {
            world_from_clip: input.world_from_clip,
            light_from_world: Mat4::from_mat3(input.light_rotation),
            size,
            levels: input.levels.len().min(MAX_PAGED_LEVELS) as u32,
            pages_per_side: input.layout.pages_per_side(),
            page_size: input.layout.page_size as f32,
            virtual_resolution: input.layout.virtual_resolution as f32,
            radius: input.rule.radius as f32,
            margin: input.rule.margin as f32,
            blend: input.rule.blend as f32,
            pixel: input.rule.pixel as f32,
            _pad: [0.0; 2],
            level,
        };
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&data));
        encoder.clear_buffer(needed, 0, None);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("page marking"),
            timestamp_writes: timestamps,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.dispatch_workgroups(size.x.div_ceil(8), size.y.div_ceil(8), 1);
    }
}

#[cfg(test)]
mod tests {
    use std::mem::offset_of;

    use super::*;
    use crate::render::shadows::jobs::layout_check::wgsl_layout;

    #[test]
    fn the_uniforms_match_the_wgsl_layout() {
        let module = ShaderLibrary::new().unwrap().pages_mark(false).unwrap();
        let rust: Vec<(String, usize)> = [
            ("world_from_clip", offset_of!(MarkGpu, world_from_clip)),
            ("light_from_world", offset_of!(MarkGpu, light_from_world)),
            ("size", offset_of!(MarkGpu, size)),
            ("levels", offset_of!(MarkGpu, levels)),
            ("pages_per_side", offset_of!(MarkGpu, pages_per_side)),
            ("page_size", offset_of!(MarkGpu, page_size)),
            ("virtual_resolution", offset_of!(MarkGpu, virtual_resolution)),
            ("radius", offset_of!(MarkGpu, radius)),
            ("margin", offset_of!(MarkGpu, margin)),
            ("blend", offset_of!(MarkGpu, blend)),
            ("pixel", offset_of!(MarkGpu, pixel)),
            ("level", offset_of!(MarkGpu, level)),
        ]
        .iter()
        .map(|(n, o)| (n.to_string(), *o))
        .collect();
        assert_eq!(wgsl_layout(&module, "Mark"), (rust, size_of::<MarkGpu>()));
    }
}
