//! The renderer: owns the device, the shadow resources, the scene's GPU copy and the render
//! graph, and renders one frame from the ECS data.

use bevy_ecs::resource::Resource;

use crate::layout::ShadowStorage;
use crate::math::pages::pixel_per_depth;
use crate::render::context::{GpuContext, GpuError};
use crate::render::counters::RenderCounters;
use crate::render::depth_bounds::DepthBoundsPass;
use crate::render::draw_args::DrawArgs;
use crate::render::forward_pass::ForwardPass;
use crate::render::fragment_count::FragmentCounter;
use crate::render::frame::FrameContext;
use crate::render::frame_inputs::FrameInputs;
use crate::render::gpu_types::FrameUniformsGpu;
use crate::render::graph::{RenderGraph, RenderNode};
use crate::render::layouts::Layouts;
use crate::render::limits::UploadProblems;
use crate::render::occlusion::{OcclusionGpu, occlusion_wanted};
use crate::render::options::Msaa;
use crate::render::prepass::{DepthPrepass, NORMAL_FORMAT, prepass_runs, visible_triangles};
use crate::render::prepass_keep::PrepassKeep;
use crate::render::probe::ProbePass;
use crate::render::report::FrameReport;
use crate::render::resolve::VisibilityResolve;
use crate::render::scene_gpu::SceneGpu;
use crate::render::seen_readback::SeenReadback;
use crate::render::shadow_cull::ShadowCullGpu;
use crate::render::shadows::ShadowResources;
use crate::render::shadows::cascade_moments_pass::CascadeMomentsPass;
use crate::render::shadows::depth_pass::DepthPass;
use crate::render::shadows::moments_pass::MomentsPass;
use crate::render::shadows::pages_pass::PagesPass;
use crate::render::shadows::visibility::ResolvePlan;
use crate::render::target::{HeadlessTarget, TargetViews};
use crate::render::timer::{FrameTimings, GpuTimer};
use crate::settings::ShadowDebugView;
use crate::shader::{ShaderError, ShaderLibrary};

/// A headless renderer; insert it as a resource next to [`RenderPlugin`](crate::render::RenderPlugin).
#[derive(Resource)]
pub struct Renderer {
    /// The device.
    pub gpu: GpuContext,
    layouts: Layouts,
    library: ShaderLibrary,
    scene: SceneGpu,
    shadows: ShadowResources,
    focus_light: usize,
    timer: GpuTimer,
    frames: u64,
    fragments: Option<FragmentCounter>,
    graph: RenderGraph,
    target: Option<HeadlessTarget>,
    probes: ProbePass,
    counters: RenderCounters,
    pipeline_error: Option<String>,
    problems: UploadProblems,
    /// The MSAA request and colour format last warned about (a fallback is warned once).
    msaa_warned: Option<(Msaa, wgpu::TextureFormat)>,
    /// The depth-bounds reduction's readback ring (the depths the camera saw).
    seen: SeenReadback,
    /// The frame's multi-draw arguments.
    draw_args: DrawArgs,
    /// The camera view's occlusion culling.
    occlusion: OcclusionGpu,
    /// The GPU culling of shadow casters.
    shadow_cull: ShadowCullGpu,
    /// The scrolling views the last frame drew whole from an earlier window's casters.
    scroll_resync: Vec<(bevy_ecs::entity::Entity, u32)>,
    /// The depth prepass kept between frames.
    prepass_keep: PrepassKeep,
    /// The last frame's GPU report.
    pub last_report: FrameReport,
}

impl Renderer {
    /// Opens a headless device and a `width`×`height` target (each side from 1 to the
    /// device's largest texture side, else [`GpuError::Limit`]).
    pub fn headless(width: u32, height: u32) -> Result<Self, GpuError> {
        let gpu = GpuContext::headless()?;
        gpu.limits.check_target(width, height)?;
        Ok(Self::new(gpu, width, height))
    }

