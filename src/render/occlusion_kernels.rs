//! The occlusion culling's pipelines, depth pyramid and bind groups
//! ([`OcclusionGpu`](crate::render::occlusion::OcclusionGpu) owns them).

use crate::math::occlusion::level_count;
use crate::render::layouts::main_compute_pipeline;
use crate::render::readback::copy_and_read;
use crate::shader::ShaderLibrary;

/// A compute-visible binding of `ty`.
fn entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty,
        count: None,
    }
}

/// A storage buffer binding.
fn storage(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
    )
}

/// Pipelines and layouts.
pub(crate) struct Kernels {
    pub cull_layout: wgpu::BindGroupLayout,
    pub early: wgpu::ComputePipeline,
    pub late: wgpu::ComputePipeline,
    first_layout: wgpu::BindGroupLayout,
    down_layout: wgpu::BindGroupLayout,
    pub first: wgpu::ComputePipeline,
    pub down: wgpu::ComputePipeline,
}

impl Kernels {
    /// Builds the pipelines.
    ///
    /// # Panics
    /// If the shipped shaders do not compose (checked by the shader tests).
    pub fn new(device: &wgpu::Device, library: &mut ShaderLibrary) -> Kernels {
        let uniform = entry(
            0,
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
        );
        let cull_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("occlusion cull"),
            entries: &[
                uniform,
                storage(1, true),
                storage(2, true),
                storage(3, true),
                storage(4, false),
                storage(5, false),
                storage(6, false),
                storage(7, true),
            ],
        });
        let level_uniform = entry(
            0,
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
        );
        let depth = entry(
            2,
            wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Depth,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
        );
        let first_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("occlusion pyramid level 0"),
            entries: &[level_uniform, storage(1, false), depth],
        });
        let down_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("occlusion pyramid level"),
            entries: &[level_uniform, storage(1, false)],
        });
        let composed = "the shipped occlusion shaders compose (checked by tests)";
        let cull = |library: &mut ShaderLibrary, late| {
            let module = library.occlusion_cull(late).expect(composed);
            main_compute_pipeline(device, "occlusion cull", module, &[Some(&cull_layout)])
        };
        let (early, late) = (cull(library, false), cull(library, true));
        let first = main_compute_pipeline(
            device,
            "occlusion pyramid level 0",
            library.occlusion_pyramid(true).expect(composed),
            &[Some(&first_layout)],
        );
        let down = main_compute_pipeline(
            device,
            "occlusion pyramid level",
            library.occlusion_pyramid(false).expect(composed),
            &[Some(&down_layout)],
        );
        Kernels {
            cull_layout,
            early,
            late,
            first_layout,
            down_layout,
            first,
            down,
        }
    }

    /// The bind group of one level's build: `uniform` describes it, `depth` (level 0 only)
    /// is read.
    fn level_group(
        &self,
        device: &wgpu::Device,
        uniform: &wgpu::Buffer,
        pyramid: &wgpu::Buffer,
        depth: Option<&wgpu::TextureView>,
    ) -> wgpu::BindGroup {
        let buffers = [
            wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: pyramid.as_entire_binding(),
            },
        ];
        let (layout, entries): (_, Vec<wgpu::BindGroupEntry<'_>>) = match depth {
            Some(view) => (
                &self.first_layout,
                buffers
                    .into_iter()
                    .chain([wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(view),
                    }])
                    .collect(),
            ),
            None => (&self.down_layout, buffers.into_iter().collect()),
        };
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("occlusion pyramid level"),
            layout,
            entries: &entries,
        })
    }
}

/// One level's description, as `Level` in the pyramid shader.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct LevelGpu {
    size: [u32; 2],
    offset: u32,
    above_offset: u32,
    above: [u32; 2],
    _pad: [u32; 2],
}

