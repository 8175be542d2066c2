//! The shadow resources' bind groups: the shadow group (group 3) every material samples
//! through, one entry per binding of [`bindings`], and the casters' per-view groups of the
//! depth pass.

use std::sync::Arc;

use crate::layout::ShadowStorage;
use crate::layout::group::{Slot, bindings};
use crate::render::layouts::Layouts;
use crate::render::shadows::gpu::{CasterViewGpu, SINGLE_PASS_VIEWS};
use crate::render::shadows::moment_storage::MomentArray;
use crate::render::shadows::storage::DepthArray;
use crate::render::shadows::visibility::VisibilityTarget;

/// The shadow bind group over `buffers` (lights, more lights, views, Poisson taps, page
/// table), each storage's depth array and moments, and the resolved `visibility`: one entry
/// per binding of [`bindings`].
pub(super) fn shadow_group(
    device: &wgpu::Device,
    layouts: &Layouts,
    buffers: [&wgpu::Buffer; 5],
    maps: &[Arc<DepthArray>; ShadowStorage::COUNT],
    moments: &[Arc<MomentArray>; ShadowStorage::COUNT],
    visibility: &VisibilityTarget,
) -> wgpu::BindGroup {
    let [lights, more_lights, views, taps, page_table] = buffers;
    let entries: Vec<wgpu::BindGroupEntry> = bindings()
        .enumerate()
        .map(|(binding, b)| wgpu::BindGroupEntry {
            binding: binding as u32,
            resource: match b.slot {
                Slot::Lights => lights.as_entire_binding(),
                Slot::MoreLights => more_lights.as_entire_binding(),
                Slot::Views => views.as_entire_binding(),
                Slot::PoissonTaps => taps.as_entire_binding(),
                Slot::CompareSampler => wgpu::BindingResource::Sampler(&layouts.shadow_compare),
                Slot::PointSampler => wgpu::BindingResource::Sampler(&layouts.shadow_point),
                Slot::WrapCompareSampler => wgpu::BindingResource::Sampler(&layouts.shadow_compare_wrap),
                Slot::WrapPointSampler => wgpu::BindingResource::Sampler(&layouts.shadow_point_wrap),
                Slot::MomentsSampler => wgpu::BindingResource::Sampler(&layouts.moments_sampler),
                Slot::Resolved => wgpu::BindingResource::TextureView(&visibility.view),
                Slot::Maps(s) => wgpu::BindingResource::TextureView(&maps[s.index()].array_view),
                Slot::Moments(s) => wgpu::BindingResource::TextureView(&moments[s.index()].moments.sampled),
                Slot::PageTable(_) => page_table.as_entire_binding(),
            },
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("shadows"),
        layout: &layouts.shadows,
        entries: &entries,
    })
}

/// The caster groups of one view and of a single-pass run of views over `buffer`.
pub(super) fn caster_groups(device: &wgpu::Device, layouts: &Layouts, buffer: &wgpu::Buffer) -> [wgpu::BindGroup; 2] {
    let group = |label, layout, views: usize| {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new((views * size_of::<CasterViewGpu>()) as u64),
                }),
            }],
        })
    };
    [
        group("caster views", &layouts.caster_view, 1),
        group("caster views (single pass)", &layouts.caster_views, SINGLE_PASS_VIEWS),
    ]
}
