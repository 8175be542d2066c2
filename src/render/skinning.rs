//! The compute skinning kernel (`shaders/skinning.wgsl`): blends bind-pose vertices by their
//! joints' matrices into posed vertices, for any number of jobs (one skinned mesh each) in one
//! dispatch, so the passes that draw a skinned mesh read vertices already posed. The GPU
//! layouts of its inputs are packed here; the CPU mirror is [`crate::math::skinning`].

use bytemuck::{Pod, Zeroable};
use glam::Mat4;

use crate::ecs::assets::MeshHandle;
use crate::ecs::skinning::{SkinSources, SkinningFrame};
use crate::math::skinning::JointWeights;
use crate::render::context::GpuContext;
use crate::render::grow_buffer::GrowBuffer;
use crate::render::layouts::main_compute_pipeline;
use crate::render::limits::LimitError;
use crate::render::timer::GpuTimer;
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

    /// The bind group of one set of buffers.
    pub fn bind_group(&self, device: &wgpu::Device, buffers: &SkinningBuffers<'_>) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("skinning"),
            layout: &self.layout,
            entries: &[
                buffer_entry(0, buffers.bind_pose),
                buffer_entry(1, buffers.influences),
                buffer_entry(2, buffers.joints),
                buffer_entry(3, buffers.jobs),
                buffer_entry(4, buffers.posed),
            ],
        })
    }

    /// Records one dispatch of `job_count` jobs, none longer than `max_vertices`, over the
    /// buffers of `group` ([`bind_group`](Self::bind_group)), timed by `timestamps` if given.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        group: &wgpu::BindGroup,
        (job_count, max_vertices): (u32, u32),
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        if job_count == 0 || max_vertices == 0 {
            return;
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("skinning"),
            timestamp_writes: timestamps,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
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
/// their bind poses back), recorded into the mesh vertex buffer ahead of the frame's passes.
#[derive(Default)]
pub struct SkinningGpu {
    kernel: Option<SkinningKernel>,
    buffers: Option<[GrowBuffer; 4]>,
    /// The kernel's bind group over `buffers` and the mesh vertex buffer, made again when a
    /// buffer is replaced.
    group: Option<wgpu::BindGroup>,
    /// The vertex buffer `group` writes.
    posed: Option<wgpu::Buffer>,
    /// First vertex of each source in the bind-pose buffer.
    source_first: Vec<u32>,
    sources_generation: Option<u64>,
    /// This frame's jobs (kept to reuse its allocation).
    job_list: Vec<SkinJobGpu>,
    /// The joint matrices of this frame's jobs, back to back (kept to reuse its allocation).
    joint_list: Vec<Mat4>,
    /// Jobs prepared and not yet recorded.
    pending: u32,
    /// Vertices of the longest of those jobs.
    longest: u32,
}

impl SkinningGpu {
    /// Skins the frame's changed poses (every pose with `all`: after the meshes were
    /// uploaded again) into `vertices`, where each mesh lies at the first vertex and count
    /// `mesh_vertices` gives (a job writes no more vertices than its mesh has): uploads the
    /// frame's joints and jobs for [`record`](Self::record). Returns the jobs prepared.
    pub fn prepare(
        &mut self,
        gpu: &GpuContext,
        sources: &SkinSources,
        frame: &SkinningFrame,
        mesh_vertices: impl Fn(MeshHandle) -> Option<(u32, u32)>,
        vertices: &wgpu::Buffer,
        all: bool,
    ) -> Result<u32, LimitError> {
        self.pending = 0;
        let device = &gpu.device;
        let [bind_pose, influences, joints, jobs] = self.buffers.get_or_insert_with(|| {
            ["skin bind poses", "skin influences", "skin joints", "skin jobs"].map(|l| GrowBuffer::new(device, l, 256))
        });
        let mut replaced = self.posed.as_ref() != Some(vertices);
        if self.sources_generation != Some(sources.generation()) {
            let mut poses = Vec::new();
            let mut packed = Vec::new();
            self.source_first.clear();
            for s in sources.as_slice() {
                self.source_first.push(poses.len() as u32);
                poses.extend_from_slice(&s.vertices);
                packed.extend(pack_influences(&s.influences));
            }
            replaced |= bind_pose.write(gpu, bytemuck::cast_slice(&poses))?;
            replaced |= influences.write(gpu, bytemuck::cast_slice(&packed))?;
            self.sources_generation = Some(sources.generation());
        }
        let source_first = &self.source_first;
        // NOTE: only the jobs run upload their joint matrices, packed in job order.
        self.job_list.clear();
        self.joint_list.clear();
        let (job_list, joint_list) = (&mut self.job_list, &mut self.joint_list);
        let joint_ends = frame.jobs.iter().skip(1).map(|j| j.joint_first as usize);
        let joint_ends = joint_ends.chain([frame.joints.len()]);
        for (j, end) in frame.jobs.iter().zip(joint_ends) {
            if !(all || j.changed) {
                continue;
            }
            let (Some(source), Some((first, count)), Some(&source_first)) = (
                sources.get(j.source),
                mesh_vertices(j.mesh),
                source_first.get(j.source.0 as usize),
            ) else {
                continue;
            };
            let Some(matrices) = frame.joints.get(j.joint_first as usize..end) else {
                continue;
            };
            job_list.push(SkinJobGpu {
                source_first,
                vertex_count: (source.vertices.len() as u32).min(count),
                joint_first: joint_list.len() as u32,
                dest_first: first,
            });
            joint_list.extend_from_slice(matrices);
        }
        if self.job_list.is_empty() {
            return Ok(0);
        }
        replaced |= joints.write(gpu, bytemuck::cast_slice(&self.joint_list))?;
        replaced |= jobs.write(gpu, bytemuck::cast_slice(&self.job_list))?;
        let kernel = self.kernel.get_or_insert_with(|| {
            let mut library = ShaderLibrary::new().expect("the shipped shader library composes (checked by tests)");
            SkinningKernel::new(device, &mut library)
        });
        if replaced || self.group.is_none() {
            let buffers = SkinningBuffers {
                bind_pose: &bind_pose.buffer,
                influences: &influences.buffer,
                joints: &joints.buffer,
                jobs: &jobs.buffer,
                posed: vertices,
            };
            self.group = Some(kernel.bind_group(device, &buffers));
            self.posed = Some(vertices.clone());
        }
        if self.group.is_none() {
            return Ok(0);
        }
        self.longest = self.job_list.iter().map(|j| j.vertex_count).max().unwrap_or(0);
        self.pending = self.job_list.len() as u32;
        Ok(self.pending)
    }

    /// Records the jobs [`prepare`](Self::prepare) uploaded into `encoder` (first in the frame:
    /// every pass after it draws the posed vertices), as the timed pass "skinning"; returns
    /// how many.
    pub fn record(&mut self, encoder: &mut wgpu::CommandEncoder, timer: &mut GpuTimer) -> u32 {
        let jobs = std::mem::take(&mut self.pending);
        let (Some(kernel), Some(group)) = (&self.kernel, &self.group) else {
            return 0;
        };
        if jobs > 0 {
            kernel.record(encoder, group, (jobs, self.longest), timer.compute_pass("skinning"));
        }
        jobs
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
