//! Forward pass: draws what the camera sees, shading receivers with every light's diffuse
//! term times its shadow from `penumbra::lights`, plus ambient light. With MSAA
//! ([`FrameResources::samples`] > 1) it draws into a multisampled colour transient resolved
//! into the target at the end of the pass, and alpha-masked materials use alpha-to-coverage
//! (drawn here only, writing their depth: the prepass leaves them out).

use std::borrow::Cow;
use std::collections::HashMap;

use crate::ecs::draw_groups::DrawBatch;
use crate::render::deferred::{DeferredInputs, DeferredPass, DeferredTarget};
use crate::render::depth_bounds::wants_depth_bounds;
use crate::render::draw::{
    bind_camera_view, camera_parts, draw_batches, draw_culled, mesh_primitive, mesh_vertex_state, skipped,
};
use crate::render::frame::FrameContext;
use crate::render::frame_inputs::FrameInputs;
use crate::render::graph::{FrameResources, GraphResources, PassBuilder, RenderNode, TextureDesc, TextureId};
use crate::render::layouts::Layouts;
use crate::render::occlusion::Phase;
use crate::render::prepass::camera_depth;
use crate::render::scene_gpu::IndexList;
use crate::render::target::{ANALYSIS_FORMAT, DEPTH_FORMAT};
use crate::render::variant::forward_variant;
use crate::shader::{ForwardVariant, ShaderLibrary};

/// Name of the forward pass in GPU timings.
pub const FORWARD_PASS_NAME: &str = "forward";

/// What a forward pipeline is built for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct PipelineKey {
    variant: ForwardVariant,
    format: wgpu::TextureFormat,
    /// No back-face culling.
    double_sided: bool,
    /// Depth comes from the prepass: test `GreaterEqual`, write nothing.
    depth_prepass: bool,
    /// Samples per pixel (MSAA).
    samples: u32,
}

/// A built pipeline and the shader generation it was built from.
struct Built {
    generation: u64,
    pipeline: Option<wgpu::RenderPipeline>,
}

/// The forward node; pipelines are created on first use of each variant and rebuilt when the
/// forward shader changes. A rebuild that fails keeps the last good pipeline.
#[derive(Default)]
pub struct ForwardPass {
    pipelines: HashMap<PipelineKey, Built>,
    /// Colour the target is cleared to (linear RGB).
    pub clear_color: [f64; 3],
    /// This frame's resources, set in `setup`; `depth_prepass` says whether the depth was
    /// written before this pass (so it is loaded and tested, not written).
    handles: Option<FrameResources>,
    /// The multisampled colour this frame draws into (resolved into the target), with MSAA.
    multisampled_color: Option<TextureId>,
    /// Whether a later pass (the depth-bounds reduction) reads the depth this pass creates,
    /// which is then stored instead of discarded.
    keep_depth: bool,
    /// The deferred lighting of the prepass's pixels, recorded first when the frame lights
    /// them so.
    deferred: DeferredPass,
}

/// Builds one pipeline, catching shader and pipeline errors instead of panicking.
fn create_pipeline(
    device: &wgpu::Device,
    layouts: &Layouts,
    library: &mut ShaderLibrary,
    key: PipelineKey,
) -> Result<wgpu::RenderPipeline, String> {
    let module = library.forward(key.variant).map_err(|e| e.to_string())?;
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("forward"),
        source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("forward"),
        bind_group_layouts: &[
            Some(&layouts.view),
            Some(&layouts.instances),
            Some(&layouts.material),
            Some(&layouts.shadows),
        ],
        immediate_size: 0,
    });
    let color = wgpu::ColorTargetState {
        format: key.format,
        blend: None,
        // NOTE: with alpha-to-coverage the shader's alpha is the coverage, not the pixel's
        // opacity: the target keeps the alpha it was cleared to.
        write_mask: if key.variant.alpha_to_coverage {
            wgpu::ColorWrites::COLOR
        } else {
            wgpu::ColorWrites::ALL
        },
    };
    let mut targets = vec![Some(color)];
    if key.variant.analysis {
        targets.extend((0..3).map(|_| Some(ANALYSIS_FORMAT.into())));
    }
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(&format!("forward {}", key.variant.label())),
        layout: Some(&layout),
        vertex: mesh_vertex_state(&shader),
        primitive: mesh_primitive(key.double_sided),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(!key.depth_prepass),
            // NOTE: after the prepass the nearest surface's depth is in the buffer, written by
            // the same @invariant vertex stage: it passes `GreaterEqual`, hidden ones fail.
            depth_compare: Some(if key.depth_prepass {
                wgpu::CompareFunction::GreaterEqual
            } else {
                wgpu::CompareFunction::Greater
            }),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: key.samples,
            mask: !0,
            alpha_to_coverage_enabled: key.variant.alpha_to_coverage,
        },
        fragment: Some(wgpu::FragmentState {
            module: &shader,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    });
    match pollster::block_on(scope.pop()) {
        None => Ok(pipeline),
        Some(error) => Err(format!("forward pipeline `{}`: {error}", key.variant.label())),
    }
}

