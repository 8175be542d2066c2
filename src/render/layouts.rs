//! Bind group layouts and samplers shared by the passes. Group numbers follow the WGSL:
//! group 0 is the view (the frame uniforms, or one shadow view's matrix in the depth pass),
//! group 1 the instances and the draw's index list, group 2 the material, group 3 the shadow
//! group (lights, shadow views, shadow storage, samplers, Poisson taps).

use std::borrow::Cow;
use std::num::NonZeroU64;

use crate::layout::group::{BindingKind, Slot, bindings};
use crate::render::gpu_types::{FrameUniformsGpu, InstanceGpu, PoissonTapsGpu};
use crate::render::shadows::gpu::{
    CasterViewGpu, LightGpu, MAX_LIGHTS, MAX_SHADOW_VIEWS, SINGLE_PASS_VIEWS, ShadowViewGpu,
};

/// The layouts and samplers every pass builds its bind groups from.
pub struct Layouts {
    /// Forward group 0: the frame uniforms.
    pub view: wgpu::BindGroupLayout,
    /// Group 3: one entry per binding of [`crate::layout::group::bindings`] (lights, shadow
    /// views, samplers, Poisson taps, resolved visibility, each storage's depth and moments).
    pub shadows: wgpu::BindGroupLayout,
    /// Depth-pass group 0: one shadow view's `CasterView`, bound with a dynamic offset.
    pub caster_view: wgpu::BindGroupLayout,
    /// Group 0 of the single-pass (multiview) caster pipelines: [`SINGLE_PASS_VIEWS`]
    /// consecutive caster views, at a dynamic offset.
    pub caster_views: wgpu::BindGroupLayout,
    /// Group 1: instances and the draw's index list.
    pub instances: wgpu::BindGroupLayout,
    /// Group 2: base-colour texture and sampler.
    pub material: wgpu::BindGroupLayout,
    /// Hardware comparison sampler for the shadow map (reverse-Z: lit when ref >= stored).
    pub shadow_compare: wgpu::Sampler,
    /// Nearest sampler for raw shadow depth reads.
    pub shadow_point: wgpu::Sampler,
    /// `shadow_compare` repeating at the edges (a wrapping clipmap layer).
    pub shadow_compare_wrap: wgpu::Sampler,
    /// `shadow_point` repeating at the edges.
    pub shadow_point_wrap: wgpu::Sampler,
    /// Bilinear, clamped sampler for VSM moments.
    pub moments_sampler: wgpu::Sampler,
    /// Trilinear, repeating sampler for material textures.
    pub material_sampler: wgpu::Sampler,
}

/// A layout entry of one binding (no array).
pub(crate) fn entry(binding: u32, visibility: wgpu::ShaderStages, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty,
        count: None,
    }
}

fn uniform<T>(dynamic: bool) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Uniform,
        has_dynamic_offset: dynamic,
        min_binding_size: NonZeroU64::new(size_of::<T>() as u64),
    }
}

fn uniform_array<T>(len: usize) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Uniform,
        has_dynamic_offset: false,
        min_binding_size: NonZeroU64::new((len * size_of::<T>()) as u64),
    }
}

pub(crate) fn storage<T>() -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only: true },
        has_dynamic_offset: false,
        min_binding_size: NonZeroU64::new(size_of::<T>() as u64),
    }
}

/// The layout type of a shadow-group binding of `kind` holding `slot`.
pub fn shadow_binding_type(slot: Slot, kind: BindingKind) -> wgpu::BindingType {
    let texture = |sample_type, view_dimension| wgpu::BindingType::Texture {
        sample_type,
        view_dimension,
        multisampled: false,
    };
    let filterable = wgpu::TextureSampleType::Float { filterable: true };
    match kind {
        BindingKind::Uniform(_) => match slot {
            Slot::Lights => uniform_array::<LightGpu>(MAX_LIGHTS),
            Slot::Views => uniform_array::<ShadowViewGpu>(MAX_SHADOW_VIEWS),
            _ => uniform::<PoissonTapsGpu>(false),
        },
        BindingKind::StorageArray(_) => match slot {
            // NOTE: a `PageEntry` is four 32-bit words (`page_allocate::EntryGpu`).
            Slot::PageTable(_) => storage::<[u32; 4]>(),
            _ => storage::<LightGpu>(),
        },
        BindingKind::DepthArray => texture(wgpu::TextureSampleType::Depth, wgpu::TextureViewDimension::D2Array),
        BindingKind::DepthCubeArray => texture(wgpu::TextureSampleType::Depth, wgpu::TextureViewDimension::CubeArray),
        BindingKind::FloatArray => texture(filterable, wgpu::TextureViewDimension::D2Array),
        BindingKind::UnfilterableFloatArray => texture(
            wgpu::TextureSampleType::Float { filterable: false },
            wgpu::TextureViewDimension::D2Array,
        ),
        BindingKind::FloatCubeArray => texture(filterable, wgpu::TextureViewDimension::CubeArray),
        BindingKind::CompareSampler => wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
        BindingKind::NearestSampler => wgpu::BindingType::Sampler(wgpu::SamplerBindingType::NonFiltering),
        BindingKind::FilterSampler => wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
    }
}

