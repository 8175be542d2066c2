//! The window loop: winit events, the ECS app (the same [`ShadowPlugin`] and renderer as the
//! CLI), live reload of the scene, settings and shader files, the fly camera, and drawing the
//! scene plus the egui inspector into each swapchain image — or, offscreen, the same frames in
//! a loop into a texture made like one ([`Presenter`]).

use std::path::{Path, PathBuf};
use std::time::Instant;

use bevy_app::App;
use bevy_transform::components::Transform;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::WindowId;

use crate::app::PreparedScene;
use crate::ecs::components::{Camera3d, ViewportSize};
use crate::ecs::plugin::ShadowPlugin;
use crate::ecs::shadow_memory::ShadowMemoryBudget;
use crate::ecs::stats::ShadowStats;
use crate::export::{OutputKind, prepare_output};
use crate::render::frame_inputs::FrameInputs;
use crate::render::plugin::publish_seen_depths;
use crate::render::target::TargetViews;
use crate::render::{RenderOptions, Renderer};
use crate::scene::{SceneDesc, load_settings};
use crate::settings::{ShadowMode, ShadowSettings};
use crate::viewer::exercise::{EXERCISE_TICKS, ExerciseStep, exercise_step};
use crate::viewer::fly_camera::{FlyCamera, MoveKeys};
use crate::viewer::inspector::{FrameInfo, Inspector};
use crate::viewer::options::{ViewerError, ViewerOptions, ViewerSummary};
use crate::viewer::presenter::Presenter;
use crate::viewer::reload::{FileWatch, LiveReload, ReloadOutcome, set_sun_settings};

/// Where frames go and the renderers that draw them.
struct WindowState {
    presenter: Presenter,
    renderer: Renderer,
    egui_ctx: egui::Context,
    egui_renderer: egui_wgpu::Renderer,
}

struct Viewer {
    app: App,
    options: ViewerOptions,
    window: Option<WindowState>,
    camera: FlyCamera,
    keys: MoveKeys,
    dragging: bool,
    cursor: Option<(f64, f64)>,
    last_frame: Instant,
    reload: LiveReload,
    shader: Option<FileWatch>,
    shader_error: Option<String>,
    /// The renderer's last errors (inputs beyond the device's limits, device errors), shown
    /// until a frame brings new ones.
    render_errors: Vec<String>,
    inspector: Inspector,
    start_settings: Option<ShadowSettings>,
    restore_size: Option<PhysicalSize<u32>>,
    lose_surface: bool,
    summary: ViewerSummary,
    error: Option<ViewerError>,
}

/// The settings file used when none is given: next to the scene, `<scene>.settings.ron`.
pub fn default_settings_path(scene: &Path) -> PathBuf {
    scene.with_extension("settings.ron")
}

/// Opens a window on the scene file at `scene_path` and runs until it is closed (or the
/// scripted frame count is reached).
pub fn run(scene_path: &Path, options: ViewerOptions) -> Result<ViewerSummary, ViewerError> {
    if let Some(path) = &options.screenshot {
        // NOTE: checked before the window opens, not after the last frame.
        prepare_output(path, OutputKind::ColorImage).map_err(|e| ViewerError::screenshot(path, e.to_string()))?;
    }
    let desc = SceneDesc::load(scene_path)?;
    let settings_path = options
        .settings
        .clone()
        .unwrap_or_else(|| default_settings_path(scene_path));
    let watched_settings = (options.settings.is_some() || settings_path.exists()).then_some(settings_path.as_path());
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    app.insert_resource(ViewportSize {
        width: options.width.max(1),
        height: options.height.max(1),
    });
    app.insert_resource(RenderOptions {
        msaa: options.msaa,
        ..RenderOptions::default()
    });
    PreparedScene::new(&desc)?.spawn(app.world_mut());
    if let Some(path) = watched_settings {
        set_sun_settings(app.world_mut(), load_settings(path)?);
    }
    let camera = FlyCamera::looking_at(desc.camera.position, desc.camera.target);
    let reload = LiveReload::new(scene_path, desc, watched_settings);
    let mut viewer = Viewer {
        app,
        window: None,
        camera,
        keys: MoveKeys::default(),
        dragging: false,
        cursor: None,
        last_frame: Instant::now(),
        reload,
        shader: options.shader.as_deref().map(FileWatch::unread),
        shader_error: None,
        render_errors: Vec::new(),
        inspector: Inspector::new(settings_path),
        start_settings: None,
        restore_size: None,
        lose_surface: false,
        summary: ViewerSummary::default(),
        error: None,
        options,
    };
    if viewer.options.offscreen {
        viewer.run_offscreen()?;
    } else {
        let event_loop = EventLoop::new().map_err(|e| ViewerError::Window(e.to_string()))?;
        event_loop
            .run_app(&mut viewer)
            .map_err(|e| ViewerError::Window(e.to_string()))?;
    }
    match viewer.error {
        Some(e) => Err(e),
        None => Ok(viewer.summary),
    }
}

