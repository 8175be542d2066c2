//! The paged clipmap's page drawing on the GPU (`shaders/pages_render.wgsl`): from the
//! allocation's list of pages to draw, a compute pass culls each caster against each listed
//! page (its bounding sphere against the page's square, seen from the light) into per-caster
//! instance lists and indirect draws; one render pass over the pool atlas then clears the
//! listed pages' tiles to the far depth and draws each caster once per page it reaches, its
//! vertices moved from the level's window onto the page's tile and clipped to the tile
//! (alpha-masked casters after the opaque ones, with the alpha test). Where indirect draws
//! may start past instance 0, each caster's draw starts its instances at its own list, so the
//! opaque casters are one multi-draw; elsewhere each caster is a draw of its own, its list's
//! start in a dynamic uniform. The CPU records the same commands every frame and never learns
//! which pages were drawn.

use std::borrow::Cow;

use bytemuck::{Pod, Zeroable};
use glam::{Mat3, Mat4, Vec2, Vec4};

use crate::math::pages::atlas_tiles;
use crate::math::pages::{PageLayout, PagedLevel};
use crate::render::draw::mesh_buffers;
use crate::render::shadows::casters::caster_bias;
use crate::render::shadows::clear::overwrite_pipeline;
use crate::render::shadows::jobs::{buffer_group, compute_pipeline, storage_entry, uniform_entry};
use crate::render::shadows::page_allocate::{MAX_PAGED_LEVELS, PageAllocator};
use crate::render::shadows::storage::{DepthArray, SHADOW_FORMAT};
use crate::settings::ShadowBias;
use crate::shader::ShaderLibrary;

/// Bytes between two casters' entries of the caster-id uniform (the dynamic-offset
/// alignment).
const ID_STRIDE: u64 = 256;

/// Mirror of WGSL `Level`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct LevelGpu {
    clip_from_world: Mat4,
    window: Vec4,
}

/// Mirror of WGSL `Render`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct RenderGpu {
    light_from_world: Mat4,
    tiles: u32,
    page_size: f32,
    atlas_side: f32,
    pages_per_side: u32,
    casters: u32,
    slots: u32,
    levels: u32,
    _pad: u32,
    level: [LevelGpu; MAX_PAGED_LEVELS],
}

/// Mirror of WGSL `Caster`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct CasterGpu {
    world_from_local: Mat4,
    sphere: Vec4,
    material: Vec4,
}

/// One caster to draw into the pages: where its triangles are in the index buffer, where it
/// is, and the sphere that bounds it.
#[derive(Clone, Copy, Debug)]
pub struct PageCaster {
    /// World from local.
    pub world_from_local: Mat4,
    /// World centre (xyz) and radius (w) of its bounding sphere.
    pub sphere: Vec4,
    /// Its indices: first, count, and the vertex they count from.
    pub indices: (u32, u32, i32),
    /// For an alpha-masked caster: its material's bind group (index into
    /// [`PageScene::materials`]), and its base colour alpha and alpha cutoff.
    pub masked: Option<(usize, Vec2)>,
}

/// What a frame's pages are drawn from besides the allocation.
#[derive(Clone, Copy, Debug)]
pub struct PageScene<'a> {
    /// The light's frame from world.
    pub light_rotation: Mat3,
    /// Each level's clip space (its whole window) from world, and its window.
    pub levels: &'a [(Mat4, PagedLevel)],
    /// The casters, the opaque ones first.
    pub casters: &'a [PageCaster],
    /// The material bind groups masked casters name.
    pub materials: &'a [wgpu::BindGroup],
    /// The mesh vertices (the engine's [`Vertex`](crate::mesh::Vertex) layout) and 32-bit
    /// indices of every caster.
    pub geometry: (&'a wgpu::Buffer, &'a wgpu::Buffer),
}

/// The pool atlas and the pipelines and buffers that draw pages into it.
pub struct PageRenderer {
    layout: PageLayout,
    /// Tiles per side of the atlas.
    pub tiles: u32,
    /// The pool's atlas drawn into (`Depth32Float`, `tiles · page_size` texels a side,
    /// physical page `p` at tile `(p mod tiles, p / tiles)`).
    atlas_view: wgpu::TextureView,
    slots: u32,
    max_casters: u32,
    cull: (wgpu::ComputePipeline, wgpu::BindGroup),
    draw_group: wgpu::BindGroup,
    clear: wgpu::RenderPipeline,
    /// The opaque and the alpha-masked casters' pipelines.
    caster: [wgpu::RenderPipeline; 2],
    id_group: wgpu::BindGroup,
    uniforms: wgpu::Buffer,
    casters: wgpu::Buffer,
    args: wgpu::Buffer,
    clear_args: wgpu::Buffer,
    /// The culling's indirect dispatch: a row of workgroups per page to draw.
    cull_args: wgpu::Buffer,
    _ids: wgpu::Buffer,
    /// The opaque casters are one multi-draw (the device has indirect first instances).
    multi_draw: bool,
    caster_data: Vec<CasterGpu>,
    args_data: Vec<[u32; 5]>,
}