impl Layouts {
    /// Creates every layout and sampler.
    pub fn new(device: &wgpu::Device) -> Self {
        // NOTE: the view and shadow groups are also bound by the shadow-probe compute pass.
        let fc = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let vfc = wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let view = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("view"),
            entries: &[entry(0, vfc, uniform::<FrameUniformsGpu>(false))],
        });
        let shadow_entries: Vec<_> = bindings()
            .enumerate()
            .map(|(i, b)| entry(i as u32, fc, shadow_binding_type(b.slot, b.kind)))
            .collect();
        let shadows = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadows"),
            entries: &shadow_entries,
        });
        let caster_view = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("caster view"),
            entries: &[entry(0, wgpu::ShaderStages::VERTEX, uniform::<CasterViewGpu>(true))],
        });
        let caster_views = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("caster views (single pass)"),
            entries: &[entry(
                0,
                wgpu::ShaderStages::VERTEX,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: NonZeroU64::new((SINGLE_PASS_VIEWS * size_of::<CasterViewGpu>()) as u64),
                },
            )],
        });
        let instances = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("instances"),
            entries: &[
                entry(0, wgpu::ShaderStages::VERTEX, storage::<InstanceGpu>()),
                entry(1, wgpu::ShaderStages::VERTEX, storage::<u32>()),
            ],
        });
        let material = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("material"),
            entries: &[
                entry(
                    0,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
                entry(
                    1,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
            ],
        });
        let shadow_compare = device.create_sampler(&compare_sampler("shadow compare", wgpu::AddressMode::ClampToEdge));
        let shadow_point = device.create_sampler(&point_sampler("shadow point", wgpu::AddressMode::ClampToEdge));
        let shadow_compare_wrap =
            device.create_sampler(&compare_sampler("shadow compare wrap", wgpu::AddressMode::Repeat));
        let shadow_point_wrap = device.create_sampler(&point_sampler("shadow point wrap", wgpu::AddressMode::Repeat));
        let moments_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow moments"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            // NOTE: the suns' moments are mipmapped for contact hardening (a wider filter
            // is a coarser level); the other moments have one level.
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let material_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("material"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            // NOTE: material textures carry their whole mip chain (render::mips).
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        Self {
            view,
            shadows,
            caster_view,
            caster_views,
            instances,
            material,
            shadow_compare,
            shadow_point,
            shadow_compare_wrap,
            shadow_point_wrap,
            moments_sampler,
            material_sampler,
        }
    }
}

/// The shadow maps' comparison sampler (bilinear, reverse-Z `GreaterEqual`), addressing its
/// edges with `mode`.
fn compare_sampler(label: &str, mode: wgpu::AddressMode) -> wgpu::SamplerDescriptor<'_> {
    wgpu::SamplerDescriptor {
        label: Some(label),
        address_mode_u: mode,
        address_mode_v: mode,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        compare: Some(wgpu::CompareFunction::GreaterEqual),
        ..Default::default()
    }
}

/// The shadow maps' nearest-neighbour sampler for raw depths, addressing its edges with `mode`.
fn point_sampler(label: &str, mode: wgpu::AddressMode) -> wgpu::SamplerDescriptor<'_> {
    wgpu::SamplerDescriptor {
        label: Some(label),
        address_mode_u: mode,
        address_mode_v: mode,
        ..Default::default()
    }
}

/// A compute pipeline running `main` of the composed `module`, with the bind groups `groups`
/// (`None` for a group number the shader leaves unused).
pub fn main_compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: naga::Module,
    groups: &[Option<&wgpu::BindGroupLayout>],
) -> wgpu::ComputePipeline {
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: groups,
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&layout),
        module: &shader,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// A compute pass's 2D texture binding of the camera's depth (`Depth`) or normals (`Uint`),
/// single-sample or multisampled.
pub fn camera_texture_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
    multisampled: bool,
) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        wgpu::ShaderStages::COMPUTE,
        wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled,
        },
    )
}