/// The depth pyramid: one storage buffer holding every level, each level's uniforms, and the
/// bind groups that build the levels after the first from the one above.
pub(crate) struct Pyramid {
    pub size: (u32, u32),
    /// Every level, one after the other (rows top to bottom).
    pub buffer: wgpu::Buffer,
    /// Each level's width, height and first texel.
    levels: Vec<(u32, u32, u32)>,
    uniforms: Vec<wgpu::Buffer>,
    down: Vec<wgpu::BindGroup>,
    /// The first level's bind group, and the depth view it reads.
    first: Option<(wgpu::TextureView, wgpu::BindGroup)>,
}

impl Pyramid {
    /// A pyramid over a `size` depth buffer.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, kernels: &Kernels, size: (u32, u32)) -> Pyramid {
        let mut levels = Vec::new();
        let (mut w, mut h, mut offset) = (size.0.max(1), size.1.max(1), 0);
        for _ in 0..level_count(size.0, size.1) {
            levels.push((w, h, offset));
            offset += w * h;
            (w, h) = ((w / 2).max(1), (h / 2).max(1));
        }
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("occlusion pyramid"),
            size: u64::from(offset.max(1)) * 4,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let uniforms: Vec<wgpu::Buffer> = (0..levels.len())
            .map(|k| {
                let (w, h, offset) = levels[k];
                let (aw, ah, above_offset) = if k > 0 { levels[k - 1] } else { (w, h, offset) };
                let level = LevelGpu {
                    size: [w, h],
                    offset,
                    above_offset,
                    above: [aw, ah],
                    _pad: [0; 2],
                };
                let uniform = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("occlusion pyramid level"),
                    size: size_of::<LevelGpu>() as u64,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                queue.write_buffer(&uniform, 0, bytemuck::bytes_of(&level));
                uniform
            })
            .collect();
        let down = uniforms[1..]
            .iter()
            .map(|u| kernels.level_group(device, u, &buffer, None))
            .collect();
        Pyramid {
            size,
            buffer,
            levels,
            uniforms,
            down,
            first: None,
        }
    }

    /// Records the pyramid's build from `depth`, one compute pass per level (so each level is
    /// written before the next reads it), timed from the first's start to the last's end by
    /// `timestamps`. Its level-0 bind group is made again only when the depth view changes.
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        kernels: &Kernels,
        depth: &wgpu::TextureView,
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        if self.first.as_ref().is_none_or(|(view, _)| view != depth) {
            let group = kernels.level_group(device, &self.uniforms[0], &self.buffer, Some(depth));
            self.first = Some((depth.clone(), group));
        }
        let Some((_, first)) = &self.first else {
            return;
        };
        let count = self.levels.len();
        for (k, &(w, h, _)) in self.levels.iter().enumerate() {
            let (pipeline, group) = match k {
                0 => (&kernels.first, first),
                k => (&kernels.down, &self.down[k - 1]),
            };
            let ends = k == 0 || k == count - 1;
            let timestamp_writes = timestamps
                .as_ref()
                .filter(|_| ends)
                .map(|t| wgpu::ComputePassTimestampWrites {
                    query_set: t.query_set,
                    beginning_of_pass_write_index: t.beginning_of_pass_write_index.filter(|_| k == 0),
                    end_of_pass_write_index: t.end_of_pass_write_index.filter(|_| k == count - 1),
                });
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("occlusion pyramid level"),
                timestamp_writes,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups(w.div_ceil(PYRAMID_WORKGROUP), h.div_ceil(PYRAMID_WORKGROUP), 1);
        }
    }

    /// Every level's width, height and depths, read back (waits for the GPU).
    pub fn read(&self, gpu: &crate::render::context::GpuContext) -> Vec<(u32, u32, Vec<f32>)> {
        let size = self.buffer.size();
        let bytes = copy_and_read(&gpu.device, &gpu.queue, &self.buffer, size).unwrap_or_default();
        let depths: &[f32] = bytemuck::cast_slice(&bytes);
        self.levels
            .iter()
            .map(|&(w, h, offset)| {
                let range = offset as usize..(offset + w * h) as usize;
                (w, h, depths.get(range).map_or_else(Vec::new, <[f32]>::to_vec))
            })
            .collect()
    }
}

/// Texels per side of a pyramid workgroup (the shader's `workgroup_size`).
const PYRAMID_WORKGROUP: u32 = 8;
