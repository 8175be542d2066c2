//! The depth prepass: writes the camera's depth of every opaque and alpha-masked receiver
//! before the lighting pass, which then tests `GreaterEqual` against it without writing, so
//! each covered pixel is shaded once however much geometry overlaps it. It creates the
//! frame's camera depth (a transient of the graph) that the forward pass and later passes
//! read. When it does not run ([`RenderOptions::depth_prepass`](crate::render::RenderOptions):
//! off, or `Auto` on a view of more triangles than pixels), it declares nothing and is culled;
//! the forward pass then creates and writes the depth itself.
//!
//! With MSAA ([`FrameResources::samples`] > 1) the depth and normals are multisampled, and
//! alpha-masked batches are left to the lighting pass: it draws them with alpha-to-coverage,
//! whose per-sample coverage an alpha-tested prepass could not match (the samples it wrote
//! and the lighting pass left uncovered would keep the clear colour).

use std::borrow::Cow;

use crate::ecs::draw_groups::InstanceRun;
use crate::render::draw::{
    bind_camera_view, camera_parts, draw_batches, draw_culled, mesh_primitive, mesh_vertex_state,
};
use crate::render::frame::FrameContext;
use crate::render::frame_inputs::FrameInputs;
use crate::render::graph::{FrameResources, GraphResources, PassBuilder, RenderNode, TextureDesc, TextureId};
use crate::render::layouts::Layouts;
use crate::render::occlusion::occlusion_wanted;
use crate::render::options::DepthPrepass as PrepassMode;
use crate::render::scene_gpu::IndexList;
use crate::render::target::DEPTH_FORMAT;
use crate::shader::ShaderLibrary;

/// Name of the prepass in GPU timings and the graph.
pub const PREPASS_NAME: &str = "depth prepass";
/// Name of the prepass's second render pass, the late occlusion phase's draws.
pub const PREPASS_LATE_NAME: &str = "depth prepass late";

/// The camera's depth buffer at the target's size, with `samples` samples per pixel.
pub fn camera_depth((width, height): (u32, u32), samples: u32) -> TextureDesc {
    TextureDesc {
        label: "camera depth",
        width,
        height,
        layers: 1,
        format: DEPTH_FORMAT,
        // NOTE: sampled by later passes (the compute resolve), not only drawn into.
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        samples,
    }
}

/// A colour target of the prepass at the target's size, also read by later passes.
fn camera_target(
    label: &'static str,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    samples: u32,
) -> TextureDesc {
    TextureDesc {
        label,
        width,
        height,
        layers: 1,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        samples,
    }
}

/// Format of the normals the prepass writes for the compute resolve (octahedron-packed with
/// the receiver flag: `penumbra::normal_packing`).
pub const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// Format of the shading ids the prepass writes when the frame lights its pixels from them
/// ([`crate::render::deferred`]): each pixel's instance index.
pub const SHADING_ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// The prepass node; its pipelines (opaque or masked, single- or double-sided, with or
/// without normals, with or without shading ids) are built on first use, for the frame's
/// sample count (a new count rebuilds them).
#[derive(Default)]
pub struct DepthPrepass {
    /// Indexed by `ids as usize * 8 + normals as usize * 4 + masked as usize * 2 +
    /// double_sided as usize`.
    pipelines: [Option<wgpu::RenderPipeline>; 16],
    /// The sample count `pipelines` were built for.
    samples: u32,
    /// This frame's sample count, set in `setup`.
    frame_samples: u32,
    depth: Option<TextureId>,
    normals: Option<TextureId>,
    ids: Option<TextureId>,
    /// The textures already hold this frame's prepass ([`FrameResources::prepass_kept`]).
    kept: bool,
}

/// What selects a prepass pipeline.
#[derive(Clone, Copy)]
struct Key {
    masked: bool,
    double_sided: bool,
    normals: bool,
    /// Also the shading ids (only with normals).
    ids: bool,
    samples: u32,
}

impl DepthPrepass {
    fn pipeline(
        &mut self,
        device: &wgpu::Device,
        layouts: &Layouts,
        library: &mut ShaderLibrary,
        key: Key,
    ) -> &wgpu::RenderPipeline {
        if self.samples != key.samples {
            self.pipelines = Default::default();
            self.samples = key.samples;
        }
        let index =
            key.ids as usize * 8 + key.normals as usize * 4 + key.masked as usize * 2 + key.double_sided as usize;
        self.pipelines[index].get_or_insert_with(|| create_pipeline(device, layouts, library, key))
    }
}