fn buffer(device: &wgpu::Device, label: &str, bytes: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

impl PageRenderer {
    /// The pipelines drawing `allocator`'s pages into `atlas` (one layer of
    /// [`atlas_tiles`] tiles a side), for up to `max_casters` casters
    /// drawn with the light's `bias` (slope-scaled, clamp) as the caster pipelines draw;
    /// `unclipped` leaves depth unclipped (casters nearer than the level's range are clamped
    /// to it); masked casters bind their material with `material` (group 2); `multi_draw`
    /// draws the opaque casters with one multi-draw (the device must have
    /// `INDIRECT_FIRST_INSTANCE`). Needs a device with clip distances.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        (device, queue, multi_draw): (&wgpu::Device, &wgpu::Queue, bool),
        (library, material): (&mut ShaderLibrary, &wgpu::BindGroupLayout),
        (allocator, atlas): (&PageAllocator, &DepthArray),
        max_casters: u32,
        bias: &ShadowBias,
        unclipped: bool,
    ) -> Self {
        let (layout, slots) = (allocator.layout(), allocator.pool_pages());
        let tiles = atlas_tiles(slots);
        let atlas_view = atlas.layer_views[0].clone();
        let uniforms = buffer(
            device,
            "page drawing",
            size_of::<RenderGpu>() as u64,
            wgpu::BufferUsages::UNIFORM,
        );
        let caster_bytes = u64::from(max_casters) * size_of::<CasterGpu>() as u64;
        let casters = buffer(device, "page casters", caster_bytes, wgpu::BufferUsages::STORAGE);
        let lists = buffer(
            device,
            "page caster lists",
            u64::from(max_casters) * u64::from(slots) * 4,
            wgpu::BufferUsages::STORAGE,
        );
        let indirect = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT;
        let args = buffer(device, "page caster draws", u64::from(max_casters) * 20, indirect);
        let clear_args = buffer(device, "page clears", 16, indirect);
        let cull_args = buffer(device, "page culling dispatch", 16, indirect);
        let ids = buffer(
            device,
            "page caster ids",
            u64::from(max_casters) * ID_STRIDE,
            wgpu::BufferUsages::UNIFORM,
        );
        let id_data: Vec<u8> = (0..max_casters)
            .flat_map(|c| {
                let mut entry = [0u8; ID_STRIDE as usize];
                entry[..4].copy_from_slice(&(c * slots).to_le_bytes());
                entry
            })
            .collect();
        let (draws, counters, table) = allocator.draw_buffers();
        let compute = wgpu::ShaderStages::COMPUTE;
        let vertex = wgpu::ShaderStages::VERTEX;
        let render_size = size_of::<RenderGpu>() as u64;
        let shared = |stages| {
            [
                uniform_entry(0, stages, false, render_size),
                storage_entry(1, stages, true),
                storage_entry(2, stages, true),
                storage_entry(3, stages, true),
                storage_entry(4, stages, true),
            ]
        };
        let cull_entries: Vec<_> = shared(compute)
            .into_iter()
            .chain([storage_entry(5, compute, false), storage_entry(6, compute, false)])
            .collect();
        let cull_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("page culling"),
            entries: &cull_entries,
        });
        let draw_entries: Vec<_> = shared(vertex)
            .into_iter()
            .chain([storage_entry(5, vertex, true)])
            .collect();
        let draw_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("page drawing"),
            entries: &draw_entries,
        });
        let id_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("page caster id"),
            entries: &[uniform_entry(0, vertex, true, 16)],
        });
        let shared_buffers = [&uniforms, draws, counters, table, &casters];
        let cull_group = buffer_group(
            device,
            "page culling",
            &cull_layout,
            &[&shared_buffers[..], &[&lists, &args]].concat(),
        );
        let draw_group = buffer_group(
            device,
            "page drawing",
            &draw_layout,
            &[&shared_buffers[..], &[&lists]].concat(),
        );
        let id_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("page caster id"),
            layout: &id_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &ids,
                    offset: 0,
                    size: wgpu::BufferSize::new(16),
                }),
            }],
        });
        let mut module = |cull: bool| {
            let module = library
                .pages_render(cull)
                .expect("the shipped page drawing shader composes (checked by tests)");
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("page drawing"),
                source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
            })
        };
        let cull_pipeline = compute_pipeline(device, "page culling", &module(true), &cull_layout, "cull");
        let shader = module(false);
        let pipeline_layout = |groups: &[Option<&wgpu::BindGroupLayout>]| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("page drawing"),
                bind_group_layouts: groups,
                immediate_size: 0,
            })
        };
        let clear_layout = pipeline_layout(&[Some(&draw_layout)]);
        let stages = (&shader, "clear_vs", None);
        let clear = overwrite_pipeline(device, "page clear", &clear_layout, stages, (0, SHADOW_FORMAT));
        let opaque_layout = pipeline_layout(&[Some(&draw_layout), Some(&id_layout)]);
        let masked_layout = pipeline_layout(&[Some(&draw_layout), Some(&id_layout), Some(material)]);
        let caster = |masked: bool| {
            let fragment = masked.then(|| wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_masked"),
                compilation_options: Default::default(),
                targets: &[],
            });
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(if masked {
                    "page casters (alpha test)"
                } else {
                    "page casters"
                }),
                layout: Some(if masked { &masked_layout } else { &opaque_layout }),
                vertex: wgpu::VertexState {
                    module: &shader,
                    entry_point: Some("caster_vs"),
                    compilation_options: Default::default(),
                    buffers: mesh_buffers(),
                },
                primitive: wgpu::PrimitiveState {
                    cull_mode: None,
                    unclipped_depth: unclipped,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: SHADOW_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Greater),
                    stencil: wgpu::StencilState::default(),
                    bias: caster_bias(bias.slope_bias, bias.bias_clamp),
                }),
                multisample: wgpu::MultisampleState::default(),
                fragment,
                multiview_mask: None,
                cache: None,
            })
        };
        let caster = [caster(false), caster(true)];
        queue.write_buffer(&ids, 0, &id_data);
        // NOTE: six vertices a tile; the instance count is copied in each frame.
        queue.write_buffer(&clear_args, 0, bytemuck::cast_slice(&[6u32, 0, 0, 0]));
        Self {
            layout,
            tiles,
            atlas_view,
            slots,
            max_casters,
            cull: (cull_pipeline, cull_group),
            draw_group,
            clear,
            caster,
            id_group,
            uniforms,
            casters,
            args,
            clear_args,
            cull_args,
            _ids: ids,
            multi_draw,
            caster_data: Vec::new(),
            args_data: Vec::new(),
        }
    }

    /// Records this frame's page drawing: the casters culled per listed page, the listed
    /// pages' tiles cleared, the casters drawn into them (that render pass timed by
    /// `timestamps`).
    pub fn record(
        &mut self,
        (queue, encoder): (&wgpu::Queue, &mut wgpu::CommandEncoder),
        allocator: &PageAllocator,
        scene: &PageScene<'_>,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let count = scene.casters.len().min(self.max_casters as usize);
        let casters = &scene.casters[..count];
        let mut level = [LevelGpu {
            clip_from_world: Mat4::ZERO,
            window: Vec4::ZERO,
        }; MAX_PAGED_LEVELS];
        for (l, (clip_from_world, paged)) in level.iter_mut().zip(scene.levels) {
            let first = self.layout.page_of(paged.first_texel).as_vec2();
            *l = LevelGpu {
                clip_from_world: *clip_from_world,
                window: Vec4::new(first.x, first.y, paged.texel as f32, 0.0),
            };
        }
        let data = RenderGpu {
            light_from_world: Mat4::from_mat3(scene.light_rotation),
            tiles: self.tiles,
            page_size: self.layout.page_size as f32,
            atlas_side: (self.tiles * self.layout.page_size) as f32,
            pages_per_side: self.layout.pages_per_side(),
            casters: count as u32,
            slots: self.slots,
            levels: scene.levels.len().min(MAX_PAGED_LEVELS) as u32,
            _pad: 0,
            level,
        };
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&data));
        // NOTE: the lists keep their allocations from frame to frame.
        self.caster_data.clear();
        self.caster_data.extend(casters.iter().map(|c| CasterGpu {
            world_from_local: c.world_from_local,
            sphere: c.sphere,
            material: c.masked.map_or(Vec4::ZERO, |(_, m)| m.extend(0.0).extend(0.0)),
        }));
        queue.write_buffer(&self.casters, 0, bytemuck::cast_slice(&self.caster_data));
        self.args_data.clear();
        let first = |c: u32| if self.multi_draw { c * self.slots } else { 0 };
        self.args_data.extend(
            casters
                .iter()
                .zip(0..)
                .map(|(c, k)| [c.indices.1, 0, c.indices.0, c.indices.2 as u32, first(k)]),
        );
        queue.write_buffer(&self.args, 0, bytemuck::cast_slice(&self.args_data));
        // NOTE: the clears' instance count, and the culling's rows of workgroups, are the
        // allocation's count of pages to draw: a frame that draws no page culls nothing.
        let listed = allocator.draw_buffers().1;
        encoder.copy_buffer_to_buffer(listed, 4, &self.clear_args, 4, 4);
        if count > 0 {
            let dispatch = [(count as u32).div_ceil(64), 0, 1, 0];
            queue.write_buffer(&self.cull_args, 0, bytemuck::cast_slice(&dispatch));
            encoder.copy_buffer_to_buffer(listed, 4, &self.cull_args, 4, 4);
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("page culling"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.cull.0);
            pass.set_bind_group(0, &self.cull.1, &[]);
            pass.dispatch_workgroups_indirect(&self.cull_args, 0);
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("pages"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.atlas_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &self.draw_group, &[]);
        pass.set_pipeline(&self.clear);
        pass.draw_indirect(&self.clear_args, 0);
        let (vertices, indices) = scene.geometry;
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
        let opaque = casters.iter().take_while(|c| c.masked.is_none()).count();
        let first_masked = if self.multi_draw && opaque > 0 {
            pass.set_pipeline(&self.caster[0]);
            pass.set_bind_group(1, &self.id_group, &[0]);
            pass.multi_draw_indexed_indirect(&self.args, 0, opaque as u32);
            opaque
        } else {
            0
        };
        let (mut pipeline, mut material) = (None, None);
        for (c, caster) in casters.iter().enumerate().skip(first_masked) {
            let masked = caster.masked.map(|(m, _)| m);
            if masked.is_some() && material != masked {
                let Some(group) = masked.and_then(|m| scene.materials.get(m)) else {
                    continue;
                };
                pass.set_bind_group(2, group, &[]);
                material = masked;
            }
            let kind = usize::from(masked.is_some());
            if pipeline != Some(kind) {
                pass.set_pipeline(&self.caster[kind]);
                pipeline = Some(kind);
            }
            // NOTE: with the multi-draw, the draw's first instance starts the list.
            let id = if self.multi_draw { 0 } else { c as u64 * ID_STRIDE };
            pass.set_bind_group(1, &self.id_group, &[id as u32]);
            pass.draw_indexed_indirect(&self.args, c as u64 * 20);
        }
    }
}

