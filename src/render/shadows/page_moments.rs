//! A paged sun's moments (EVSM2, EVSM4, MSM) on the GPU (`page_bake` of
//! `shaders/shadow_cascade_moments.wgsl` with `PAGES`): after the pages are drawn, every page
//! drawn this frame (the allocation's list) is turned into moments and blurred in one
//! dispatch, indirect like the drawing (a row of workgroups per listed page), into the
//! moments atlas laid out as the pool's. Each level is baked with the parameters the plain
//! clipmap's level would have ([`cascade_moments`](crate::render::shadows::sun_moments::cascade_moments));
//! a page's blur stops at its edge (taps past it repeat its edge texels), so a page never
//! depends on a neighbour that may not be resident. With contact hardening the moments are
//! unblurred and each drawn page is averaged down the atlas's mip levels (`page_downsample`,
//! a dispatch per level), tile by tile. A page that is not drawn again keeps its moments, as
//! it keeps its depth.

use std::borrow::Cow;

use bytemuck::{Pod, Zeroable};

use crate::render::shadows::jobs::{
    array_texture_entry, compute_pipeline, moments_out_entry, storage_entry, uniform_entry,
};
use crate::render::shadows::moment_storage::MomentArray;
use crate::render::shadows::page_allocate::{MAX_PAGED_LEVELS, PageAllocator};
use crate::render::shadows::storage::DepthArray;
use crate::render::shadows::sun_moments::{CascadeMoments, MOMENT_MIPS};
use crate::shader::ShaderLibrary;

/// Mirror of WGSL `PageLevelMoments`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
struct LevelGpu {
    technique: u32,
    c_positive: f32,
    c_negative: f32,
    radius: f32,
    depth_start: f32,
    variance_down: u32,
    _pad: [u32; 2],
}

/// Mirror of WGSL `PageMoments`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct PageMomentsGpu {
    tiles: u32,
    page_size: u32,
    _pad: [u32; 2],
    level: [LevelGpu; MAX_PAGED_LEVELS],
}

/// Texels per side of a workgroup of the bake.
const BLOCK: u32 = 8;

/// The bake's pipeline for one moments format, its uniforms and indirect dispatch.
pub struct PageMoments {
    /// The format the moments are written in.
    pub format: wgpu::TextureFormat,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    downsample: (wgpu::ComputePipeline, wgpu::BindGroupLayout),
    uniforms: wgpu::Buffer,
    /// The dispatches, one per mip level: a workgroup per 8×8 block of a page at that level,
    /// a row per page drawn.
    args: wgpu::Buffer,
    /// The uniforms and mip count last written.
    written: Option<(PageMomentsGpu, u32)>,
    /// The bake's group, then one per mip level past the first, and the atlas and moments
    /// they bind (their ids).
    groups: Option<((u64, u64), Vec<wgpu::BindGroup>)>,
}

/// Bytes of one indirect dispatch.
const DISPATCH_BYTES: u64 = 16;