fn create_pipeline(
    device: &wgpu::Device,
    layouts: &Layouts,
    library: &mut ShaderLibrary,
    key: Key,
) -> wgpu::RenderPipeline {
    let Key {
        masked,
        double_sided,
        normals,
        ids,
        samples,
    } = key;
    let module = library
        .prepass()
        .expect("the shipped prepass shader composes (checked by tests)");
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("depth prepass"),
        source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
    });
    let material = masked.then_some(&layouts.material);
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("depth prepass"),
        bind_group_layouts: &[Some(&layouts.view), Some(&layouts.instances), material],
        immediate_size: 0,
    });
    let targets = [
        Some(wgpu::ColorTargetState::from(NORMAL_FORMAT)),
        Some(wgpu::ColorTargetState::from(SHADING_ID_FORMAT)),
    ];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(PREPASS_NAME),
        layout: Some(&layout),
        vertex: mesh_vertex_state(&shader),
        primitive: mesh_primitive(double_sided),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Greater),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: samples,
            ..Default::default()
        },
        fragment: (masked || normals).then(|| wgpu::FragmentState {
            module: &shader,
            entry_point: Some(match (masked, normals, ids) {
                (true, false, _) => "fs_masked",
                (false, _, false) => "fs_normal",
                (true, true, false) => "fs_masked_normal",
                (false, _, true) => "fs_normal_id",
                (true, true, true) => "fs_masked_normal_id",
            }),
            compilation_options: Default::default(),
            targets: &targets[..normals as usize + ids as usize],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Whether the prepass runs this frame on a target of `size` pixels: as
/// [`RenderOptions::depth_prepass`](crate::render::RenderOptions::depth_prepass) decides,
/// and always for a paged sun (its pages are marked from the prepass's depth) or, unless the
/// prepass is off, for a light with contact shadows (they march over its depth); `Auto` runs
/// it too for the occlusion culling (which draws the hidden instances in neither pass).
pub fn prepass_runs(inputs: &FrameInputs<'_>, (width, height): (u32, u32)) -> bool {
    let pixels = u64::from(width) * u64::from(height);
    let mode = inputs.options.depth_prepass;
    mode.runs(|| visible_triangles(inputs), pixels)
        || (mode == PrepassMode::Auto && occlusion_wanted(inputs))
        || inputs.lights.paged_sun().is_some()
        || (mode != PrepassMode::Off && inputs.lights.any_contact_shadows())
}

/// Triangles the camera's view draws this frame (every instance of every batch); for a view
/// the GPU culls, at most: every instance of every run, with the whole mesh.
pub fn visible_triangles(inputs: &FrameInputs<'_>) -> u64 {
    let views = inputs.view_groups;
    let group = &views.group;
    let triangles = |mesh| inputs.meshes.get(mesh).map_or(0, |m| m.indices.len() as u64 / 3);
    if !views.runs.is_empty() {
        // NOTE: batches are numbered opaque first, then masked.
        let run_triangles = |r: &InstanceRun| {
            let b = r.batch as usize;
            let masked = || b.checked_sub(group.opaque.len()).and_then(|m| group.masked.get(m));
            let batch = group.opaque.get(b).or_else(masked);
            batch.map_or(0, |batch| triangles(batch.mesh) * u64::from(r.count))
        };
        return views.runs.iter().map(run_triangles).sum();
    }
    let batches = group.opaque.iter().chain(&group.masked);
    batches.map(|b| triangles(b.mesh) * u64::from(b.count)).sum()
}

impl RenderNode for DepthPrepass {
    fn name(&self) -> &'static str {
        PREPASS_NAME
    }

    /// Creates the camera depth and writes it (nothing when off); when the frame resolves
    /// visibility, also the normals the resolve reads. Where the renderer imported them (a
    /// kept prepass), writes those instead.
    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, _: &FrameInputs<'_>) {
        self.depth = None;
        self.normals = None;
        self.ids = None;
        self.kept = frame.prepass_kept;
        self.frame_samples = frame.samples;
        if let (true, Some(depth)) = (frame.depth_prepass, frame.depth) {
            self.depth = Some(pass.write(depth));
            self.normals = frame.normals.map(|n| pass.write(n));
            self.ids = frame.shading_ids.map(|i| pass.write(i));
        } else if frame.depth_prepass {
            let depth = pass.create_texture(camera_depth(frame.size, frame.samples));
            frame.depth = Some(depth);
            self.depth = Some(depth);
            if frame.visibility.is_some() {
                let normals = pass.create_texture(camera_target(
                    "camera normals",
                    frame.size,
                    NORMAL_FORMAT,
                    frame.samples,
                ));
                frame.normals = Some(normals);
                self.normals = Some(normals);
                if frame.deferred_lighting && frame.samples <= 1 {
                    let ids =
                        pass.create_texture(camera_target("camera shading ids", frame.size, SHADING_ID_FORMAT, 1));
                    frame.shading_ids = Some(ids);
                    self.ids = Some(ids);
                }
            }
        }
    }

    /// Draws the view's depth (and normals); with GPU culling, the early phase's list (culled
    /// at the frame's start), and with occlusion culling then the pyramid and the late test,
    /// then the late list over it. Draws nothing where the kept textures already hold the
    /// frame's prepass (no pyramid or late test either: the early list holds every instance
    /// seen).
    fn record(&mut self, ctx: &mut FrameContext<'_>, resources: &GraphResources, encoder: &mut wgpu::CommandEncoder) {
        let Some(depth) = self.depth else { return };
        if self.kept {
            return;
        }
        if !ctx.occlusion.active() {
            self.draw(ctx, resources, encoder, None);
            return;
        }
        self.draw(ctx, resources, encoder, Some(0));
        if ctx.occlusion.occluding() {
            ctx.occlusion
                .record_late(&ctx.gpu.device, encoder, ctx.timer, resources.view(depth));
            self.draw(ctx, resources, encoder, Some(1));
        }
    }
}

