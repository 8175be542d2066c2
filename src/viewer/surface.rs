//! The window's swapchain: configuration, resizing (a 0×0 window is "minimised": nothing is
//! configured or drawn until it has a size again), acquiring frames with every surface
//! error handled (outdated or lost: reconfigure and skip the frame; timeout or occluded:
//! skip it), and screenshots.

use std::path::Path;

use image::RgbaImage;

use crate::export::write_color_image;
use crate::render::target::read_texture;
use crate::viewer::options::ViewerError;

/// A configured surface (the render graph provides the depth buffer).
pub(crate) struct WindowSurface {
    pub surface: wgpu::Surface<'static>,
    pub config: wgpu::SurfaceConfiguration,
    /// The window has no area; frames are skipped.
    pub minimised: bool,
    /// Swapchain images can be copied (for screenshots).
    pub can_copy: bool,
    /// Times the surface was reconfigured after an error.
    pub recoveries: u32,
    /// The last image was suboptimal: reconfigure before the next.
    stale: bool,
}

impl WindowSurface {
    /// Configures `surface` for `adapter` at `width`×`height`.
    pub fn new(
        surface: wgpu::Surface<'static>,
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        (width, height): (u32, u32),
    ) -> Self {
        let caps = surface.get_capabilities(adapter);
        // NOTE: the surface uses a plain (non-sRGB) format, as egui expects; the scene is drawn
        // through an sRGB view of the same image, so its linear output is encoded for display.
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb())
            .unwrap_or(caps.formats[0])
            .remove_srgb_suffix();
        let can_copy = caps.usages.contains(wgpu::TextureUsages::COPY_SRC);
        let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        if can_copy {
            usage |= wgpu::TextureUsages::COPY_SRC;
        }
        let max = device.limits().max_texture_dimension_2d.max(1);
        let config = wgpu::SurfaceConfiguration {
            usage,
            format,
            width: width.clamp(1, max),
            height: height.clamp(1, max),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![format.add_srgb_suffix()],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        let s = Self {
            surface,
            config,
            minimised: width == 0 || height == 0,
            can_copy,
            recoveries: 0,
            stale: false,
        };
        if !s.minimised {
            s.surface.configure(device, &s.config);
        }
        s
    }

    /// Follows a window resize; a zero width or height marks the window minimised. A side
    /// larger than the device's largest texture is clamped to it (the image is stretched).
    pub fn resize(&mut self, device: &wgpu::Device, width: u32, height: u32) {
        if width == 0 || height == 0 {
            self.minimised = true;
            return;
        }
        self.minimised = false;
        let max = device.limits().max_texture_dimension_2d.max(1);
        let (width, height) = (width.min(max), height.min(max));
        if (width, height) != (self.config.width, self.config.height) {
            self.config.width = width;
            self.config.height = height;
        }
        self.surface.configure(device, &self.config);
        self.stale = false;
    }

    /// The next swapchain image, or None when this frame must be skipped (minimised, or the
    /// surface was outdated, lost, timed out or occluded). `lose` takes the lost path as if
    /// the surface had reported it.
    pub fn acquire(&mut self, device: &wgpu::Device, lose: bool) -> Option<wgpu::SurfaceTexture> {
        if self.minimised {
            return None;
        }
        if self.stale || lose {
            self.recover(device);
            if lose {
                return None;
            }
        }
        match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(frame) => Some(frame),
            wgpu::CurrentSurfaceTexture::Suboptimal(frame) => {
                // Present this one; reconfigure before the next.
                self.stale = true;
                Some(frame)
            }
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.recover(device);
                None
            }
            other => {
                log::warn!("skipping a frame: the surface returned {other:?}");
                None
            }
        }
    }

    fn recover(&mut self, device: &wgpu::Device) {
        self.recoveries += 1;
        self.stale = false;
        self.surface.configure(device, &self.config);
    }

    /// Copies a swapchain image to the CPU and writes it to `path` as PNG.
    pub fn save_screenshot(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        texture: &wgpu::Texture,
        path: &Path,
    ) -> Result<(), ViewerError> {
        let image = self
            .screenshot(device, queue, texture)
            .ok_or_else(|| ViewerError::screenshot(path, "this surface cannot be copied"))?;
        write_color_image(path, &image).map_err(|e| ViewerError::screenshot(path, e.to_string()))
    }

    /// Copies a swapchain image to the CPU as RGBA (None when the surface cannot be copied).
    pub fn screenshot(&self, device: &wgpu::Device, queue: &wgpu::Queue, texture: &wgpu::Texture) -> Option<RgbaImage> {
        if !self.can_copy {
            return None;
        }
        let mut pixels = read_texture(device, queue, texture, 4);
        if matches!(
            self.config.format,
            wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
        ) {
            for p in pixels.chunks_exact_mut(4) {
                p.swap(0, 2);
            }
        }
        RgbaImage::from_raw(texture.width(), texture.height(), pixels)
    }
}