impl PageMoments {
    /// The bake writing moments in `format`.
    pub fn new(device: &wgpu::Device, library: &mut ShaderLibrary, format: wgpu::TextureFormat) -> Self {
        let module = library
            .page_moments(format)
            .expect("the shipped page moments shader composes (checked by tests)");
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("page moments"),
            source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
        });
        let compute = wgpu::ShaderStages::COMPUTE;
        // NOTE: both stages write binding 1 from the list; the bake reads the depth (binding
        // 0), a mip level the level before (binding 5).
        let layout = |label, texture| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries: &[
                    texture,
                    moments_out_entry(format),
                    uniform_entry(2, compute, false, size_of::<PageMomentsGpu>() as u64),
                    storage_entry(3, compute, true),
                    storage_entry(4, compute, true),
                ],
            })
        };
        let bake_layout = layout("page moments", array_texture_entry(0, wgpu::TextureSampleType::Depth));
        let unfiltered = wgpu::TextureSampleType::Float { filterable: false };
        let mip_layout = layout("page moments mips", array_texture_entry(5, unfiltered));
        let pipeline = compute_pipeline(device, "page moments", &shader, &bake_layout, "page_bake");
        let downsample = compute_pipeline(device, "page moments mips", &shader, &mip_layout, "page_downsample");
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("page moments"),
            size: size_of::<PageMomentsGpu>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let args = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("page moments dispatch"),
            size: DISPATCH_BYTES * u64::from(MOMENT_MIPS),
            usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            format,
            pipeline,
            layout: bake_layout,
            downsample: (downsample, mip_layout),
            uniforms,
            args,
            written: None,
            groups: None,
        }
    }

    /// Records the bake of the pages `allocator` listed for drawing this frame, from `atlas`
    /// into `moments` (both `tiles` pages of `page_size` texels a side), level `l` baked as
    /// `levels[l]` says, then averaged down each of the moments' mip levels; timed by
    /// `timestamps`.
    pub fn record(
        &mut self,
        (device, queue, encoder): (&wgpu::Device, &wgpu::Queue, &mut wgpu::CommandEncoder),
        allocator: &PageAllocator,
        (atlas, moments): (&DepthArray, &MomentArray),
        (tiles, page_size): (u32, u32),
        levels: &[CascadeMoments],
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let mut data = PageMomentsGpu {
            tiles,
            page_size,
            _pad: [0; 2],
            level: [LevelGpu::default(); MAX_PAGED_LEVELS],
        };
        for (gpu, m) in data.level.iter_mut().zip(levels) {
            *gpu = LevelGpu {
                technique: m.technique,
                c_positive: m.c_positive,
                c_negative: m.c_negative,
                radius: m.blur_texels,
                depth_start: m.depth_start,
                variance_down: u32::from(m.variance_down),
                _pad: [0; 2],
            };
        }
        let mips = moments.mips().min(MOMENT_MIPS);
        // NOTE: the uniforms and the dispatches' widths are written only when they change (the
        // rows are copied in below every frame).
        let same = self
            .written
            .as_ref()
            .is_some_and(|(d, m)| bytemuck::bytes_of(d) == bytemuck::bytes_of(&data) && *m == mips);
        if !same {
            queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&data));
            let mut args = [0u32; 4 * MOMENT_MIPS as usize];
            for (m, dispatch) in args.chunks_exact_mut(4).enumerate().take(mips as usize) {
                dispatch.copy_from_slice(&[((page_size >> m) / BLOCK).max(1).pow(2), 0, 1, 0]);
            }
            queue.write_buffer(&self.args, 0, bytemuck::cast_slice(&args));
            self.written = Some((data, mips));
        }
        let (draws, counters, _) = allocator.draw_buffers();
        // NOTE: the rows are the allocation's count of pages drawn: a frame that draws none
        // bakes none.
        for m in 0..u64::from(mips) {
            encoder.copy_buffer_to_buffer(counters, 4, &self.args, m * DISPATCH_BYTES + 4, 4);
        }
        let key = (atlas.id, moments.id);
        if self.groups.as_ref().is_none_or(|(k, _)| *k != key) {
            // NOTE: binding 1 is the level written; the bake reads the depth (binding 0), a
            // mip level the level before (binding 5).
            let uniforms = &self.uniforms;
            let group = |label: &str,
                         layout: &wgpu::BindGroupLayout,
                         write: &wgpu::TextureView,
                         (binding, read): (u32, &wgpu::TextureView)| {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(label),
                    layout,
                    entries: &[
                        texture_entry(binding, read),
                        texture_entry(1, write),
                        buffer_entry(2, uniforms),
                        buffer_entry(3, draws),
                        buffer_entry(4, counters),
                    ],
                })
            };
            let bake = group(
                "page moments",
                &self.layout,
                &moments.moments.storage,
                (0, &atlas.array_view),
            );
            let levels = moments.moments.levels.iter();
            let levels = levels.map(|(write, read)| group("page moments mip", &self.downsample.1, write, (5, read)));
            let groups = std::iter::once(bake).chain(levels).collect();
            self.groups = Some((key, groups));
        }
        let Some((_, groups)) = &self.groups else {
            return;
        };
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("page moments"),
            timestamp_writes: timestamps,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &groups[0], &[]);
        pass.dispatch_workgroups_indirect(&self.args, 0);
        // NOTE: each level reads the one before, written by the dispatch before it.
        pass.set_pipeline(&self.downsample.0);
        for (m, group) in groups.iter().enumerate().take(mips as usize).skip(1) {
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups_indirect(&self.args, m as u64 * DISPATCH_BYTES);
        }
    }
}

fn texture_entry(binding: u32, view: &wgpu::TextureView) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: wgpu::BindingResource::TextureView(view),
    }
}

fn buffer_entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}

#[cfg(test)]
mod tests {
    use std::mem::offset_of;

    use super::*;
    use crate::render::shadows::jobs::layout_check::wgsl_layout;

    #[test]
    fn the_uniforms_match_the_wgsl_layout() {
        let fields = |list: &[(&str, usize)]| list.iter().map(|(n, o)| (n.to_string(), *o)).collect::<Vec<_>>();
        let module = ShaderLibrary::new()
            .unwrap()
            .page_moments(wgpu::TextureFormat::Rgba32Float)
            .unwrap();
        let top = [
            ("tiles", offset_of!(PageMomentsGpu, tiles)),
            ("page_size", offset_of!(PageMomentsGpu, page_size)),
            ("level", offset_of!(PageMomentsGpu, level)),
        ];
        assert_eq!(
            wgsl_layout(&module, "PageMoments"),
            (fields(&top), size_of::<PageMomentsGpu>())
        );
        let level = [
            ("technique", offset_of!(LevelGpu, technique)),
            ("c_positive", offset_of!(LevelGpu, c_positive)),
            ("c_negative", offset_of!(LevelGpu, c_negative)),
            ("radius", offset_of!(LevelGpu, radius)),
            ("depth_start", offset_of!(LevelGpu, depth_start)),
            ("variance_down", offset_of!(LevelGpu, variance_down)),
        ];
        assert_eq!(
            wgsl_layout(&module, "PageLevelMoments"),
            (fields(&level), size_of::<LevelGpu>())
        );
    }
}