impl ForwardPass {
    /// A forward pass clearing to `clear_color` (linear RGB).
    pub fn new(clear_color: [f64; 3]) -> Self {
        Self {
            pipelines: HashMap::new(),
            clear_color,
            handles: None,
            multisampled_color: None,
            keep_depth: false,
            deferred: DeferredPass::default(),
        }
    }

    /// The pipeline for `key`, built (or rebuilt for a new shader generation) on demand. When
    /// the build fails the error is reported in the frame context and the previous pipeline,
    /// if any, is kept; the build is not retried until the shader changes again.
    fn pipeline(&mut self, ctx: &mut FrameContext<'_>, key: PipelineKey) -> Option<wgpu::RenderPipeline> {
        let generation = ctx.library.forward_generation();
        let built = self.pipelines.entry(key).or_insert(Built {
            generation: u64::MAX,
            pipeline: None,
        });
        if built.generation != generation {
            built.generation = generation;
            match create_pipeline(&ctx.gpu.device, ctx.layouts, ctx.library, key) {
                Ok(pipeline) => {
                    built.pipeline = Some(pipeline);
                    ctx.counters.forward_pipelines += 1;
                }
                Err(message) => {
                    log::error!("{message}; keeping the last good pipeline");
                    *ctx.pipeline_error = Some(message);
                }
            }
        }
        built.pipeline.clone()
    }
}

