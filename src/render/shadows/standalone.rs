//! Standalone depth-only shadow passes (the Taos seed's §8.4–8.5): render one spot light's
//! map or one point light's cube from a list of casters into textures the caller owns, with
//! the same caster pipelines (slope bias, depth clamping, reverse-Z) as the engine, and
//! nothing else — no ECS, no scene, no lighting. The output is a [`SpotShadowMap`] (a 2D
//! depth texture and its matrix) or a [`PointShadowMap`] (a cube depth texture and its face
//! matrices), ready to bind in an application's own passes.
//!
//! ```no_run
//! use glam::{Mat4, Vec3};
//! use penumbra::math::spot::SpotInput;
//! use penumbra::mesh::cuboid;
//! use penumbra::render::GpuContext;
//! use penumbra::render::shadows::standalone::{ShadowCaster, StandaloneShadows};
//! use penumbra::settings::ShadowSettings;
//!
//! let gpu = GpuContext::headless().expect("a GPU adapter");
//! let mut pass = StandaloneShadows::new(&gpu);
//! let cube = cuboid(Vec3::ONE);
//! let casters = [ShadowCaster { mesh: &cube, world_from_local: Mat4::from_translation(Vec3::Y) }];
//! let spot = SpotInput {
//!     position: Vec3::new(0.0, 5.0, 0.0),
//!     direction: Vec3::NEG_Y,
//!     outer_angle: 0.6,
//!     range: 20.0,
//!     near: 0.05,
//!     resolution: 1024,
//! };
//! let map = pass.render_spot(&gpu, &casters, &spot, &ShadowSettings::default()).expect("a valid light");
//! // `map.view` is a `texture_depth_2d`; `map.shadow.clip_from_world` projects into it.
//! ```

use glam::{Mat4, Vec3, Vec4};
use wgpu::util::DeviceExt;

use crate::math::point::{FACES, PointView, point_view};
use crate::math::spot::{SpotInput, SpotView, spot_view};
use crate::mesh::MeshData;
use crate::render::context::GpuContext;
use crate::render::gpu_types::InstanceGpu;
use crate::render::layouts::Layouts;
use crate::render::scene_gpu::instances_group;
use crate::render::shadows::casters::{CasterKey, CasterPipelines};
use crate::render::shadows::gpu::CasterViewGpu;
use crate::render::shadows::storage::{DEPTH_USAGE, SHADOW_FORMAT};
use crate::render::target::texture_2d;
use crate::settings::ShadowSettings;
use crate::shader::ShaderLibrary;

/// One opaque shadow caster: a mesh placed in the world.
#[derive(Clone, Copy, Debug)]
pub struct ShadowCaster<'a> {
    /// The mesh, in local space.
    pub mesh: &'a MeshData,
    /// World from local.
    pub world_from_local: Mat4,
}

pub use crate::render::shadows::storage::read_depth_layer;

/// A spot light's shadow map rendered on its own.
pub struct SpotShadowMap {
    /// `Depth32Float`, `resolution`² texels, reverse-Z (1 at the near plane, 0 at the range).
    pub texture: wgpu::Texture,
    /// The whole texture, for sampling as `texture_depth_2d`.
    pub view: wgpu::TextureView,
    /// The light's view: `clip_from_world` projects a world point into the map.
    pub shadow: SpotView,
}

/// A point light's cube shadow rendered on its own.
pub struct PointShadowMap {
    /// `Depth32Float`, six `resolution`² layers in cube-map order (+X, −X, +Y, −Y, +Z, −Z),
    /// each storing the reverse-Z depth of the distance along its face's axis.
    pub texture: wgpu::Texture,
    /// The cube, for sampling as `texture_depth_cube` along the light-to-surface direction.
    pub cube_view: wgpu::TextureView,
    /// The faces' matrices and planes.
    pub shadow: PointView,
}

/// The caster pipelines and bind group layouts of standalone shadow passes.
pub struct StandaloneShadows {
    layouts: Layouts,
    library: ShaderLibrary,
    pipelines: CasterPipelines,
}