#[cfg(test)]
mod tests {
    use std::mem::offset_of;

    use super::*;
    use crate::render::shadows::jobs::layout_check::wgsl_layout;

    #[test]
    fn the_uniforms_and_records_match_the_wgsl_layout() {
        let fields = |list: &[(&str, usize)]| list.iter().map(|(n, o)| (n.to_string(), *o)).collect::<Vec<_>>();
        for cull in [true, false] {
            let module = ShaderLibrary::new().unwrap().pages_render(cull).unwrap();
            let render = [
                ("light_from_world", offset_of!(RenderGpu, light_from_world)),
                ("tiles", offset_of!(RenderGpu, tiles)),
                ("page_size", offset_of!(RenderGpu, page_size)),
                ("atlas_side", offset_of!(RenderGpu, atlas_side)),
                ("pages_per_side", offset_of!(RenderGpu, pages_per_side)),
                ("casters", offset_of!(RenderGpu, casters)),
                ("slots", offset_of!(RenderGpu, slots)),
                ("levels", offset_of!(RenderGpu, levels)),
                ("level", offset_of!(RenderGpu, level)),
            ];
            assert_eq!(
                wgsl_layout(&module, "Render"),
                (fields(&render), size_of::<RenderGpu>())
            );
            let level = [
                ("clip_from_world", offset_of!(LevelGpu, clip_from_world)),
                ("window", offset_of!(LevelGpu, window)),
            ];
            assert_eq!(wgsl_layout(&module, "Level"), (fields(&level), size_of::<LevelGpu>()));
            let caster = [
                ("world_from_local", offset_of!(CasterGpu, world_from_local)),
                ("sphere", offset_of!(CasterGpu, sphere)),
                ("material", offset_of!(CasterGpu, material)),
            ];
            assert_eq!(
                wgsl_layout(&module, "Caster"),
                (fields(&caster), size_of::<CasterGpu>())
            );
        }
    }
}
