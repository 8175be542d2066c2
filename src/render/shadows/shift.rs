//! Moves a clipmap level's layer by whole texels when its window moves
//! (`shaders/shadow_shift.wgsl`): one pass writes the layer's texels, shifted, into a scratch
//! depth texture of the layer's size (the far depth where the shifted source holds nothing),
//! and a whole-subresource copy puts them back. The kept texels are bit-identical to what a
//! fresh draw of the moved window writes there (the same grid texels, the same depth), so
//! only the strips the window newly covers need drawing.

use std::borrow::Cow;

use bytemuck::{Pod, Zeroable};
use glam::IVec2;

use crate::render::layouts::entry;
use crate::render::shadows::clear::overwrite_pipeline;
use crate::render::shadows::storage::{DepthArray, depth_texel_bytes};
use crate::render::target::texture_2d;
use crate::shader::ShaderLibrary;

/// Bytes between the uniforms of two shifts of one frame (the dynamic-offset alignment).
const STRIDE: u64 = 256;
/// Shifts one frame can record (more are drawn whole by the caller).
pub const MAX_SHIFTS_PER_FRAME: usize = 64;

/// Mirror of WGSL `Shift`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ShiftGpu {
    offset: IVec2,
    side: i32,
    _pad: [u32; 61],
}

/// The depth layer a scrolling layer is moved through (owned by the shadow resources, so the
/// shadow-memory account counts it).
pub struct ShiftScratch {
    /// Texels per side.
    pub side: u32,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
}

impl ShiftScratch {
    /// A `side`² depth layer of `format` (its storage's).
    pub fn new(device: &wgpu::Device, side: u32, format: wgpu::TextureFormat) -> Self {
        let texture = texture_2d(
            device,
            "clipmap shift scratch",
            (side, side, 1),
            format,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        Self { side, texture, view }
    }

    /// Its depth format.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.texture.format()
    }

    /// Bytes of GPU memory it takes.
    pub fn memory_bytes(&self) -> u64 {
        u64::from(self.side).pow(2) * u64::from(depth_texel_bytes(self.format()))
    }
}

/// The layer a shift moves and the scratch it moves it through.
#[derive(Clone, Copy)]
pub struct ShiftTarget<'a> {
    /// The array.
    pub storage: &'a DepthArray,
    /// The scratch layer, of the array's side.
    pub scratch: &'a ShiftScratch,
    /// The layer.
    pub layer: u32,
    /// Texels per side of the view in its top-left corner (the layer's side, or less when
    /// the storage is shared with larger views).
    pub resolution: u32,
}

/// The shift pipeline and its uniforms, made on first use.
#[derive(Default)]
pub struct LevelShift {
    pipeline: Option<(wgpu::BindGroupLayout, Built, wgpu::Buffer)>,
    /// The bind groups over a storage's layers (its allocation id; one per layer, made on a
    /// layer's first shift), kept while it lives.
    groups: Option<(u64, Vec<Option<wgpu::BindGroup>>)>,
    /// Shifts recorded this frame.
    used: usize,
}

impl LevelShift {
    /// Starts a frame: its shifts use the uniforms from the first on.
    pub fn begin_frame(&mut self) {
        self.used = 0;
    }

    /// Records the shift of `target`'s view by `offset` texels (target texel + offset =
    /// source texel; the rest of its layer is cleared), timed by `timing`; false when this frame already recorded as many
    /// shifts as its uniforms hold, or the scratch is not of the layer's side (the caller
    /// then draws the level whole).
    #[allow(clippy::too_many_arguments)]
    pub fn shift(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        library: &mut ShaderLibrary,
        encoder: &mut wgpu::CommandEncoder,
        target: ShiftTarget<'_>,
        offset: IVec2,
        timing: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> bool {
        let ShiftTarget {
            storage,
            scratch,
            layer,
            resolution,
        } = target;
        if self.used >= MAX_SHIFTS_PER_FRAME || scratch.side != storage.side || scratch.format() != storage.format() {
            return false;
        }
        let Some(view) = storage.layer_views.get(layer as usize) else {
            return false;
        };
        if self.pipeline.as_ref().is_some_and(|p| p.1.format != storage.format()) {
            (self.pipeline, self.groups) = (None, None);
        }
        let (layout, built, uniforms) = self
            .pipeline
            .get_or_insert_with(|| create(device, library, storage.format()));
        let pipeline = &built.pipeline;
        let at = self.used as u64 * STRIDE;
        self.used += 1;
        let data = ShiftGpu {
            offset,
            side: resolution.min(storage.side) as i32,
            _pad: [0; 61],
        };
        queue.write_buffer(uniforms, at, bytemuck::bytes_of(&data));
        let side = storage.side;
        if self.groups.as_ref().is_none_or(|(id, _)| *id != storage.id) {
            self.groups = Some((storage.id, Vec::new()));
        }
        let groups = &mut self.groups.as_mut().expect("set above").1;
        if groups.len() <= layer as usize {
            groups.resize(layer as usize + 1, None);
        }
        let group = groups[layer as usize].get_or_insert_with(|| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("clipmap shift"),
                layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: uniforms,
                            offset: 0,
                            size: wgpu::BufferSize::new(size_of::<ShiftGpu>() as u64),
                        }),
                    },
                ],
            })
        });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("clipmap shift"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &scratch.view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: timing,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &*group, &[at as u32]);
            pass.draw(0..3, 0..1);
        }
        encoder.copy_texture_to_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &scratch.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyTextureInfo {
                texture: &storage.texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::Extent3d {
                width: side,
                height: side,
                depth_or_array_layers: 1,
            },
        );
        true
    }
}

/// A shift pipeline and the depth format it writes.
struct Built {
    pipeline: wgpu::RenderPipeline,
    format: wgpu::TextureFormat,
}

/// The shift's bind group layout, pipeline (writing `format`) and uniform buffer.
fn create(
    device: &wgpu::Device,
    library: &mut ShaderLibrary,
    format: wgpu::TextureFormat,
) -> (wgpu::BindGroupLayout, Built, wgpu::Buffer) {
    let module = library
        .shadow_shift()
        .expect("the shipped shift shader composes (checked by tests)");
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("clipmap shift"),
        source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
    });
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("clipmap shift"),
        entries: &[
            entry(
                0,
                wgpu::ShaderStages::FRAGMENT,
                wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
            ),
            entry(
                1,
                wgpu::ShaderStages::FRAGMENT,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(size_of::<ShiftGpu>() as u64),
                },
            ),
        ],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("clipmap shift"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let stages = (&shader, "vs_main", Some("fs_main"));
    let pipeline = overwrite_pipeline(device, "clipmap shift", &pipeline_layout, stages, (0, format));
    let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("clipmap shift"),
        size: STRIDE * MAX_SHIFTS_PER_FRAME as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    (layout, Built { pipeline, format }, uniforms)
}