impl StandaloneShadows {
    /// Prepares the layouts and the shader library (pipelines are built on first use).
    pub fn new(gpu: &GpuContext) -> Self {
        Self {
            layouts: Layouts::new(&gpu.device),
            library: ShaderLibrary::new().expect("the shipped shader modules compose (checked by tests)"),
            pipelines: CasterPipelines::default(),
        }
    }

    /// Renders the shadow map of the spot light `input` (its `resolution` is the map's side)
    /// with `settings`' biases and depth clamping; None when no view can be made for it.
    pub fn render_spot(
        &mut self,
        gpu: &GpuContext,
        casters: &[ShadowCaster<'_>],
        input: &SpotInput,
        settings: &ShadowSettings,
    ) -> Option<SpotShadowMap> {
        let shadow = spot_view(input)?;
        let texture = depth_texture(gpu, "standalone spot shadow", input.resolution, 1);
        self.draw(gpu, casters, &[shadow.clip_from_world], &texture, settings);
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        Some(SpotShadowMap { texture, view, shadow })
    }

    /// Renders the six faces of the point light at `position` reaching `range` (faces of
    /// `resolution` texels, near plane `near`) with `settings`' biases and depth clamping;
    /// None when no view can be made for it.
    #[allow(clippy::too_many_arguments)]
    pub fn render_point(
        &mut self,
        gpu: &GpuContext,
        casters: &[ShadowCaster<'_>],
        position: Vec3,
        near: f32,
        range: f32,
        resolution: u32,
        settings: &ShadowSettings,
    ) -> Option<PointShadowMap> {
        let shadow = point_view(position, near, range, resolution)?;
        let texture = depth_texture(gpu, "standalone point shadow", resolution, FACES as u32);
        self.draw(gpu, casters, &shadow.faces, &texture, settings);
        let cube_view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("standalone point shadow"),
            dimension: Some(wgpu::TextureViewDimension::Cube),
            ..Default::default()
        });
        Some(PointShadowMap {
            texture,
            cube_view,
            shadow,
        })
    }

    /// Renders one orthographic view (a clipmap level's window, say) of `resolution`² texels
    /// from `clip_from_world` (reverse-Z) with `settings`' biases and depth clamping; returns
    /// the `Depth32Float` texture.
    pub fn render_ortho(
        &mut self,
        gpu: &GpuContext,
        casters: &[ShadowCaster<'_>],
        clip_from_world: Mat4,
        resolution: u32,
        settings: &ShadowSettings,
    ) -> wgpu::Texture {
        let texture = depth_texture(gpu, "standalone orthographic shadow", resolution, 1);
        self.draw(gpu, casters, &[clip_from_world], &texture, settings);
        texture
    }

    /// Draws every caster into layer `i` of `texture` from `views[i]`, then submits.
    fn draw(
        &mut self,
        gpu: &GpuContext,
        casters: &[ShadowCaster<'_>],
        views: &[Mat4],
        texture: &wgpu::Texture,
        settings: &ShadowSettings,
    ) {
        let device = &gpu.device;
        let mut built = 0;
        let key = CasterKey::new(settings, false, gpu.unclipped_depth, SHADOW_FORMAT);
        let pipeline = self
            .pipelines
            .get(device, &self.layouts, &mut self.library, key, &mut built)
            .clone();
        let view_data: Vec<CasterViewGpu> = views.iter().map(|m| CasterViewGpu::new(*m, 0)).collect();
        let view_buffer = buffer(
            gpu,
            "standalone caster views",
            bytemuck::cast_slice(&view_data),
            wgpu::BufferUsages::UNIFORM,
        );
        let view_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("standalone caster view"),
            layout: &self.layouts.caster_view,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &view_buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(size_of::<CasterViewGpu>() as u64),
                }),
            }],
        });
        let geometry = Geometry::new(gpu, casters);
        let instances_group = instances_group(
            device,
            &self.layouts,
            &geometry.instances,
            &geometry.draw_indices,
            "standalone casters",
        );
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("standalone shadow"),
        });
        for layer in 0..views.len() {
            let target = texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some("standalone shadow layer"),
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: layer as u32,
                array_layer_count: Some(1),
                ..Default::default()
            });
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("standalone shadow"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &target,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let Some((vertices, indices)) = &geometry.buffers else {
                continue;
            };
            pass.set_pipeline(&pipeline);
            let offset = (layer * size_of::<CasterViewGpu>()) as u32;
            pass.set_bind_group(0, &view_group, &[offset]);
            pass.set_bind_group(1, &instances_group, &[]);
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
            for (k, range) in geometry.ranges.iter().enumerate() {
                let k = k as u32;
                pass.draw_indexed(
                    range.first_index..range.first_index + range.count,
                    range.base_vertex,
                    k..k + 1,
                );
            }
        }
        gpu.queue.submit([encoder.finish()]);
    }
}

