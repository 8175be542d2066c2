//! The cascade moments pass (`shaders/shadow_cascade_moments.wgsl`): after the depth pass,
//! every cascade of a sun that filters moments (EVSM2, EVSM4, MSM) whose depth or moment
//! parameters changed gets its moments made again — one compute pass per cascade
//! (`shadow moments sun k cascade c`) that warps its depth into moments and, with a blur,
//! blurs them along x into the scratch and along y back, then with contact hardening averages
//! them down the mip chain one level at a time. No extra rasterisation: the moments
//! come from the depth cascades. It remembers what each layer's moments were made from, so a
//! still sun costs nothing.

use std::borrow::Cow;
use std::fmt::Write;

use bytemuck::{Pod, Zeroable};

use crate::layout::ShadowStorage;
use crate::render::frame::FrameContext;
use crate::render::frame_inputs::FrameInputs;
use crate::render::graph::{FrameResources, GraphResources, PassBuilder, RenderNode, TextureId};
use crate::render::shadows::jobs::{
    JobBuffer, array_texture_entry, compute_pipeline, job_binding, job_entry, moments_out_entry,
};
use crate::render::shadows::moment_storage::MomentArray;
use crate::render::shadows::storage::DepthArray;
use crate::render::shadows::sun_moments::{CascadeMoments, any_sun_moments, cascade_moments};
use crate::shader::ShaderLibrary;

/// Mirror of WGSL `CascadeMomentsJob`, padded to the 256-byte dynamic-offset alignment.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct JobGpu {
    src_layer: u32,
    dst_layer: u32,
    size: u32,
    technique: u32,
    c_positive: f32,
    c_negative: f32,
    radius: f32,
    axis: u32,
    depth_start: f32,
    variance_down: u32,
    _pad: [u32; 54],
}

/// One cascade whose moments are made this frame.
#[derive(Clone, Copy, Debug)]
struct Job {
    layer: u32,
    size: u32,
    moments: CascadeMoments,
    /// Index of the sun and of the cascade (for the pass name).
    sun: u32,
    cascade: u32,
}

/// One dispatch of a job: which of the node's groups it binds (0 resolve, 1 and 2 the blur's
/// axes, 2 + k the mip level k), its source and destination layers, the texels per side it
/// writes and its `axis` field.
type Stage = (usize, u32, u32, u32, u32);

impl Job {
    /// Its dispatches: the resolve, then with a blur both axes, then each mip level of `mips`.
    fn stages(&self, mips: u32) -> impl Iterator<Item = Stage> + use<> {
        let (layer, size) = (self.layer, self.size);
        // NOTE: the scratch holds one layer, from layer 0 (called twice per baked cascade
        // each frame, so nothing is collected).
        let blurs = self.moments.blur_texels > 0.0;
        let blur = [(1, layer, 0, size, 0), (2, 0, layer, size, 1)]
            .into_iter()
            .filter(move |_| blurs);
        let levels = (1..mips).map(move |level| {
            let (from, to) = ((size >> (level - 1)).max(1), (size >> level).max(1));
            (2 + level as usize, layer, layer, to, from)
        });
        std::iter::once((0, layer, layer, size, 0)).chain(blur).chain(levels)
    }
}

/// The pipelines of one moments format.
struct Pipelines {
    format: wgpu::TextureFormat,
    resolve_layout: wgpu::BindGroupLayout,
    blur_layout: wgpu::BindGroupLayout,
    resolve: wgpu::ComputePipeline,
    blur: wgpu::ComputePipeline,
    downsample: wgpu::ComputePipeline,
}

/// What a layer's moments were made from: the depth's content version and the parameters.
type Held = (u64, [f32; 6]);

/// The cascade moments node.
#[derive(Default)]
pub struct CascadeMomentsPass {
    pipelines: Option<Pipelines>,
    /// The per-dispatch uniforms.
    jobs_buffer: JobBuffer,
    /// The resolve, blur and mip groups, with the depth and moments allocations and the
    /// buffer generation they were made for.
    groups: Option<((u64, u64, u64), Vec<wgpu::BindGroup>)>,
    /// The depth and moments allocations `held` refers to, and what each layer holds.
    held_for: (u64, u64),
    held: Vec<Held>,
    /// This frame's cascade depth array and moments in the graph.
    handles: Option<(TextureId, TextureId)>,
    cache: bool,
    jobs: Vec<Job>,
    data: Vec<JobGpu>,
    name: String,
}

