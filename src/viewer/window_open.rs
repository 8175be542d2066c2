//! Opening the viewer's window: the winit window, its surface and GPU device, the renderer
//! that draws into it and egui's state and renderer.

use std::sync::Arc;

use winit::dpi::PhysicalSize;
use winit::event_loop::ActiveEventLoop;
use winit::window::Window;

use super::{Viewer, WindowState};
use crate::render::{GpuContext, Renderer};
use crate::viewer::options::ViewerError;
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
            window,
            surface,
            renderer: Renderer::for_window(gpu),
            egui_ctx,
            egui_state,
            egui_renderer,
        })
    }
}
