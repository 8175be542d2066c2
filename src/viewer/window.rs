//! The window loop: winit events, the surface, and drawing the scene plus the egui inspector
//! into each swapchain image.

use std::sync::Arc;
use std::time::Instant;

use bevy_app::App;
use thiserror::Error;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

use crate::app::{SpawnError, spawn_scene};
use crate::ecs::components::{Camera3d, Transform, ViewportSize};
use crate::ecs::plugin::ShadowPlugin;
use crate::render::frame::FrameInputs;
use crate::render::target::{TargetViews, texture_2d};
use crate::render::{GpuContext, GpuError, Renderer};
use crate::scene::SceneDesc;
use crate::viewer::fly_camera::{FlyCamera, MoveKeys};
use crate::viewer::inspector;

/// Why the viewer stopped with an error.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ViewerError {
    /// The window system is not available.
    #[error("cannot open a window: {0}")]
    Window(String),
    /// No GPU.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// The scene could not be spawned.
    #[error(transparent)]
    Spawn(#[from] SpawnError),
}

/// Viewer options.
#[derive(Clone, Copy, Debug)]
pub struct ViewerOptions {
    /// Initial window width.
    pub width: u32,
    /// Initial window height.
    pub height: u32,
    /// Close after this many frames (for scripted runs).
    pub exit_after: Option<u32>,
}

/// Window, surface and the renderers that draw into it.
struct WindowState {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    depth: TargetViews,
    renderer: Renderer,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
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
    frames: u32,
    error: Option<ViewerError>,
}

/// Opens a window on `desc` and runs until it is closed.
pub fn run(desc: &SceneDesc, options: ViewerOptions) -> Result<(), ViewerError> {
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    spawn_scene(app.world_mut(), desc)?;
    let camera = FlyCamera::looking_at(desc.camera.position, desc.camera.target);
    let event_loop = EventLoop::new().map_err(|e| ViewerError::Window(e.to_string()))?;
    let mut viewer = Viewer {
        app,
        options,
        window: None,
        camera,
        keys: MoveKeys::default(),
        dragging: false,
        cursor: None,
        last_frame: Instant::now(),
        frames: 0,
        error: None,
    };
    event_loop
        .run_app(&mut viewer)
        .map_err(|e| ViewerError::Window(e.to_string()))?;
    viewer.error.map_or(Ok(()), Err)
}

impl Viewer {
    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<WindowState, ViewerError> {
        let attributes = Window::default_attributes()
            .with_title("penumbra")
            .with_inner_size(winit::dpi::PhysicalSize::new(self.options.width, self.options.height));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(|e| ViewerError::Window(e.to_string()))?,
        );
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| ViewerError::Window(e.to_string()))?;
        let gpu = GpuContext::for_surface(instance, &surface)?;
        let size = window.inner_size();
        let caps = surface.get_capabilities(&gpu.adapter);
        // NOTE: the surface uses a plain (non-sRGB) format, as egui expects; the scene is drawn
        // through an sRGB view of the same image, so its linear output is encoded for display.
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb())
            .unwrap_or(caps.formats[0])
            .remove_srgb_suffix();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![format.add_srgb_suffix()],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&gpu.device, &config);
        let depth = depth_target(&gpu.device, &config);
        let egui_ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &*window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        let egui_renderer = egui_wgpu::Renderer::new(&gpu.device, format, egui_wgpu::RendererOptions::default());
        let renderer = Renderer::for_window(gpu);
        Ok(WindowState {
            window,
            surface,
            config,
            depth,
            renderer,
            egui_ctx,
            egui_state,
            egui_renderer,
        })
    }

    fn resize(&mut self, width: u32, height: u32) {
        let Some(state) = &mut self.window else { return };
        state.config.width = width.max(1);
        state.config.height = height.max(1);
        state.surface.configure(&state.renderer.gpu.device, &state.config);
        state.depth = depth_target(&state.renderer.gpu.device, &state.config);
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

    /// Updates the ECS, builds the UI and draws both into the next swapchain image.
    fn frame(&mut self) {
        let now = Instant::now();
        let dt = (now - self.last_frame).as_secs_f32();
        self.last_frame = now;
        self.camera.advance(self.keys, dt);
        let Some(state) = &mut self.window else { return };
        let world = self.app.world_mut();
        world.insert_resource(ViewportSize {
            width: state.config.width,
            height: state.config.height,
        });
        let mut cameras = world.query::<(&Camera3d, &mut Transform)>();
        for (_, mut t) in cameras.iter_mut(world) {
            *t = self.camera.transform();
        }
        self.app.update();

        let report = state.renderer.last_report.clone();
        let raw = state.egui_state.take_egui_input(&state.window);
        let world = self.app.world_mut();
        let output = state.egui_ctx.run_ui(raw, |ui| {
            egui::Panel::left("inspector").show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| inspector::inspector_ui(ui, world, &report));
            });
        });
        state
            .egui_state
            .handle_platform_output(&state.window, output.platform_output);
        let jobs = state.egui_ctx.tessellate(output.shapes, output.pixels_per_point);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [state.config.width, state.config.height],
            pixels_per_point: output.pixels_per_point,
        };

        // Textures are updated (and freed) before the frame is acquired, so no delta is ever
        // dropped unapplied, even when the swapchain image is not available.
        let mut textures = output.textures_delta;
        for (id, deltas) in &textures.set {
            for delta in deltas {
                state
                    .egui_renderer
                    .update_texture(&state.renderer.gpu.device, &state.renderer.gpu.queue, *id, delta);
            }
        }
        for id in &textures.free {
            state.egui_renderer.free_texture(id);
        }
        textures.clear();

        let frame = match state.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f) | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                state.surface.configure(&state.renderer.gpu.device, &state.config);
                return;
            }
            _ => return,
        };
        let scene_format = state.config.format.add_srgb_suffix();
        let view = frame.texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(scene_format),
            ..Default::default()
        });
        let target = TargetViews {
            color: view,
            format: scene_format,
            depth: state.depth.depth.clone(),
            analysis: None,
            width: state.config.width,
            height: state.config.height,
        };
        let egui_renderer = &mut state.egui_renderer;
        let egui_view = frame.texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(state.config.format),
            ..Default::default()
        });
        state.renderer.render_to(
            &FrameInputs::from_world(self.app.world(), self.frames),
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
        state.window.pre_present_notify();
        state.renderer.gpu.queue.present(frame);
        self.frames += 1;
    }
}

fn depth_target(device: &wgpu::Device, config: &wgpu::SurfaceConfiguration) -> TargetViews {
    let format = config.format.add_srgb_suffix();
    // Only the depth view is used; the colour view is replaced by each swapchain image.
    let placeholder = texture_2d(
        device,
        "unused colour",
        (1, 1),
        format,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    )
    .create_view(&wgpu::TextureViewDescriptor::default());
    TargetViews::for_color(device, placeholder, format, config.width, config.height)
}

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        match self.open(event_loop) {
            Ok(state) => {
                state.window.request_redraw();
                self.window = Some(state);
            }
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if let Some(state) = &mut self.window {
            let response = state.egui_state.on_window_event(&state.window, &event);
            if response.consumed {
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
                if self.options.exit_after.is_some_and(|n| self.frames >= n) {
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(state) = &self.window {
            state.window.request_redraw();
        }
    }
}