fn create_pipelines(device: &wgpu::Device, library: &mut ShaderLibrary, format: wgpu::TextureFormat) -> Pipelines {
    let storage = moments_out_entry(format);
    let job = job_entry::<JobGpu>();
    let layout = |label, first| {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries: &[first, storage, job],
        })
    };
    let resolve_layout = layout(
        "cascade moments resolve",
        array_texture_entry(0, wgpu::TextureSampleType::Depth),
    );
    let blur_layout = layout(
        "cascade moments blur",
        array_texture_entry(3, wgpu::TextureSampleType::Float { filterable: false }),
    );
    let module = library
        .cascade_moments(format)
        .expect("the shipped cascade moments shader composes (checked by tests)");
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("cascade moments"),
        source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
    });
    let pipeline = |layout: &wgpu::BindGroupLayout, entry_point: &str| {
        compute_pipeline(device, "cascade moments", &shader, layout, entry_point)
    };
    Pipelines {
        format,
        resolve: pipeline(&resolve_layout, "resolve"),
        blur: pipeline(&blur_layout, "blur"),
        downsample: pipeline(&blur_layout, "downsample"),
        resolve_layout,
        blur_layout,
    }
}

impl RenderNode for CascadeMomentsPass {
    fn name(&self) -> &'static str {
        "shadow cascade moments"
    }

    /// Reads the cascades' depth and writes their moments while a sun filters moments; else
    /// nothing (the node is culled).
    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, inputs: &FrameInputs<'_>) {
        self.cache = inputs.options.shadow_cache;
        self.handles = Some((
            frame.maps(ShadowStorage::Cascades),
            frame.moments(ShadowStorage::Cascades),
        ));
        if any_sun_moments(inputs.lights) {
            pass.read(frame.maps(ShadowStorage::Cascades));
            pass.write(frame.moments(ShadowStorage::Cascades));
        }
    }

    fn record(&mut self, ctx: &mut FrameContext<'_>, res: &GraphResources, encoder: &mut wgpu::CommandEncoder) {
        let Some((depth, moments)) = self.handles else {
            return;
        };
        let (depth, moments) = (res.object::<DepthArray>(depth), res.object::<MomentArray>(moments));
        self.plan(ctx, (depth.id, moments.id));
        if self.jobs.is_empty() {
            return;
        }
        let device = &ctx.gpu.device;
        let format = moments.moments.texture.format();
        if self.pipelines.as_ref().is_none_or(|p| p.format != format) {
            self.pipelines = Some(create_pipelines(device, ctx.library, format));
            self.groups = None;
        }
        let Some(pipelines) = &self.pipelines else {
            return;
        };
        // NOTE: one uniform entry per dispatch: resolve depth → moments; blur x moments →
        // scratch (layer 0); blur y scratch → moments; each mip level from the one before.
        let mips = moments.mips();
        self.data.clear();
        for job in &self.jobs {
            for (_, src_layer, dst_layer, size, axis) in job.stages(mips) {
                let m = &job.moments;
                self.data.push(JobGpu {
                    src_layer,
                    dst_layer,
                    size,
                    technique: m.technique,
                    c_positive: m.c_positive,
                    c_negative: m.c_negative,
                    radius: m.blur_texels,
                    axis,
                    depth_start: m.depth_start,
                    variance_down: u32::from(m.variance_down),
                    _pad: [0; 54],
                });
            }
        }
        let uploaded = self
            .jobs_buffer
            .upload(device, &ctx.gpu.queue, "cascade moments jobs", &self.data);
        let Some((buffer, generation)) = uploaded else {
            return;
        };
        let key = (depth.id, moments.id, generation);
        if self.groups.as_ref().is_none_or(|(held, _)| *held != key) {
            self.groups = Some((key, bind_groups(device, pipelines, buffer, depth, moments)));
        }
        let Some((_, groups)) = &self.groups else {
            return;
        };
        let mut entry = 0;
        for job in &self.jobs {
            self.name.clear();
            // NOTE: writing to a String cannot fail.
            let _ = write!(self.name, "shadow moments sun {} cascade {}", job.sun, job.cascade);
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(&self.name),
                timestamp_writes: ctx.timer.compute_pass(&self.name),
            });
            for (group, _, _, size, _) in job.stages(mips) {
                let pipeline = match group {
                    0 => &pipelines.resolve,
                    1 | 2 => &pipelines.blur,
                    _ => &pipelines.downsample,
                };
                let offset = (entry * size_of::<JobGpu>()) as u32;
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &groups[group], &[offset]);
                pass.dispatch_workgroups(size.div_ceil(8), size.div_ceil(8), 1);
                entry += 1;
            }
        }
    }
}

/// The resolve group, both blur groups (x: moments → scratch, y: scratch → moments) and one
/// group per mip level from the second (the level before → the level).
fn bind_groups(
    device: &wgpu::Device,
    pipelines: &Pipelines,
    buffer: &wgpu::Buffer,
    depth: &DepthArray,
    moments: &MomentArray,
) -> Vec<wgpu::BindGroup> {
    let job = job_binding::<JobGpu>(buffer);
    let group = |label, layout, (binding, from): (u32, &wgpu::TextureView), to: &wgpu::TextureView| {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding,
                    resource: wgpu::BindingResource::TextureView(from),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(to),
                },
                job.clone(),
            ],
        })
    };
    let resolve_layout = &pipelines.resolve_layout;
    let blur_layout = &pipelines.blur_layout;
    let mut groups = vec![
        group(
            "cascade moments resolve",
            resolve_layout,
            (0, &depth.flat_view),
            &moments.moments.storage,
        ),
        group(
            "cascade moments blur",
            blur_layout,
            (3, &moments.moments.sampled),
            &moments.scratch.storage,
        ),
        group(
            "cascade moments blur",
            blur_layout,
            (3, &moments.scratch.sampled),
            &moments.moments.storage,
        ),
    ];
    for (write, read) in &moments.moments.levels {
        groups.push(group("cascade moments mip", blur_layout, (3, read), write));
    }
    groups
}

