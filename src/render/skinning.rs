//! The compute skinning kernel (`shaders/skinning.wgsl`): blends bind-pose vertices by their
//! joints' matrices into posed vertices, for any number of jobs (one skinned mesh each) in one
//! dispatch, so the passes that draw a skinned mesh read vertices already posed. The GPU
//! layouts of its inputs are packed here; the CPU mirror is [`crate::math::skinning`].

use bytemuck::{Pod, Zeroable};

use crate::ecs::assets::MeshHandle;
use crate::ecs::skinning::{SkinSources, SkinningFrame};
use crate::math::skinning::JointWeights;
use crate::render::context::GpuContext;
use crate::render::grow_buffer::GrowBuffer;
use crate::render::layouts::main_compute_pipeline;
use crate::render::limits::LimitError;
use crate::shader::ShaderLibrary;

/// Vertices one workgroup skins (WGSL `@workgroup_size`).
pub const SKINNING_WORKGROUP: u32 = 64;
/// 32-bit words of one packed influence ([`pack_influences`]).
pub const INFLUENCE_WORDS: usize = 6;

/// One skinning job: a run of bind-pose vertices, their joints' first matrix, and where the
/// posed vertices go (WGSL `SkinJob`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct SkinJobGpu {
    /// First vertex of the job in the bind-pose and influence buffers.
    pub source_first: u32,
    /// Vertices in the job.
    pub vertex_count: u32,
    /// First of the job's joint matrices in the joint buffer.
    pub joint_first: u32,
    /// First vertex of the job in the posed buffer.
    pub dest_first: u32,
}

/// Influences as the kernel reads them: per vertex, joints 0–1 and 2–3 as 16-bit pairs, then
/// the four weights' bits.
pub fn pack_influences(influences: &[JointWeights]) -> Vec<u32> {
    let mut out = Vec::with_capacity(influences.len() * INFLUENCE_WORDS);
    for i in influences {
        let [a, b, c, d] = i.joints.map(u32::from);
        out.extend([a | (b << 16), c | (d << 16)]);
        out.extend(i.weights.map(f32::to_bits));
    }
    out
}

/// The kernel's pipeline and bind-group layout.
pub struct SkinningKernel {
    /// Bind group 0: bind pose, influences, joint matrices, jobs (read), posed (write).
    pub layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

/// The buffers of one dispatch.
pub struct SkinningBuffers<'a> {
    /// Bind-pose vertices (`mesh::Vertex`, 32 bytes each).
    pub bind_pose: &'a wgpu::Buffer,
    /// Packed influences ([`pack_influences`]), one per bind-pose vertex.
    pub influences: &'a wgpu::Buffer,
    /// Joint matrices (column-major `mat4x4<f32>`).
    pub joints: &'a wgpu::Buffer,
    /// Jobs ([`SkinJobGpu`]).
    pub jobs: &'a wgpu::Buffer,
    /// Posed vertices, written (`STORAGE`; a vertex buffer too where passes draw from it).
    pub posed: &'a wgpu::Buffer,
}

impl SkinningKernel {
    /// Builds the pipeline.
    ///
    /// # Panics
    /// If the shipped shader does not compose (checked by the shader tests).
    pub fn new(device: &wgpu::Device, library: &mut ShaderLibrary) -> SkinningKernel {
        let storage = |binding, read_only| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("skinning"),
            entries: &[
                storage(0, true),
                storage(1, true),
                storage(2, true),
                storage(3, true),
                storage(4, false),
            ],
        });
        let module = library
            .skinning()
            .expect("the shipped skinning shader composes (checked by tests)");
        let pipeline = main_compute_pipeline(device, "skinning", module, &[Some(&layout)]);
        SkinningKernel { layout, pipeline }
    }

    /// Records one dispatch of `job_count` jobs, none longer than `max_vertices`.
    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        buffers: &SkinningBuffers<'_>,
        job_count: u32,
        max_vertices: u32,
    ) {
        if job_count == 0 || max_vertices == 0 {
            return;
        }
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("skinning"),
            layout: &self.layout,
            entries: &[
                buffer_entry(0, buffers.bind_pose),
                buffer_entry(1, buffers.influences),
                buffer_entry(2, buffers.joints),
                buffer_entry(3, buffers.jobs),
                buffer_entry(4, buffers.posed),
            ],
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("skinning"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(max_vertices.div_ceil(SKINNING_WORKGROUP), job_count, 1);
    }
}

/// A whole buffer at `binding`.
fn buffer_entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}