    /// Like [`headless`](Self::headless), with analysis targets: every frame also records
    /// the shadow factor, world position and normal of each pixel, read with
    /// [`read_analysis`](Self::read_analysis). Its frames render one sample per pixel
    /// whatever [`RenderOptions::msaa`](crate::render::RenderOptions::msaa) asks.
    pub fn headless_with_analysis(width: u32, height: u32) -> Result<Self, GpuError> {
        let gpu = GpuContext::headless()?;
        gpu.limits.check_target(width, height)?;
        let bytes = gpu.device.limits().max_color_attachment_bytes_per_sample;
        if bytes < 56 {
            return Err(GpuError::Unsupported {
                adapter: gpu.adapter_info.name.clone(),
                what: format!("write analysis targets: 56 colour bytes per sample needed, {bytes} available"),
            });
        }
        let mut renderer = Self::new(gpu, width, height);
        renderer.target = Some(HeadlessTarget::new(&renderer.gpu.device, width, height, true));
        Ok(renderer)
    }

    /// Builds a renderer without an offscreen target, for drawing into a window with
    /// [`render_to`](Self::render_to).
    pub fn for_window(gpu: GpuContext) -> Self {
        let mut renderer = Self::new(gpu, 1, 1);
        renderer.target = None;
        renderer
    }

    /// Builds the renderer on an open device, with a `width`×`height` offscreen target (each
    /// side clamped to 1 ..= the device's largest texture side).
    pub fn new(gpu: GpuContext, width: u32, height: u32) -> Self {
        let max = gpu.limits.max_texture_side.max(1);
        let (width, height) = (width.clamp(1, max), height.clamp(1, max));
        let layouts = Layouts::new(&gpu.device);
        let library = ShaderLibrary::new().expect("the shipped shader modules compose (checked by tests)");
        let scene = SceneGpu::new(&gpu.device, &layouts);
        let shadows = ShadowResources::new(&gpu.device, &layouts, gpu.moments_format);
        let timer = GpuTimer::new(&gpu.queue, gpu.timestamps);
        let mut graph = RenderGraph::default();
        graph.add_node(Box::new(DepthPass::default()));
        graph.add_node(Box::new(MomentsPass::default()));
        graph.add_node(Box::new(CascadeMomentsPass::default()));
        graph.add_node(Box::new(DepthPrepass::default()));
        graph.add_node(Box::new(PagesPass::default()));
        graph.add_node(Box::new(VisibilityResolve::default()));
        graph.add_node(Box::new(ForwardPass::new([0.42, 0.55, 0.75])));
        graph.add_node(Box::new(DepthBoundsPass::default()));
        let target = Some(HeadlessTarget::new(&gpu.device, width, height, false));
        let probes = ProbePass::new(&gpu.device);
        Self {
            gpu,
            layouts,
            library,
            scene,
            shadows,
            focus_light: 0,
            timer,
            frames: 0,
            fragments: None,
            graph,
            target,
            probes,
            counters: RenderCounters::default(),
            pipeline_error: None,
            problems: UploadProblems::default(),
            msaa_warned: None,
            seen: SeenReadback::default(),
            draw_args: DrawArgs::default(),
            occlusion: OcclusionGpu::default(),
            shadow_cull: ShadowCullGpu::default(),
            scroll_resync: Vec::new(),
            prepass_keep: PrepassKeep::default(),
            last_report: FrameReport::default(),
        }
    }

    /// GPU objects created so far (see [`RenderCounters`]).
    pub fn counters(&self) -> RenderCounters {
        self.counters
    }

    /// Side of the layers of `storage` (None until a light of it has cast a shadow).
    pub fn storage_resolution(&self, storage: ShadowStorage) -> Option<u32> {
        let maps = self.shadows.array(storage);
        (!maps.placeholder).then_some(maps.side)
    }