/// Where one caster's indices lie in the shared buffers.
struct IndexRange {
    first_index: u32,
    count: u32,
    base_vertex: i32,
}

/// The casters' meshes, instances and draw list on the GPU.
struct Geometry {
    /// Vertices and indices of every caster (None without triangles).
    buffers: Option<(wgpu::Buffer, wgpu::Buffer)>,
    ranges: Vec<IndexRange>,
    instances: wgpu::Buffer,
    draw_indices: wgpu::Buffer,
}

impl Geometry {
    fn new(gpu: &GpuContext, casters: &[ShadowCaster<'_>]) -> Self {
        let mut vertices = Vec::new();
        let mut indices = Vec::new();
        let mut ranges = Vec::with_capacity(casters.len());
        for caster in casters {
            ranges.push(IndexRange {
                first_index: indices.len() as u32,
                count: caster.mesh.indices.len() as u32,
                base_vertex: vertices.len() as i32,
            });
            vertices.extend_from_slice(&caster.mesh.vertices);
            indices.extend_from_slice(&caster.mesh.indices);
        }
        let instances: Vec<InstanceGpu> = casters
            .iter()
            .map(|c| InstanceGpu {
                world_rows: InstanceGpu::world_rows(&c.world_from_local),
                base_color: Vec4::ONE,
                alpha_cutoff: 0.0,
                flags: 0,
                transmission: 0.0,
                _pad: 0,
            })
            .collect();
        let draw_indices: Vec<u32> = (0..casters.len().max(1) as u32).collect();
        let storage = wgpu::BufferUsages::STORAGE;
        let buffers = (!indices.is_empty()).then(|| {
            (
                buffer(
                    gpu,
                    "standalone vertices",
                    bytemuck::cast_slice(&vertices),
                    wgpu::BufferUsages::VERTEX,
                ),
                buffer(
                    gpu,
                    "standalone indices",
                    bytemuck::cast_slice(&indices),
                    wgpu::BufferUsages::INDEX,
                ),
            )
        });
        let instances = if instances.is_empty() {
            buffer(
                gpu,
                "standalone instances",
                bytemuck::bytes_of(&InstanceGpu::default()),
                storage,
            )
        } else {
            buffer(gpu, "standalone instances", bytemuck::cast_slice(&instances), storage)
        };
        Self {
            buffers,
            ranges,
            instances,
            draw_indices: buffer(
                gpu,
                "standalone draw list",
                bytemuck::cast_slice(&draw_indices),
                storage,
            ),
        }
    }
}

fn buffer(gpu: &GpuContext, label: &str, contents: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage,
    })
}

/// A `Depth32Float` texture of `layers` `side`² layers to render into, sample and copy.
fn depth_texture(gpu: &GpuContext, label: &str, side: u32, layers: u32) -> wgpu::Texture {
    let side = side.clamp(1, gpu.limits.max_texture_side.max(1));
    texture_2d(&gpu.device, label, (side, side, layers), SHADOW_FORMAT, DEPTH_USAGE)
}
