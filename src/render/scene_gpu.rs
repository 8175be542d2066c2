//! GPU copies of the scene: the mesh mega-buffers, material textures, the instance buffer
//! and the per-frame index lists and frame uniforms. `prepare` uploads only what changed.
//! (Lights and shadow views are in [`ShadowResources`](crate::render::shadows::ShadowResources).)

use std::borrow::Cow;
use std::collections::HashMap;

use wgpu::util::DeviceExt;

use crate::ecs::assets::{ImageData, Material, MeshHandle, Meshes};
use crate::mesh::{Vertex, position_indices};
use crate::render::context::GpuContext;
use crate::render::frame_inputs::FrameInputs;
use crate::render::gpu_types::{FrameUniformsGpu, InstanceGpu};
use crate::render::grow_buffer::GrowBuffer;
use crate::render::layouts::Layouts;
use crate::render::limits::{LimitError, UploadProblems};
use crate::render::mips::MaskedAlpha;
use crate::render::skinning::SkinningGpu;
use crate::render::textures::{fit_image, upload, white};

/// What a material samples: an image (None: white) and, for a masked material, its alpha
/// test as bit patterns (cutoff, `base_color.a`), which its mip levels are made for.
type TextureKey = (Option<usize>, Option<(u32, u32)>);

/// Where one mesh lives in the mega-buffers.
#[derive(Clone, Copy, Debug, Default)]
pub struct MeshRange {
    /// First index in the index buffer.
    pub first_index: u32,
    /// Number of indices.
    pub index_count: u32,
    /// Added to every index.
    pub base_vertex: i32,
    /// First index of the mesh's position-only list ([`crate::mesh::position_indices`]:
    /// the same triangles, each corner the first vertex at its position), as many indices;
    /// `first_index` where the mesh has none, is skinned (its vertices move apart) or
    /// [`RenderOptions::position_indices`](crate::render::RenderOptions::position_indices)
    /// is off.
    pub position_first_index: u32,
}

/// Which of a mesh's index lists a draw reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IndexList {
    /// The mesh's own: for stages that read normals or texture coordinates.
    Shaded,
    /// Its position-only list: for depth-only stages (opaque shadow casters).
    Positions,
}

impl IndexList {
    /// The list a shadow caster draws from: an opaque caster, drawn with no fragment stage,
    /// reads positions only; a masked caster samples its texture, and a multiview pass reads
    /// the meshes' own indices (from position-only lists lavapipe's multiview pass wrote 436
    /// texels of the default scene's cascade 0 unlike one pass per cascade,
    /// `tests/single_pass.rs`; not checked on other GPUs).
    pub fn for_caster(masked: bool, multiview: bool) -> Self {
        if masked || multiview {
            IndexList::Shaded
        } else {
            IndexList::Positions
        }
    }
}

impl MeshRange {
    /// The first index of `list`.
    pub fn first_of(&self, list: IndexList) -> u32 {
        match list {
            IndexList::Shaded => self.first_index,
            IndexList::Positions => self.position_first_index,
        }
    }
}

/// Everything of the scene that lives on the GPU.
pub struct SceneGpu {
    vertex_buffer: Option<wgpu::Buffer>,
    index_buffer: Option<wgpu::Buffer>,
    /// Per mesh handle.
    pub mesh_ranges: Vec<MeshRange>,
    /// The meshes with a position-only list: handle and that list's first index.
    position_lists: Vec<(usize, u32)>,
    /// Bind group per material handle (group 2).
    pub material_groups: Vec<wgpu::BindGroup>,
    instances: GrowBuffer,
    shadow_indices: GrowBuffer,
    view_indices: GrowBuffer,
    frame_uniforms: wgpu::Buffer,
    /// Group 1 for the depth pass (instances + shadow index list).
    pub shadow_instances_group: wgpu::BindGroup,
    /// Group 1 for the forward pass (instances + view index list).
    pub view_instances_group: wgpu::BindGroup,
    /// Group 0 of the forward pass and the probe pass: the frame uniforms.
    pub view_group: wgpu::BindGroup,
    mesh_generation: u64,
    material_generation: (u64, u64),
    /// The skinned meshes' compute skinning, run into the mesh vertex buffer.
    pub skinning: SkinningGpu,
    /// Whether a material has diffuse transmission: the lighting pass compiles its code in
    /// only then.
    pub any_transmission: bool,
    /// Per material handle: opaque and untextured ([`Material::is_untextured`]), so lit from
    /// the prepass when the frame lights it so ([`crate::render::deferred`]).
    pub untextured: Vec<bool>,
}