    /// The scrolling views (light entity, clipmap level) the last frame had to draw whole from
    /// a caster list of an earlier window; taken, so the next frame's culling remakes them.
    pub fn take_scroll_resync(&mut self) -> impl Iterator<Item = (bevy_ecs::entity::Entity, u32)> + '_ {
        self.scroll_resync.drain(..)
    }

    /// Chooses the light (an index into the light list: suns, then spots, then points) whose
    /// shadow the analysis targets, the probes and the cascade debug view report. Default 0:
    /// the first sun.
    pub fn set_focus_light(&mut self, light: usize) {
        self.focus_light = light;
    }

    /// Replaces the forward shader with a material's own WGSL; see
    /// [`ShaderLibrary::set_forward_source`]. On error nothing changes. Pipelines are rebuilt
    /// on the next frame; if that build fails (say, the pipeline layout does not match), the
    /// last good pipeline keeps drawing and [`pipeline_error`](Self::pipeline_error) says why.
    pub fn set_forward_shader(&mut self, file: &str, source: &str) -> Result<(), ShaderError> {
        self.library.set_forward_source(file, source)?;
        self.pipeline_error = None;
        Ok(())
    }

    /// Goes back to the shipped forward shader.
    pub fn reset_forward_shader(&mut self) {
        self.library.reset_forward_source();
        self.pipeline_error = None;
    }

    /// The last pipeline build that failed since the shader was last set, if any.
    pub fn pipeline_error(&self) -> Option<&str> {
        self.pipeline_error.as_deref()
    }

    /// Inputs the renderer had to change to fit the device since the last call (an image
    /// downscaled), emptying the list. Each is also logged as a warning.
    pub fn take_warnings(&mut self) -> Vec<String> {
        std::mem::take(&mut self.problems.warnings)
    }

    /// Errors since the last call, emptying the list: inputs too large for the device (the
    /// frame was not drawn), images that could not be used, and any error the device itself
    /// reported. Each is also logged. Empty after a frame that rendered as asked.
    pub fn take_errors(&mut self) -> Vec<String> {
        let mut errors = std::mem::take(&mut self.problems.errors);
        errors.extend(self.gpu.take_errors());
        errors
    }

    /// Size of the render target.
    pub fn size(&self) -> (u32, u32) {
        self.target.as_ref().map_or((0, 0), |t| (t.views.width, t.views.height))
    }

    /// Counts the lighting pass's fragment-shader invocations from the next frame on
    /// ([`FrameReport::forward_fragments`]; each frame then waits for the count) or stops;
    /// returns false when the device cannot count them.
    pub fn count_forward_fragments(&mut self, on: bool) -> bool {
        if !self.gpu.pipeline_statistics {
            return false;
        }
        self.fragments = on.then(|| FragmentCounter::new(&self.gpu.device));
        true
    }

    /// Frames rendered so far; frame `n` is the `n`-th call (from 0) of
    /// [`render`](Self::render) or [`render_to`](Self::render_to).
    pub fn frames_rendered(&self) -> u64 {
        self.frames
    }

    /// The per-pass GPU timings that have arrived since the last call, oldest first, without
    /// waiting (timings of the newest frames may still be in flight).
    pub fn take_timings(&mut self) -> Vec<FrameTimings> {
        self.timer.take_completed(&self.gpu.device)
    }

    /// Waits for the GPU timings of every frame rendered so far and returns those not yet
    /// taken, oldest first (for headless runs that report every frame).
    pub fn wait_for_timings(&mut self) -> Vec<FrameTimings> {
        self.timer.wait(&self.gpu.device)
    }

    /// Frames rendered without timings because every timing slot was still in flight.
    pub fn untimed_frames(&self) -> u64 {
        self.timer.untimed_frames
    }

    /// Names of the graph's nodes the last frame recorded, in execution order.
    pub fn graph_order(&self) -> Vec<&'static str> {
        self.graph.execution_order()
    }

    /// Names of the graph's nodes the last frame culled (nothing read what they write).
    pub fn graph_culled(&self) -> Vec<&'static str> {
        self.graph.culled()
    }

    /// Adds a node to the render graph (after the built-in shadow and forward nodes in
    /// declaration order; it runs where its reads and writes put it). It declares its work
    /// from the next frame on.
    pub fn add_node(&mut self, node: Box<dyn RenderNode>) {
        self.graph.add_node(node);
    }

    /// Renders one frame into the headless target and waits for its GPU timings.
    pub fn render(&mut self, input: &FrameInputs<'_>) -> &FrameReport {
        // NOTE: the target is taken out for the call so `render_to` can borrow `self` whole;
        // it always goes back.
        if let Some(target) = self.target.take() {
            self.render_to(input, &target.views, &mut |_, _| {});
            self.target = Some(target);
        }
        &self.last_report
    }

    /// Renders one frame into `target` (for example a window's swapchain image) and waits for
    /// its GPU timings. `overlay` records extra work (a UI) into the same encoder after the
    /// graph, before submission.
    pub fn render_to(
        &mut self,
        input: &FrameInputs<'_>,
        target: &TargetViews,
        overlay: &mut dyn FnMut(&GpuContext, &mut wgpu::CommandEncoder),
    ) -> &FrameReport {
        let light_count = input.lights.len();
        let frame = match input.view.camera {
            Some((camera, cam)) => FrameUniformsGpu {
                clip_from_world: camera.clip_from_world(),
                view_from_world: camera.view_from_world(),
                world_from_clip: camera.clip_from_world().inverse(),
                camera_position: camera.position(),
                exposure: cam.exposure,
                ambient: input.ambient.color,
                frame_index: input.frame_index,
                light_count: light_count as u32,
                focus_light: self.focus_light.min(light_count) as u32,
                debug_contact: u32::from(
                    input
                        .lights
                        .settings_at(self.focus_light as u32)
                        .is_some_and(|s| s.filter.debug_view == ShadowDebugView::Contact),
                ),
                _padding: 0,
            },
            None => FrameUniformsGpu::default(),
        };
        let mut problems = UploadProblems::default();
        let size = (target.width, target.height);
        let samples = self.frame_samples(input.options.msaa, target, &mut problems);
        // NOTE: decided once, before the upload: the prepass, the lights' resolve layers, the
        // prepass's normals, the resolve node and the forward pass's shadow group must agree.
        // Where the prepass's normals cannot be multisampled, an MSAA frame filters its
        // shadows in the lighting pass.
        let prepass = prepass_runs(input, size);
        if let Some((camera, _)) = input.view.camera {
            self.shadows.page_pixel = pixel_per_depth(camera.clip_from_world(), size.1) as f32;
        }
        let resolve = ResolvePlan::for_frame(
            input,
            size,
            prepass && self.gpu.supports_samples(NORMAL_FORMAT, samples),
        );
        self.shadows.cascade_format = input.options.sun_depth.format();
        let prepared = self
            .scene
            .prepare(&self.gpu, &self.layouts, input, &frame, &mut problems)
            .and_then(|()| {
                self.shadows.prepare(
                    (&self.gpu, &self.layouts, &mut self.library),
                    input.lights,
                    input.shadow_views,
                    resolve,
                    &mut self.counters,
                    &mut problems,
                )
            })
            .and_then(|_| {
                let wanted = prepass && samples == 1 && occlusion_wanted(input) && self.gpu.indirect_first_instance;
                self.occlusion.prepare(
                    (&self.gpu, &self.layouts, &mut self.library),
                    &self.scene,
                    (input.instances, input.view_groups),
                    input.view.camera.as_ref().map(|(c, _)| c),
                    size,
                    wanted,
                )
            })
            .and_then(|()| {
                self.shadow_cull.prepare(
                    (&self.gpu, &self.layouts, &mut self.library),
                    &self.scene,
                    input.instances,
                    input.shadow_views,
                )
            });
        let mut drawable = prepared.is_ok();
        if let Err(e) = prepared {
            problems.errors.push(format!("the frame is not drawn: {e}"));
        }
        // NOTE: the prepass writes normals only where the frame resolves (same condition as
        // the resolve node's).
        let deferred = prepass
            && samples == 1
            && target.analysis.is_none()
            && input.options.deferred_lighting.runs(
                || visible_triangles(input),
                u64::from(size.0) * u64::from(size.1),
                target.storage.is_some(),
            )
            && self.shadows.resolved.is_some()
            && !self.library.forward_replaced()
            && self.scene.untextured.contains(&true);
        match self.build_graph(input, target, (prepass, samples, deferred)) {
            Ok(created) => self.counters.transient_resources += created,
            Err(e) => {
                drawable = false;
                problems.errors.push(format!("the frame is not drawn: {e}"));
            }
        }
        for warning in &problems.warnings {
            log::warn!("{warning}");
        }
        for error in &problems.errors {
            log::error!("{error}");
        }
        self.problems.append(problems);
        // NOTE: one timed pass per shadow view, plus the prepass, the resolve and the forward
        // pass.
        self.timer
            .begin_frame(&self.gpu.device, self.frames, input.timed_passes());
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        self.scroll_resync.clear();
        let skinned_meshes_posed = self.scene.skinning.record(&mut encoder, &mut self.timer);
        // NOTE: the early phase needs no depth: it runs first, prepass or not.
        self.occlusion.record_early(&mut encoder, &mut self.timer);
        let multi_draw = input.options.multi_draw && self.gpu.indirect_first_instance;
        self.draw_args
            .begin(&self.gpu.device, input.expected_draws(), multi_draw);
        let mut ctx = FrameContext {
            gpu: &self.gpu,
            layouts: &self.layouts,
            library: &mut self.library,
            scene: &self.scene,
            shadows: &self.shadows,
            shadow_views: input.shadow_views,
            view_groups: input.view_groups,
            lights: input.lights,
            timer: &mut self.timer,
            fragments: self.fragments.as_ref(),
            draw_calls: 0,
            deferred_lighting: false,
            shadow_views_drawn: 0,
            shadow_draw_calls: 0,
            shadow_cleared_texels: 0,
            shadow_views_scrolled: 0,
            shadow_drawn_texels: 0,
            counters: &mut self.counters,
            pipeline_error: &mut self.pipeline_error,
            seen: &mut self.seen,
            draw_args: &mut self.draw_args,
            occlusion: &mut self.occlusion,
            shadow_cull: &mut self.shadow_cull,
            scroll_resync: &mut self.scroll_resync,
        };
        let drawn = input.view.camera.is_some() && drawable;
        if drawn {
            self.graph.execute(&mut ctx, &mut encoder);
        } else {
            self.graph.skip();
        }
        let (draw_calls, shadow_views_drawn, shadow_draw_calls, shadow_cleared_texels) = (
            ctx.draw_calls,
            ctx.shadow_views_drawn,
            ctx.shadow_draw_calls,
            ctx.shadow_cleared_texels,
        );
        let (shadow_views_scrolled, shadow_drawn_texels) = (ctx.shadow_views_scrolled, ctx.shadow_drawn_texels);
        let deferred_lighting = ctx.deferred_lighting;
        overlay(&self.gpu, &mut encoder);
        self.draw_args.upload(&self.gpu.queue);
        self.timer.resolve(&mut encoder);
        if let Some(counter) = &self.fragments {
            counter.resolve(&mut encoder);
        }
        self.gpu.queue.submit([encoder.finish()]);
        self.timer.submitted();
        self.timer.poll(&self.gpu.device);
        self.seen.after_submit(&self.gpu.device, false);
        self.frames += 1;
        let latest = self.timer.latest();
        let report = &mut self.last_report;
        // NOTE: `clone_from` keeps the pass list's (and names') allocations from frame to frame.
        report.passes.clone_from(&latest.passes);
        report.timed_frame = latest.frame;
        report.draw_calls = draw_calls;
        report.draws = self.draw_args.draws() as u32;
        report.deferred_lighting = deferred_lighting;
        report.shadow_views_drawn = shadow_views_drawn;
        report.shadow_draw_calls = shadow_draw_calls;
        report.shadow_cleared_texels = shadow_cleared_texels;
        report.shadow_views_scrolled = shadow_views_scrolled;
        report.shadow_views_resynced = self.scroll_resync.len() as u32;
        report.shadow_drawn_texels = shadow_drawn_texels;
        report.skinned_meshes_posed = skinned_meshes_posed;
        report.prepass_kept = self.prepass_keep.reused();
        self.prepass_keep.end(drawn && self.pipeline_error.is_none());
        report.shadow_memory = self.shadows.memory_bytes();
        report.resolved_memory = self.shadows.resolved_memory_bytes();
        report.forward_fragments = self.fragments.as_ref().and_then(|c| c.read(&self.gpu.device));
        &self.last_report
    }
}

#[path = "renderer_graph.rs"]
mod graph_build;
#[path = "renderer_readback.rs"]
mod readback;
