//! Where the viewer's frames go: a window's swapchain, or (`--offscreen`) a texture made like
//! a swapchain image (a plain 8-bit BGRA format the scene draws through its sRGB view, no
//! storage view) for machines without a display. Both run the same frame loop, inspector and
//! render path; an offscreen frame is only not presented.

use std::path::Path;
use std::sync::Arc;

use image::RgbaImage;
use winit::dpi::PhysicalSize;
use winit::window::Window;

use crate::export::write_color_image;
use crate::render::target::{read_texture, texture_2d_viewed};
use crate::viewer::options::ViewerError;
use crate::viewer::surface::WindowSurface;

/// The format of an offscreen frame: what swapchains most often offer.
pub(crate) const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Bgra8Unorm;

/// A texture standing in for a swapchain image.
pub(crate) struct OffscreenFrame {
    texture: wgpu::Texture,
}

impl OffscreenFrame {
    /// A `width`×`height` frame (each side at least 1).
    pub(crate) fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let texture = texture_2d_viewed(
            device,
            "viewer offscreen frame",
            (width.max(1), height.max(1)),
            OFFSCREEN_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            &[OFFSCREEN_FORMAT.add_srgb_suffix()],
        );
        Self { texture }
    }
}

/// The window and its surface, or an offscreen frame.
pub(crate) enum Presenter {
    /// A window on the screen.
    Window {
        /// The window.
        window: Arc<Window>,
        /// Its swapchain.
        surface: WindowSurface,
        /// egui's input from the window's events (boxed: it is most of the variant).
        egui_state: Box<egui_winit::State>,
    },
    /// No window: frames are drawn into a texture and kept there.
    Offscreen(OffscreenFrame),
}

/// The image one frame draws into.
pub(crate) enum Frame {
    /// A swapchain image, presented after drawing.
    Surface(wgpu::SurfaceTexture),
    /// The offscreen texture.
    Offscreen(wgpu::Texture),
}

impl Frame {
    /// The image's texture.
    pub(crate) fn texture(&self) -> &wgpu::Texture {
        match self {
            Frame::Surface(frame) => &frame.texture,
            Frame::Offscreen(texture) => texture,
        }
    }
}

impl Presenter {
    /// The frame's size in pixels.
    pub(crate) fn size(&self) -> (u32, u32) {
        match self {
            Presenter::Window { surface, .. } => (surface.config.width, surface.config.height),
            Presenter::Offscreen(frame) => (frame.texture.width(), frame.texture.height()),
        }
    }

    /// The frame's (plain, non-sRGB) format.
    pub(crate) fn format(&self) -> wgpu::TextureFormat {
        match self {
            Presenter::Window { surface, .. } => surface.config.format,
            Presenter::Offscreen(_) => OFFSCREEN_FORMAT,
        }
    }

    /// Times the surface was reconfigured after an error (0 offscreen).
    pub(crate) fn recoveries(&self) -> u32 {
        match self {
            Presenter::Window { surface, .. } => surface.recoveries,
            Presenter::Offscreen(_) => 0,
        }
    }

    /// Follows a new size (0 on a side: minimised, nothing drawn until it has one again).
    pub(crate) fn resize(&mut self, device: &wgpu::Device, width: u32, height: u32) {
        match self {
            Presenter::Window { surface, .. } => surface.resize(device, width, height),
            Presenter::Offscreen(frame) => {
                if width > 0 && height > 0 {
                    *frame = OffscreenFrame::new(device, width, height);
                }
            }
        }
    }

    /// The size the window has (or the offscreen frame's).
    pub(crate) fn inner_size(&self) -> PhysicalSize<u32> {
        match self {
            Presenter::Window { window, .. } => window.inner_size(),
            Presenter::Offscreen(_) => {
                let (w, h) = self.size();
                PhysicalSize::new(w, h)
            }
        }
    }

    /// Asks for a new size: the window system answers a window with a resize event (or
    /// ignores it); an offscreen frame is resized at once.
    pub(crate) fn request_size(&mut self, device: &wgpu::Device, width: u32, height: u32) {
        match self {
            Presenter::Window { window, .. } => {
                let _ = window.request_inner_size(PhysicalSize::new(width, height));
            }
            Presenter::Offscreen(_) => self.resize(device, width, height),
        }
    }

    /// egui's input for this frame: the window's events, or just the frame's area.
    pub(crate) fn egui_input(&mut self) -> egui::RawInput {
        match self {
            Presenter::Window { window, egui_state, .. } => egui_state.take_egui_input(window),
            Presenter::Offscreen(frame) => egui::RawInput {
                screen_rect: Some(egui::Rect::from_min_size(
                    egui::Pos2::ZERO,
                    egui::vec2(frame.texture.width() as f32, frame.texture.height() as f32),
                )),
                ..Default::default()
            },
        }
    }

    /// Hands egui's platform output (cursor, clipboard) to the window; nothing offscreen.
    pub(crate) fn platform_output(&mut self, output: egui::PlatformOutput) {
        if let Presenter::Window { window, egui_state, .. } = self {
            egui_state.handle_platform_output(window, output);
        }
    }

    /// The image to draw this frame into, or None when the frame must be skipped (see
    /// [`WindowSurface::acquire`]; `lose` takes the lost-surface path).
    pub(crate) fn acquire(&mut self, device: &wgpu::Device, lose: bool) -> Option<Frame> {
        match self {
            Presenter::Window { surface, .. } => surface.acquire(device, lose).map(Frame::Surface),
            Presenter::Offscreen(frame) => Some(Frame::Offscreen(frame.texture.clone())),
        }
    }

    /// Writes `frame` to `path` as PNG.
    pub(crate) fn save_screenshot(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        frame: &Frame,
        path: &Path,
    ) -> Result<(), ViewerError> {
        match self {
            Presenter::Window { surface, .. } => surface.save_screenshot(device, queue, frame.texture(), path),
            Presenter::Offscreen(_) => {
                let texture = frame.texture();
                let mut pixels = read_texture(device, queue, texture, 4);
                // NOTE: BGRA to RGBA.
                for p in pixels.chunks_exact_mut(4) {
                    p.swap(0, 2);
                }
                let image = RgbaImage::from_raw(texture.width(), texture.height(), pixels)
                    .ok_or_else(|| ViewerError::screenshot(path, "the frame's pixels do not fill its size"))?;
                write_color_image(path, &image).map_err(|e| ViewerError::screenshot(path, e.to_string()))
            }
        }
    }

    /// Shows `frame` (a window's); an offscreen frame stays in its texture.
    pub(crate) fn present(&self, queue: &wgpu::Queue, frame: Frame) {
        if let (Presenter::Window { window, .. }, Frame::Surface(image)) = (self, frame) {
            window.pre_present_notify();
            queue.present(image);
        }
    }

    /// Asks the window for the next frame (offscreen frames are drawn in a loop).
    pub(crate) fn request_redraw(&self) {
        if let Presenter::Window { window, .. } = self {
            window.request_redraw();
        }
    }
}