pub(crate) fn instances_group(
    device: &wgpu::Device,
    layouts: &Layouts,
    instances: &wgpu::Buffer,
    indices: &wgpu::Buffer,
    label: &str,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &layouts.instances,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: instances.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: indices.as_entire_binding(),
            },
        ],
    })
}

/// A uniform buffer of `size` bytes, written by the queue.
pub(crate) fn uniform_buffer(device: &wgpu::Device, label: &str, size: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

impl SceneGpu {
    /// Creates empty buffers.
    pub fn new(device: &wgpu::Device, layouts: &Layouts) -> Self {
        let instances = GrowBuffer::new(device, "instances", 1 << 16);
        let shadow_indices = GrowBuffer::new(device, "shadow draw indices", 1 << 14);
        let view_indices = GrowBuffer::new(device, "view draw indices", 1 << 14);
        let frame_uniforms = uniform_buffer(device, "frame uniforms", size_of::<FrameUniformsGpu>());
        let view_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("view"),
            layout: &layouts.view,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: frame_uniforms.as_entire_binding(),
            }],
        });
        Self {
            vertex_buffer: None,
            index_buffer: None,
            mesh_ranges: Vec::new(),
            position_lists: Vec::new(),
            material_groups: Vec::new(),
            shadow_instances_group: instances_group(
                device,
                layouts,
                &instances.buffer,
                &shadow_indices.buffer,
                "shadow instances",
            ),
            view_instances_group: instances_group(
                device,
                layouts,
                &instances.buffer,
                &view_indices.buffer,
                "view instances",
            ),
            instances,
            shadow_indices,
            view_indices,
            frame_uniforms,
            view_group,
            mesh_generation: u64::MAX,
            material_generation: (u64::MAX, u64::MAX),
            skinning: SkinningGpu::default(),
            any_transmission: false,
            untextured: Vec::new(),
        }
    }

    /// The instance buffer and the camera view's draw list (what the occlusion culling reads
    /// and draws its lists with).
    pub fn view_buffers(&self) -> (&wgpu::Buffer, &wgpu::Buffer) {
        (&self.instances.buffer, &self.view_indices.buffer)
    }

    /// The mesh vertex and index buffers (None before any mesh was uploaded).
    pub fn mesh_buffers(&self) -> Option<(&wgpu::Buffer, &wgpu::Buffer)> {
        Some((self.vertex_buffer.as_ref()?, self.index_buffer.as_ref()?))
    }

    /// Uploads what changed since the last frame and this frame's lists and uniforms. Sizes
    /// are checked against the device's limits first: an oversized image is downscaled (a
    /// warning in `problems`); mesh, instance or draw lists too large for the device are
    /// refused with an error, and the frame must not be drawn.
    pub fn prepare(
        &mut self,
        gpu: &GpuContext,
        layouts: &Layouts,
        input: &FrameInputs<'_>,
        frame: &FrameUniformsGpu,
        problems: &mut UploadProblems,
    ) -> Result<(), LimitError> {
        let (device, queue) = (&gpu.device, &gpu.queue);
        let skinned = input.skinning.filter(|f| !f.jobs.is_empty());
        let uploaded = input.meshes.generation() != self.mesh_generation;
        if uploaded {
            self.upload_meshes(gpu, input.meshes, skinned.is_some())?;
        }
        self.choose_position_lists(input);
        // NOTE: an upload wrote the bind poses back: every skinned mesh is posed again.
        if let (Some(frame), Some(sources), Some(vertices)) = (skinned, input.skin_sources, &self.vertex_buffer) {
            let ranges = &self.mesh_ranges;
            let mesh_vertices = |m: MeshHandle| {
                let count = input.meshes.get(m)?.vertices.len() as u32;
                ranges.get(m.0 as usize).map(|r| (r.base_vertex as u32, count))
            };
            self.skinning
                .prepare(gpu, sources, frame, mesh_vertices, vertices, uploaded)?;
        }
        if (input.materials.generation(), input.images.generation()) != self.material_generation {
            self.upload_materials(gpu, layouts, input, problems);
        }
        let instances = bytemuck::cast_slice::<InstanceGpu, u8>(&input.instances.gpu);
        // NOTE: instances that only moved are patched, not uploaded whole.
        let patch = input.instances.patch_from(self.instances.generation());
        let regroup = self.instances.write_patch(
            gpu,
            input.instances.generation,
            instances,
            std::mem::size_of::<InstanceGpu>(),
            patch,
        )?;
        // NOTE: the draw lists are uploaded only when culling rebuilt them (a still frame
        // reuses them, and they are the largest per-frame upload: one index per drawn instance).
        let (shadow, view) = (input.shadow_views, input.view_groups);
        let shadow_replaced =
            self.shadow_indices
                .write_generation(gpu, shadow.generation, bytemuck::cast_slice(&shadow.indices))?;
        let view_replaced =
            self.view_indices
                .write_generation(gpu, view.generation, bytemuck::cast_slice(&view.indices))?;
        if regroup || shadow_replaced {
            self.shadow_instances_group = instances_group(
                device,
                layouts,
                &self.instances.buffer,
                &self.shadow_indices.buffer,
                "shadow instances",
            );
        }
        if regroup || view_replaced {
            self.view_instances_group = instances_group(
                device,
                layouts,
                &self.instances.buffer,
                &self.view_indices.buffer,
                "view instances",
            );
        }
        queue.write_buffer(&self.frame_uniforms, 0, bytemuck::bytes_of(frame));
        Ok(())
    }

    /// Points each mesh's [`MeshRange::position_first_index`] at its position-only list, or
    /// at its own indices where it has none, the option is off or a skinning job poses it.
    fn choose_position_lists(&mut self, input: &FrameInputs<'_>) {
        let on = input.options.position_indices;
        for &(m, first) in &self.position_lists {
            let range = &mut self.mesh_ranges[m];
            range.position_first_index = if on { first } else { range.first_index };
        }
        let jobs = input.skinning.map_or(&[][..], |f| &f.jobs[..]);
        for job in jobs {
            if let Some(range) = self.mesh_ranges.get_mut(job.mesh.0 as usize) {
                range.position_first_index = range.first_index;
            }
        }
    }

    /// Packs every mesh into one vertex and one index buffer, after checking that both fit;
    /// with `skinned`, the vertex buffer is also bound as storage, which the compute
    /// skinning writes the posed vertices into.
    fn upload_meshes(&mut self, gpu: &GpuContext, meshes: &Meshes, skinned: bool) -> Result<(), LimitError> {
        let vertex_count: u64 = meshes.as_slice().iter().map(|m| m.vertices.len() as u64).sum();
        let index_count: u64 = meshes.as_slice().iter().map(|m| m.indices.len() as u64).sum();
        let limits = &gpu.limits;
        limits.check_buffer("mesh vertex", vertex_count * size_of::<Vertex>() as u64, skinned)?;
        limits.check_buffer("mesh index", index_count * 4, false)?;
        // NOTE: draws address indices with u32 and vertices with an i32 base.
        for (what, count, max) in [
            ("the vertices of all meshes", vertex_count, i32::MAX as u64),
            ("the indices of all meshes", index_count, u32::MAX as u64),
        ] {
            if count > max {
                return Err(LimitError {
                    what: what.to_owned(),
                    found: count,
                    min: 0,
                    max,
                });
            }
        }
        let mut vertices: Vec<Vertex> = Vec::with_capacity(vertex_count as usize + 1);
        let mut indices: Vec<u32> = Vec::with_capacity(index_count as usize + 3);
        self.mesh_ranges.clear();
        self.position_lists.clear();
        for (m, mesh) in meshes.as_slice().iter().enumerate() {
            let first_index = indices.len() as u32;
            self.mesh_ranges.push(MeshRange {
                first_index,
                index_count: mesh.indices.len() as u32,
                base_vertex: vertices.len() as i32,
                position_first_index: first_index,
            });
            vertices.extend_from_slice(&mesh.vertices);
            indices.extend_from_slice(&mesh.indices);
            // NOTE: a position-only list only while the index buffer has room for it.
            let room = u64::from(u32::MAX) - indices.len() as u64;
            if let Some(welded) = position_indices(mesh).filter(|w| (w.len() as u64) < room) {
                self.position_lists.push((m, indices.len() as u32));
                indices.extend_from_slice(&welded);
            }
        }
        limits.check_buffer("mesh index", indices.len() as u64 * 4, false)?;
        // Never create an empty buffer: pad with one degenerate vertex/index.
        if vertices.is_empty() {
            vertices.push(Vertex::default());
            indices.extend([0, 0, 0]);
        }
        let device = &gpu.device;
        self.vertex_buffer = Some(device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mesh vertices"),
            contents: bytemuck::cast_slice(&vertices),
            usage: if skinned {
                wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::STORAGE
            } else {
                wgpu::BufferUsages::VERTEX
            },
        }));
        self.index_buffer = Some(device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mesh indices"),
            contents: bytemuck::cast_slice(&indices),
            usage: wgpu::BufferUsages::INDEX,
        }));
        self.mesh_generation = meshes.generation();
        Ok(())
    }

    /// Uploads every image a material samples (fitted to the device, see [`fit_image`]),
    /// once per alpha test that samples it (a masked material's mip levels keep its
    /// coverage), and makes one bind group per material.
    fn upload_materials(
        &mut self,
        gpu: &GpuContext,
        layouts: &Layouts,
        input: &FrameInputs<'_>,
        problems: &mut UploadProblems,
    ) {
        let (materials, images) = (input.materials, input.images);
        let (device, queue) = (&gpu.device, &gpu.queue);
        let white = white();
        let fitted: Vec<Cow<'_, ImageData>> = images
            .as_slice()
            .iter()
            .enumerate()
            .map(|(i, image)| fit_image(image, &format!("image {i}"), &gpu.limits, problems))
            .collect();
        // NOTE: keyed by image and alpha test (bit patterns: cutoff, factor), so materials
        // that sample an image the same way share one texture.
        let mut views: HashMap<TextureKey, wgpu::TextureView> = HashMap::new();
        self.any_transmission = materials.as_slice().iter().any(|m| m.effective_transmission() > 0.0);
        self.untextured = materials.as_slice().iter().map(Material::is_untextured).collect();
        self.material_groups = materials
            .as_slice()
            .iter()
            .map(|m| {
                let image = m.base_color_texture.map(|h| h.0 as usize).filter(|&i| i < fitted.len());
                let masked = (m.is_masked() && image.is_some()).then(|| MaskedAlpha {
                    cutoff: m.alpha_cutoff(),
                    factor: m.base_color.w,
                });
                let key = (image, masked.map(|a| (a.cutoff.to_bits(), a.factor.to_bits())));
                let view = views.entry(key).or_insert_with(|| {
                    let pixels = image.map_or(&white, |i| &*fitted[i]);
                    upload(device, queue, pixels, masked)
                });
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("material"),
                    layout: &layouts.material,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: wgpu::BindingResource::TextureView(view),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::Sampler(&layouts.material_sampler),
                        },
                    ],
                })
            })
            .collect();
        self.material_generation = (materials.generation(), images.generation());
    }
}
