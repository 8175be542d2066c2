//! What the moments passes share: a uniform buffer of per-dispatch jobs, bound at a dynamic
//! offset each, that grows to the largest frame seen; the layout entries of the moments they
//! write and of their job; and a compute pipeline of one bind group from a shader module.

use bytemuck::Pod;

use crate::render::layouts::entry;

/// Per-dispatch job uniforms (each `T` padded to the 256-byte dynamic-offset alignment).
#[derive(Default)]
pub struct JobBuffer {
    /// The buffer and how many jobs it holds.
    buffer: Option<(wgpu::Buffer, usize)>,
    /// Bumped whenever the buffer is replaced, so bind groups over it are made again.
    generation: u64,
}

impl JobBuffer {
    /// Uploads `jobs`, replacing the buffer with one of the next power of two (at least 8)
    /// when they do not fit; returns the buffer and its generation.
    pub fn upload<T: Pod>(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        label: &str,
        jobs: &[T],
    ) -> Option<(&wgpu::Buffer, u64)> {
        if self.buffer.as_ref().is_none_or(|(_, n)| *n < jobs.len()) {
            let capacity = jobs.len().next_power_of_two().max(8);
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (capacity * size_of::<T>()) as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            self.buffer = Some((buffer, capacity));
            self.generation += 1;
        }
        let (buffer, _) = self.buffer.as_ref()?;
        queue.write_buffer(buffer, 0, bytemuck::cast_slice(jobs));
        Some((buffer, self.generation))
    }
}

/// A compute pipeline running `entry_point` of `shader` with one bind group of `layout`.
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    shader: &wgpu::ShaderModule,
    layout: &wgpu::BindGroupLayout,
    entry_point: &str,
) -> wgpu::ComputePipeline {
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout),
        module: shader,
        entry_point: Some(entry_point),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// A compute pass's 2D-array texture (single-sample) at `binding`, read as `sample_type`:
/// the depth a moments pass turns into moments, or the moments level it reads.
pub fn array_texture_entry(binding: u32, sample_type: wgpu::TextureSampleType) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        wgpu::ShaderStages::COMPUTE,
        wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        },
    )
}

/// The moments passes' binding 1: the moments written, a 2D-array storage texture of
/// `format`.
pub fn moments_out_entry(format: wgpu::TextureFormat) -> wgpu::BindGroupLayoutEntry {
    entry(
        1,
        wgpu::ShaderStages::COMPUTE,
        wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2Array,
        },
    )
}

/// The moments passes' binding 2: one job `T` of a [`JobBuffer`], at a dynamic offset.
pub fn job_entry<T>() -> wgpu::BindGroupLayoutEntry {
    entry(
        2,
        wgpu::ShaderStages::COMPUTE,
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: true,
            min_binding_size: wgpu::BufferSize::new(size_of::<T>() as u64),
        },
    )
}

/// Binds one job `T` of `buffer` at binding 2 (the dynamic offset picks which).
pub fn job_binding<T>(buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding: 2,
        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer,
            offset: 0,
            size: wgpu::BufferSize::new(size_of::<T>() as u64),
        }),
    }
}

/// A storage-buffer entry at `binding` for `stages`.
pub fn storage_entry(binding: u32, stages: wgpu::ShaderStages, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        stages,
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
    )
}

/// A uniform-buffer entry at `binding` for `stages` of at least `size` bytes (bound at a
/// dynamic offset with `dynamic`).
pub fn uniform_entry(binding: u32, stages: wgpu::ShaderStages, dynamic: bool, size: u64) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        stages,
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: dynamic,
            min_binding_size: wgpu::BufferSize::new(size),
        },
    )
}

/// A group binding each of `buffers` whole, at its position in the list.
pub fn buffer_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry<'_>> = buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// Reading a struct's layout from naga, for the tests that compare a Rust mirror with it.
#[cfg(test)]
pub(crate) mod layout_check {
    /// The members (name, byte offset) and the size of WGSL struct `name` in `module`.
    pub fn wgsl_layout(module: &naga::Module, name: &str) -> (Vec<(String, usize)>, usize) {
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no struct {name} in the module"));
        let naga::TypeInner::Struct { members, span } = &ty.inner else {
            panic!("{name} is not a struct")
        };
        let fields = members
            .iter()
            .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
            .filter(|(n, _)| !n.starts_with("_pad"))
            .collect();
        (fields, *span as usize)
    }
}