impl DepthPrepass {
    /// One render pass over the depth (cleared unless it draws the late phase): the view's
    /// list, or occlusion `phase` 0 (early) or 1 (late).
    fn draw(
        &mut self,
        ctx: &mut FrameContext<'_>,
        resources: &GraphResources,
        encoder: &mut wgpu::CommandEncoder,
        phase: Option<usize>,
    ) {
        let Some(depth) = self.depth else { return };
        let late = phase == Some(1);
        let attachment = |n| {
            Some(wgpu::RenderPassColorAttachment {
                view: resources.view(n),
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    // NOTE: not cleared: the resolve reads a pixel's normal only where the
                    // depth says it is covered, and every covered pixel is written here. A
                    // clear would cost about as much as the whole pass's fill on GPUs with few
                    // raster units (0.15 ms at 1920×1080 on the H100).
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        // NOTE: the shading ids likewise: read only where the depth is covered.
        let targets = [self.normals.and_then(attachment), self.ids.and_then(attachment)];
        let used = targets.iter().take_while(|t| t.is_some()).count();
        let name = if late { PREPASS_LATE_NAME } else { PREPASS_NAME };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(name),
            color_attachments: &targets[..used],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: resources.view(depth),
                depth_ops: Some(wgpu::Operations {
                    load: if late {
                        wgpu::LoadOp::Load
                    } else {
                        wgpu::LoadOp::Clear(0.0)
                    },
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: ctx.timer.pass(name),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let phases = ctx.occlusion.phases();
        let culled = phase.and_then(|p| phases.as_ref().map(|phases| &phases[p]));
        if !bind_camera_view(&mut pass, ctx.scene, culled.map(|c| c.instances)) {
            return;
        }
        let samples = self.frame_samples.max(1);
        // NOTE: with MSAA the lighting pass draws masked batches itself (alpha-to-coverage).
        for (masked, double_sided, part, first) in camera_parts(&ctx.view_groups.group, samples == 1) {
            if part.is_empty() {
                continue;
            }
            let device = &ctx.gpu.device;
            let key = Key {
                masked,
                double_sided,
                normals: self.normals.is_some(),
                ids: self.ids.is_some(),
                samples,
            };
            pass.set_pipeline(self.pipeline(device, ctx.layouts, ctx.library, key));
            ctx.draw_calls += match culled {
                Some(c) => draw_culled(
                    &mut pass,
                    ctx.scene,
                    part,
                    (masked, &[]),
                    (c.args, first),
                    ctx.draw_args,
                ),
                None => draw_batches(
                    &mut pass,
                    (ctx.scene, IndexList::Shaded),
                    part,
                    (masked, &[]),
                    ctx.draw_args,
                ),
            };
        }
    }
}