impl CascadeMomentsPass {
    /// Lists the cascades whose moments must be made this frame (their depth or parameters
    /// changed, the allocations are new, or the cache is off), and marks what their layers
    /// hold.
    /// `ids` are this frame's depth and moments allocation ids.
    fn plan(&mut self, ctx: &FrameContext<'_>, ids: (u64, u64)) {
        self.jobs.clear();
        if self.held_for != ids {
            self.held_for = ids;
            self.held.clear();
        }
        let fp32 = ctx.gpu.filters_fp32();
        for view in &ctx.shadow_views.views {
            if view.kind.storage != ShadowStorage::Cascades {
                continue;
            }
            let c = view.kind.index;
            let Some(sun) = ctx.lights.sun_at(view.light) else {
                continue;
            };
            let Some(moments) = cascade_moments(sun, c as usize, fp32) else {
                continue;
            };
            let params = [
                moments.technique as f32,
                moments.c_positive,
                moments.c_negative,
                moments.blur_texels,
                moments.depth_start,
                f32::from(u8::from(moments.variance_down)),
            ];
            let slot = view.slot as usize;
            if self.held.len() <= slot {
                self.held.resize(slot + 1, (0, [0.0; 6]));
            }
            let made = (view.version, params);
            // NOTE: a scrolling clipmap level keeps its version while its texels move or its
            // regions are drawn again; its moments follow the depth it holds this frame.
            let redrawn = view.scroll.is_some_and(|s| s.from != s.to || s.region_count > 0);
            if self.cache && self.held[slot] == made && !redrawn {
                continue;
            }
            self.held[slot] = made;
            self.jobs.push(Job {
                layer: view.slot,
                size: view.resolution,
                moments,
                sun: view.light,
                cascade: c,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use std::mem::offset_of;

    use super::*;

    #[test]
    fn a_job_resolves_blurs_through_the_scratch_and_fills_each_mip_level() {
        let job = |blur_texels| Job {
            layer: 2,
            size: 1024,
            moments: CascadeMoments {
                technique: 5,
                c_positive: 0.0,
                c_negative: 0.0,
                blur_texels,
                depth_start: 0.0,
                variance_down: false,
            },
            sun: 0,
            cascade: 2,
        };
        // (group, source layer, destination layer, side written, axis or side read)
        let stages: Vec<Stage> = job(1.5).stages(3).collect();
        assert_eq!(
            stages,
            [
                (0, 2, 2, 1024, 0),
                (1, 2, 0, 1024, 0),
                (2, 0, 2, 1024, 1),
                (3, 2, 2, 512, 1024),
                (4, 2, 2, 256, 512)
            ]
        );
        let unblurred: Vec<usize> = job(0.0).stages(1).map(|s| s.0).collect();
        assert_eq!(unblurred, [0]);
    }

    #[test]
    fn the_job_uniform_matches_the_wgsl_layout() {
        let mut library = ShaderLibrary::new().unwrap();
        let module = library.cascade_moments(wgpu::TextureFormat::Rgba16Float).unwrap();
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref().is_some_and(|n| n.starts_with("CascadeMomentsJob")))
            .expect("CascadeMomentsJob in the cascade moments shader");
        let naga::TypeInner::Struct { members, .. } = &ty.inner else {
            panic!("CascadeMomentsJob is not a struct")
        };
        let wgsl: Vec<(&str, usize)> = members
            .iter()
            .map(|m| (m.name.as_deref().unwrap_or(""), m.offset as usize))
            .collect();
        let rust = [
            ("src_layer", offset_of!(JobGpu, src_layer)),
            ("dst_layer", offset_of!(JobGpu, dst_layer)),
            ("size", offset_of!(JobGpu, size)),
            ("technique", offset_of!(JobGpu, technique)),
            ("c_positive", offset_of!(JobGpu, c_positive)),
            ("c_negative", offset_of!(JobGpu, c_negative)),
            ("radius", offset_of!(JobGpu, radius)),
            ("axis", offset_of!(JobGpu, axis)),
            ("depth_start", offset_of!(JobGpu, depth_start)),
            ("variance_down", offset_of!(JobGpu, variance_down)),
        ];
        assert_eq!(wgsl, rust);
        assert_eq!(size_of::<JobGpu>(), 256);
    }
}