/// The frame's skinning on the GPU: the bind poses and influences of every source (uploaded
/// when the sources change), and each frame the joint matrices and jobs of the skinned
/// meshes whose pose changed (of every one after the meshes were uploaded again, which wrote
/// their bind poses back), run into the mesh vertex buffer before the frame's passes.
#[derive(Default)]
pub struct SkinningGpu {
    kernel: Option<SkinningKernel>,
    bind_pose: Option<GrowBuffer>,
    influences: Option<GrowBuffer>,
    joints: Option<GrowBuffer>,
    jobs: Option<GrowBuffer>,
    /// First vertex of each source in the bind-pose buffer.
    source_first: Vec<u32>,
    sources_generation: Option<u64>,
    /// Skinning jobs run by the last frame.
    pub last_jobs: u32,
}

impl SkinningGpu {
    /// Skins the frame's changed poses (every pose with `all`) into `vertices`, where each
    /// mesh lies at the first vertex and count `mesh_vertices` gives (a job writes no more
    /// vertices than its mesh has), in a command buffer submitted now (before the frame's).
    /// Returns the jobs run.
    pub fn run(
        &mut self,
        gpu: &GpuContext,
        sources: &SkinSources,
        frame: &SkinningFrame,
        mesh_vertices: impl Fn(MeshHandle) -> Option<(u32, u32)>,
        vertices: &wgpu::Buffer,
        all: bool,
    ) -> Result<u32, LimitError> {
        self.last_jobs = 0;
        let device = &gpu.device;
        if self.sources_generation != Some(sources.generation()) {
            let mut bind_pose = Vec::new();
            let mut influences = Vec::new();
            self.source_first.clear();
            for s in sources.as_slice() {
                self.source_first.push(bind_pose.len() as u32);
                bind_pose.extend_from_slice(&s.vertices);
                influences.extend(pack_influences(&s.influences));
            }
            let buffer = |label| GrowBuffer::new(device, label, 256);
            let b = self.bind_pose.get_or_insert_with(|| buffer("skin bind poses"));
            b.write(gpu, bytemuck::cast_slice(&bind_pose))?;
            let i = self.influences.get_or_insert_with(|| buffer("skin influences"));
            i.write(gpu, bytemuck::cast_slice(&influences))?;
            self.sources_generation = Some(sources.generation());
        }
        let items = sources.as_slice();
        let jobs: Vec<SkinJobGpu> = frame
            .jobs
            .iter()
            .filter(|j| all || j.changed)
            .filter_map(|j| {
                let source = items.get(j.source as usize)?;
                let (first, count) = mesh_vertices(j.mesh)?;
                Some(SkinJobGpu {
                    source_first: *self.source_first.get(j.source as usize)?,
                    vertex_count: (source.vertices.len() as u32).min(count),
                    joint_first: j.joint_first,
                    dest_first: first,
                })
            })
            .collect();
        if jobs.is_empty() {
            return Ok(0);
        }
        let joints = self
            .joints
            .get_or_insert_with(|| GrowBuffer::new(device, "skin joints", 256));
        joints.write(gpu, bytemuck::cast_slice(&frame.joints))?;
        let job_buffer = self
            .jobs
            .get_or_insert_with(|| GrowBuffer::new(device, "skin jobs", 256));
        job_buffer.write(gpu, bytemuck::cast_slice(&jobs))?;
        let kernel = match &mut self.kernel {
            Some(k) => k,
            none => {
                let mut library = ShaderLibrary::new().expect("the shipped shader library composes (checked by tests)");
                none.insert(SkinningKernel::new(device, &mut library))
            }
        };
        let (Some(bind_pose), Some(influences)) = (&self.bind_pose, &self.influences) else {
            return Ok(0);
        };
        let buffers = SkinningBuffers {
            bind_pose: &bind_pose.buffer,
            influences: &influences.buffer,
            joints: &joints.buffer,
            jobs: &job_buffer.buffer,
            posed: vertices,
        };
        let longest = jobs.iter().map(|j| j.vertex_count).max().unwrap_or(0);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("skinning"),
        });
        kernel.record(device, &mut encoder, &buffers, jobs.len() as u32, longest);
        gpu.queue.submit([encoder.finish()]);
        self.last_jobs = jobs.len() as u32;
        Ok(self.last_jobs)
    }
}

#[cfg(test)]
mod tests {
    use super::{INFLUENCE_WORDS, pack_influences};
    use crate::math::skinning::JointWeights;

    #[test]
    fn influences_pack_into_six_words() {
        let i = JointWeights {
            joints: [1, 2, 300, 65535],
            weights: [0.5, 0.25, 0.25, 0.0],
        };
        let packed = pack_influences(&[i, i]);
        assert_eq!(packed.len(), 2 * INFLUENCE_WORDS);
        assert_eq!(packed[0], 1 | (2 << 16));
        assert_eq!(packed[1], 300 | (65535 << 16));
        assert_eq!(f32::from_bits(packed[2]), 0.5);
        assert_eq!(f32::from_bits(packed[5]), 0.0);
    }
}