impl RenderNode for ForwardPass {
    fn name(&self) -> &'static str {
        FORWARD_PASS_NAME
    }

    /// Reads both shadow storages; writes the colour (and analysis) targets; reads the camera
    /// depth an earlier node (the prepass) wrote, or creates and writes it. With MSAA it also
    /// creates the multisampled colour it resolves into the target.
    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, inputs: &FrameInputs<'_>) {
        self.keep_depth = wants_depth_bounds(inputs);
        for texture in frame.shadow_textures() {
            pass.read(texture);
        }
        if let Some(visibility) = frame.visibility {
            pass.read(visibility);
        }
        let loaded = frame.depth.is_some();
        let samples = frame.samples.max(1);
        let depth = match frame.depth {
            Some(depth) => pass.read(depth),
            None => *frame
                .depth
                .insert(pass.create_texture(camera_depth(frame.size, samples))),
        };
        self.multisampled_color = (samples > 1).then(|| {
            let (width, height) = frame.size;
            pass.create_texture(TextureDesc {
                label: "camera colour (multisampled)",
                width,
                height,
                layers: 1,
                format: frame.color_format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                samples,
            })
        });
        // NOTE: the prepass makes the shading ids only when the frame lights its pixels.
        if let (Some(normals), Some(ids)) = (frame.normals, frame.shading_ids) {
            pass.read(normals);
            pass.read(ids);
            if let Some(storage) = frame.color_storage {
                pass.write(storage);
            }
        }
        pass.write(frame.color);
        for target in frame.analysis.iter().flatten() {
            pass.write(*target);
        }
        self.handles = Some(FrameResources {
            depth: Some(depth),
            depth_prepass: loaded,
            ..*frame
        });
    }

    fn record(&mut self, ctx: &mut FrameContext<'_>, resources: &GraphResources, encoder: &mut wgpu::CommandEncoder) {
        let Some(FrameResources {
            color,
            color_format: format,
            analysis: analysis_targets,
            depth: Some(depth),
            depth_prepass,
            visibility,
            samples,
            normals,
            shading_ids,
            color_storage,
            size,
            ..
        }) = self.handles
        else {
            return;
        };
        let analysis = analysis_targets.is_some();
        let lights = ctx.lights;
        let variant_of = |ctx: &FrameContext<'_>, alpha_mask| {
            let variant = ForwardVariant {
                analysis,
                transmission: ctx.scene.any_transmission,
                ..forward_variant(lights, alpha_mask).with_samples(samples)
            };
            // NOTE: a light whose layer holds its contact shadows alone filters its own
            // shadow maps in this pass.
            let filters_resolved = ctx.shadows.resolved.as_ref().is_some_and(|r| r.filters);
            match visibility {
                Some(_) if filters_resolved => variant.reading_resolved(),
                _ => variant,
            }
        };
        // NOTE: a frame that resolved its shadows reads them through the group that binds the
        // resolved visibility (the lights' resolve layers point into it).
        let shadow_group = match (&ctx.shadows.resolved, visibility.is_some()) {
            (Some(r), true) => r.group.clone(),
            _ => ctx.shadows.group.clone(),
        };
        let [r, g, b] = self.clear_color;
        let clear = wgpu::Color { r, g, b, a: 1.0 };
        let deferred_inputs = match (depth_prepass, normals, shading_ids) {
            (true, Some(normals), Some(ids)) => Some(DeferredInputs { depth, normals, ids }),
            _ => None,
        };
        let deferred = deferred_inputs.is_some_and(|inputs| {
            let variant = variant_of(ctx, false);
            let target = DeferredTarget {
                color: resources.view(color),
                format,
                storage: color_storage.map(|s| resources.view(s)),
                clear,
                size,
            };
            self.deferred
                .record(ctx, resources, encoder, (inputs, variant, &shadow_group), target)
        });
        ctx.deferred_lighting = deferred;
        let mut pipeline = |ctx: &mut FrameContext<'_>, alpha_mask, double_sided| {
            let variant = variant_of(ctx, alpha_mask);
            self.pipeline(
                ctx,
                PipelineKey {
                    variant,
                    format,
                    double_sided,
                    // NOTE: alpha-to-coverage materials are not in the prepass: they write
                    // their own depth.
                    depth_prepass: depth_prepass && !variant.alpha_to_coverage,
                    samples: samples.max(1),
                },
            )
        };
        // Only the pipelines this frame draws with are built.
        let view_groups = ctx.view_groups;
        let group = &view_groups.group;
        let scene = ctx.scene;
        // NOTE: the materials the deferred lighting lit are not drawn again.
        let skip: &[bool] = if deferred { &scene.untextured } else { &[] };
        let wanted = |list: &[DrawBatch], sided| list.iter().any(|b| b.double_sided == sided && !skipped(skip, b));
        let wants = [
            wanted(&group.opaque, false),
            wanted(&group.opaque, true),
            wanted(&group.masked, false),
            wanted(&group.masked, true),
        ];
        let mut pipelines: [Option<wgpu::RenderPipeline>; 4] = [const { None }; 4];
        for (i, slot) in pipelines.iter_mut().enumerate() {
            if wants[i] {
                *slot = pipeline(ctx, i >= 2, i % 2 == 1);
            }
        }
        let attachment = |view, load| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        // NOTE: a fixed array, not a Vec: nothing is allocated per frame.
        let mut color_attachments = [const { None }; 4];
        color_attachments[0] = match self.multisampled_color {
            // NOTE: only the resolved target is kept; the samples are discarded.
            Some(samples) => Some(wgpu::RenderPassColorAttachment {
                view: resources.view(samples),
                depth_slice: None,
                resolve_target: Some(resources.view(color)),
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(clear),
                    store: wgpu::StoreOp::Discard,
                },
            }),
            // NOTE: over the pixels the deferred lighting wrote.
            None if deferred => attachment(resources.view(color), wgpu::LoadOp::Load),
            None => attachment(resources.view(color), wgpu::LoadOp::Clear(clear)),
        };
        let mut used = 1;
        // Background: shadow factor 1 (nothing shadows the sky), cascade -1, position w = 0.
        let clears = [
            wgpu::Color {
                r: 1.0,
                g: -1.0,
                b: 0.0,
                a: 0.0,
            },
            wgpu::Color::TRANSPARENT,
            wgpu::Color::TRANSPARENT,
        ];
        for (target, clear) in analysis_targets.iter().flatten().zip(clears) {
            color_attachments[used] = attachment(resources.view(*target), wgpu::LoadOp::Clear(clear));
            used += 1;
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(FORWARD_PASS_NAME),
            color_attachments: &color_attachments[..used],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: resources.view(depth),
                depth_ops: Some(if depth_prepass {
                    wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    }
                } else {
                    wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: if self.keep_depth {
                            wgpu::StoreOp::Store
                        } else {
                            wgpu::StoreOp::Discard
                        },
                    }
                }),
                stencil_ops: None,
            }),
            timestamp_writes: ctx.timer.pass(FORWARD_PASS_NAME),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if !bind_camera_view(&mut pass, ctx.scene, None) {
            return;
        }
        pass.set_bind_group(3, &shadow_group, &[]);
        if let Some(counter) = ctx.fragments {
            pass.begin_pipeline_statistics_query(&counter.query_set, 0);
        }
        let group = &ctx.view_groups.group;
        let args = &mut *ctx.draw_args;
        // Every batch with its pipeline, from the view's list or a culling phase's arguments.
        let mut draw = |pass: &mut wgpu::RenderPass<'_>, culled: Option<&Phase<'_>>| {
            let mut calls = 0;
            for (masked, double_sided, part, first) in camera_parts(group, true) {
                let pipeline = &pipelines[masked as usize * 2 + double_sided as usize];
                let (false, Some(pipeline)) = (part.is_empty(), pipeline) else {
                    continue;
                };
                pass.set_pipeline(pipeline);
                calls += match culled {
                    Some(c) => draw_culled(pass, scene, part, (true, skip), (c.args, first), args),
                    None => draw_batches(pass, (scene, IndexList::Shaded), part, (true, skip), args),
                };
            }
            calls
        };
        let mut calls = 0;
        match ctx.occlusion.phases() {
            Some(phases) => {
                // NOTE: without the occlusion test the late list stays empty.
                let count = if ctx.occlusion.occluding() { 2 } else { 1 };
                for phase in &phases[..count] {
                    pass.set_bind_group(1, phase.instances, &[]);
                    calls += draw(&mut pass, Some(phase));
                }
            }
            None => calls += draw(&mut pass, None),
        }
        if ctx.fragments.is_some() {
            pass.end_pipeline_statistics_query();
        }
        drop(pass);
        ctx.draw_calls += calls;
    }
}
