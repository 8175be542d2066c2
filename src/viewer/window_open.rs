//! Opening the viewer's window: the winit window, its surface and GPU device, the renderer
//! that draws into it and egui's state and renderer; or, offscreen, a headless device and a
//! frame made like a swapchain image.

use std::sync::Arc;

use winit::dpi::PhysicalSize;
use winit::event_loop::ActiveEventLoop;
use winit::window::Window;

use super::{Viewer, WindowState};
use crate::render::{GpuContext, GpuError, Renderer};
use crate::viewer::options::ViewerError;
use crate::viewer::presenter::{OFFSCREEN_FORMAT, OffscreenFrame, Presenter};
use crate::viewer::surface::WindowSurface;

impl Viewer {
    /// Opens the window and everything that draws into it.
    pub(super) fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<WindowState, ViewerError> {
        let attributes = Window::default_attributes()
            .with_title(format!("penumbra — {}", self.reload.scene_path().display()))
            .with_inner_size(PhysicalSize::new(self.options.width, self.options.height));
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
        let surface = WindowSurface::new(surface, &gpu.adapter, &gpu.device, (size.width, size.height));
        let egui_ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &*window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        let egui_renderer = egui_wgpu::Renderer::new(
            &gpu.device,
            surface.config.format,
            egui_wgpu::RendererOptions::default(),
        );
        self.summary.adapter = gpu.describe();
        Ok(WindowState {
            presenter: Presenter::Window {
                window,
                surface,
                egui_state: Box::new(egui_state),
            },
            renderer: Renderer::for_window(gpu),
            egui_ctx,
            egui_renderer,
        })
    }

    /// Opens a headless device and an offscreen frame of the options' size.
    pub(super) fn open_offscreen(&mut self) -> Result<WindowState, ViewerError> {
        let gpu = GpuContext::headless()?;
        gpu.limits
            .check_target(self.options.width, self.options.height)
            .map_err(GpuError::from)?;
        let frame = OffscreenFrame::new(&gpu.device, self.options.width, self.options.height);
        let egui_renderer =
            egui_wgpu::Renderer::new(&gpu.device, OFFSCREEN_FORMAT, egui_wgpu::RendererOptions::default());
        self.summary.adapter = gpu.describe();
        Ok(WindowState {
            presenter: Presenter::Offscreen(frame),
            renderer: Renderer::for_window(gpu),
            egui_ctx: egui::Context::default(),
            egui_renderer,
        })
    }
}