#[path = "window_offscreen.rs"]
mod offscreen;
#[path = "window_open.rs"]
mod open;

impl Viewer {
    fn resize(&mut self, width: u32, height: u32) {
        let Some(state) = &mut self.window else { return };
        state.presenter.resize(&state.renderer.gpu.device, width, height);
    }

    /// Takes `state` as where frames go, with the device's shadow-memory budget unless the
    /// application set one.
    pub(super) fn adopt(&mut self, state: WindowState) {
        state.presenter.request_redraw();
        let world = self.app.world_mut();
        if *world.resource::<ShadowMemoryBudget>() == ShadowMemoryBudget::default() {
            world.insert_resource(state.renderer.gpu.shadow_memory_budget());
        }
        self.window = Some(state);
    }

    fn key(&mut self, code: KeyCode, pressed: bool) {
        let k = &mut self.keys;
        match code {
            KeyCode::KeyW => k.forward = pressed,
            KeyCode::KeyS => k.back = pressed,
            KeyCode::KeyA => k.left = pressed,
            KeyCode::KeyD => k.right = pressed,
            KeyCode::KeyE => k.up = pressed,
            KeyCode::KeyQ => k.down = pressed,
            KeyCode::ShiftLeft | KeyCode::ShiftRight => k.fast = pressed,
            _ => {}
        }
    }

    /// Applies one step of the `--exercise` script.
    fn exercise(&mut self, step: ExerciseStep) {
        log::info!("exercise: {step:?}");
        match step {
            ExerciseStep::Resize(w, h) => {
                if let Some(state) = &mut self.window {
                    state.presenter.request_size(&state.renderer.gpu.device, w, h);
                }
            }
            ExerciseStep::Minimise => {
                self.restore_size = self.window.as_ref().map(|s| s.presenter.inner_size());
                self.resize(0, 0);
            }
            ExerciseStep::Restore => {
                if let Some(size) = self.restore_size.take() {
                    self.resize(size.width, size.height);
                }
            }
            ExerciseStep::LoseSurface => self.lose_surface = true,
            ExerciseStep::ChangeSettings => {
                let world = self.app.world_mut();
                let mut q = world.query::<&mut ShadowSettings>();
                for mut s in q.iter_mut(world) {
                    self.start_settings.get_or_insert(*s);
                    s.filter.mode = ShadowMode::Pcss;
                    s.map.cascades.count = 2;
                    s.map.resolution = 1024;
                }
            }
            ExerciseStep::ResetSettings => {
                if let Some(settings) = self.start_settings.take() {
                    set_sun_settings(self.app.world_mut(), settings);
                }
            }
        }
    }

    /// Picks up edits of the scene, settings and shader files.
    fn poll_files(&mut self) {
        if let ReloadOutcome::Applied {
            camera_changed: true, ..
        } = self.reload.poll(self.app.world_mut())
        {
            let c = self.reload.current().camera;
            self.camera = FlyCamera {
                speed: self.camera.speed,
                ..FlyCamera::looking_at(c.position, c.target)
            };
        }
        let (Some(watch), Some(state)) = (&mut self.shader, &mut self.window) else {
            return;
        };
        if !watch.changed() {
            return;
        }
        let name = watch.path.display().to_string();
        self.shader_error = match std::fs::read_to_string(&watch.path) {
            Err(e) => Some(format!("{name}: cannot read: {e}")),
            Ok(source) => state
                .renderer
                .set_forward_shader(&name, &source)
                .err()
                .map(|e| e.to_string()),
        };
        if let Some(e) = &self.shader_error {
            log::error!("{e}; keeping the last good shader");
        }
    }

    /// Updates the ECS, builds the UI and draws both into the next swapchain image.
    fn frame(&mut self) {
        self.summary.ticks += 1;
        if self.options.exercise
            && let Some(step) = exercise_step(self.summary.ticks)
        {
            self.exercise(step);
        }
        self.poll_files();
        let now = Instant::now();
        let dt = (now - self.last_frame).as_secs_f32();
        self.last_frame = now;
        self.camera.advance(self.keys, dt);
        if let Some(metres) = self.options.walk {
            self.camera.walk(metres);
        }
        let Some(state) = &mut self.window else { return };
        let world = self.app.world_mut();
        let (width, height) = state.presenter.size();
        world.insert_resource(ViewportSize { width, height });
        let mut cameras = world.query::<(&Camera3d, &mut Transform)>();
        for (_, mut t) in cameras.iter_mut(world) {
            *t = self.camera.transform();
        }
        self.app.update();

        // NOTE: the error list is kept in the summary and refilled in place, so a frame
        // without errors allocates nothing here.
        let errors = &mut self.summary.errors;
        errors.clear();
        errors.extend(self.reload.error.iter().chain(&self.shader_error).cloned());
        errors.extend(state.renderer.pipeline_error().map(str::to_owned));
        errors.extend(self.render_errors.iter().cloned());
        let raw = state.presenter.egui_input();
        let world = self.app.world_mut();
        let inspector = &mut self.inspector;
        let camera = &mut self.camera;
        let info = FrameInfo {
            report: Some(&state.renderer.last_report),
            errors: &self.summary.errors,
        };
        let output = state.egui_ctx.run_ui(raw, |ui| {
            egui::Panel::left("inspector").show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| inspector.ui(ui, world, &info, Some(camera)));
            });
        });
        state.presenter.platform_output(output.platform_output);
        let jobs = state.egui_ctx.tessellate(output.shapes, output.pixels_per_point);

        // Textures are updated (and freed) before the frame is acquired, so no delta is ever
        // dropped unapplied, even when the frame is skipped.
        let gpu = &state.renderer.gpu;
        let mut textures = output.textures_delta;
        for (id, deltas) in &textures.set {
            for delta in deltas {
                state.egui_renderer.update_texture(&gpu.device, &gpu.queue, *id, delta);
            }
        }
        for id in &textures.free {
            state.egui_renderer.free_texture(id);
        }
        textures.clear();

        let lose = std::mem::take(&mut self.lose_surface);
        let Some(frame) = state.presenter.acquire(&gpu.device, lose) else {
            self.summary.surface_recoveries = state.presenter.recoveries();
            return;
        };
        let (width, height) = state.presenter.size();
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [width, height],
            pixels_per_point: output.pixels_per_point,
        };
        let format = state.presenter.format();
        let scene_format = format.add_srgb_suffix();
        let view = frame.texture().create_view(&wgpu::TextureViewDescriptor {
            format: Some(scene_format),
            ..Default::default()
        });
        let target = TargetViews {
            color: view,
            format: scene_format,
            storage: None,
            analysis: None,
            width,
            height,
        };
        let egui_view = frame.texture().create_view(&wgpu::TextureViewDescriptor {
            format: Some(format),
            ..Default::default()
        });
        let egui_renderer = &mut state.egui_renderer;
        state.renderer.render_to(
            &FrameInputs::from_world(self.app.world(), self.summary.frames),
            &target,
            &mut |gpu, encoder| {
                egui_renderer.update_buffers(&gpu.device, &gpu.queue, encoder, &jobs, &screen);
                let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("egui"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &egui_view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                egui_renderer.render(&mut pass.forget_lifetime(), &jobs, &screen);
            },
        );
        publish_seen_depths(self.app.world_mut(), &state.renderer);
        // NOTE: a paged sun's counters are read back at once (a stall, for the inspector).
        state.renderer.last_report.pages = state.renderer.read_page_stats();
        self.inspector
            .record(&state.renderer.last_report, self.app.world().resource::<ShadowStats>());
        // NOTE: kept for scripted runs only: an open window would grow the list forever.
        if self.options.exit_after.is_some() {
            let gpu_ms = state.renderer.last_report.passes.iter().fold(0.0, |ms, p| ms + p.ms);
            self.summary.gpu_ms.push(gpu_ms as f32);
        }
        // NOTE: warnings are already logged by the renderer; errors stay on screen.
        state.renderer.take_warnings();
        let render_errors = state.renderer.take_errors();
        if !render_errors.is_empty() {
            self.render_errors = render_errors;
        }
        self.summary.frames += 1;
        self.summary.surface_recoveries = state.presenter.recoveries();
        let finished = self.finished();
        let Some(state) = &mut self.window else { return };
        let gpu = &state.renderer.gpu;
        if finished && let Some(path) = self.options.screenshot.clone() {
            match state.presenter.save_screenshot(&gpu.device, &gpu.queue, &frame, &path) {
                Ok(()) => self.summary.screenshot = Some(path),
                Err(e) => self.error = Some(e),
            }
        }
        state.presenter.present(&gpu.queue, frame);
    }

    /// True once the scripted frame count (and the exercise script) is done.
    fn finished(&self) -> bool {
        let script_done = !self.options.exercise || self.summary.ticks >= EXERCISE_TICKS;
        self.options.exit_after.is_some_and(|n| self.summary.frames >= n) && script_done
    }
}

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        match self.open(event_loop) {
            Ok(state) => self.adopt(state),
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if let Some(WindowState {
            presenter: Presenter::Window { window, egui_state, .. },
            ..
        }) = &mut self.window
        {
            let response = egui_state.on_window_event(window, &event);
            // NOTE: egui sees every event, but only input it used is withheld from the camera;
            // resizes and redraws always reach the viewer.
            let input = matches!(
                event,
                WindowEvent::KeyboardInput { .. }
                    | WindowEvent::MouseInput { .. }
                    | WindowEvent::MouseWheel { .. }
                    | WindowEvent::CursorMoved { .. }
            );
            if response.consumed && input {
                return;
            }
        }
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => self.resize(size.width, size.height),
            WindowEvent::KeyboardInput { event, .. } => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    if code == KeyCode::Escape {
                        event_loop.exit();
                    }
                    self.key(code, event.state == ElementState::Pressed);
                }
            }
            WindowEvent::MouseInput {
                button: MouseButton::Right,
                state,
                ..
            } => {
                self.dragging = state == ElementState::Pressed;
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.camera.scroll_speed(steps);
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let Some((x, y)) = self.cursor
                    && self.dragging
                {
                    self.camera.drag((position.x - x) as f32, (position.y - y) as f32);
                }
                self.cursor = Some((position.x, position.y));
            }
            WindowEvent::RedrawRequested => {
                self.frame();
                if self.finished() || self.error.is_some() {
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(state) = &self.window {
            state.presenter.request_redraw();
        }
    }
}
