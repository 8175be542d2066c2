//! The wgpu device: found for a window surface or for headless rendering, with the optional
//! features penumbra uses (timestamp queries, unclipped depth, multiview, filterable 32-bit floats,
//! the adapter's own texture-format capabilities such as 2× MSAA) turned on where the adapter
//! has them.

use std::sync::{Arc, Mutex};

use thiserror::Error;

use crate::ecs::shadow_memory::{GPU_BUDGET, SHARED_BUDGET, SOFTWARE_BUDGET, ShadowMemoryBudget};
use crate::math::shadow_memory::{DEFAULT_SUN_DEPTH_TEXEL_BYTES, MemoryCosts};
use crate::render::limits::{DeviceLimits, LimitError, requested_limits};
use crate::render::shadows::sun_moments::MomentSupport;

/// Why no GPU device could be opened, or why the device refused the work.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum GpuError {
    /// No adapter (GPU or software rasteriser) was found.
    #[error(
        "no GPU adapter found ({0}).\n\
         penumbra needs Vulkan, Metal or DirectX 12. On a Linux machine without a GPU, install \
         Mesa's software Vulkan driver (lavapipe):\n    sudo apt-get install -y mesa-vulkan-drivers\n\
         then run the command again."
    )]
    NoAdapter(String),
    /// The device lacks a capability a feature needs.
    #[error("the GPU adapter `{adapter}` cannot {what}")]
    Unsupported {
        /// Adapter name.
        adapter: String,
        /// What it cannot do.
        what: String,
    },
    /// The adapter refused to open a device.
    #[error("the GPU adapter `{adapter}` could not open a device: {message}")]
    Device {
        /// Adapter name.
        adapter: String,
        /// wgpu's reason.
        message: String,
    },
    /// A size derived from the input is beyond what the device allows.
    #[error(transparent)]
    Limit(#[from] LimitError),
    /// The device reported an error for work it was given (a validation error that no check
    /// before it caught); the frame's output is not to be trusted.
    #[error("the GPU reported an error: {0}")]
    Validation(String),
}

/// Most device errors kept between two reads of [`GpuContext::take_errors`]; later ones are
/// counted, not kept.
const MAX_KEPT_ERRORS: usize = 8;

/// Device errors reported outside any error scope, collected instead of panicking (wgpu's
/// default handler panics).
#[derive(Debug, Default)]
struct ErrorSink {
    kept: Vec<String>,
    dropped: usize,
}

/// An open device and what it can do.
pub struct GpuContext {
    /// The wgpu instance.
    pub instance: wgpu::Instance,
    /// The adapter the device was opened on.
    pub adapter: wgpu::Adapter,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// Adapter name, driver and backend, for reports.
    pub adapter_info: wgpu::AdapterInfo,
    /// Timestamp queries are available at pass boundaries.
    pub timestamps: bool,
    /// Depth can be left unclipped (casters in front of the near plane are clamped to it).
    pub unclipped_depth: bool,
    /// Vertex stages may write clip distances (the paged clipmap's caster confines each page
    /// to its tile with them).
    pub clip_distances: bool,
    /// Indirect draws may start past instance 0 (the paged clipmap's casters are then drawn
    /// with one multi-draw, each draw's instances starting at its own list).
    pub indirect_first_instance: bool,
    /// Pipeline-statistics queries are available (fragment invocations can be counted).
    pub pipeline_statistics: bool,
    /// Most views one multiview pass may render (0: no `MULTIVIEW`, cascades are drawn one
    /// pass each).
    pub multiview_views: u32,
    /// Format of variance shadow maps' covered moments `(o·z, o·z², o)`: `Rgba32Float`
    /// where 32-bit floats can be filtered (`FLOAT32_FILTERABLE`), else `Rgba16Float`, whose
    /// 11-bit mantissa makes the variance `E[z²] − E[z]²` coarse (raise `vsm_min_variance`
    /// there).
    pub moments_format: wgpu::TextureFormat,
    /// 16-bit unorm textures can be sampled and written (`TEXTURE_FORMAT_16BIT_NORM`): 16-bit
    /// MSM moments are stored in `Rgba16Unorm`, whose uniform steps the optimised
    /// quantisation was designed for (else `Rgba16Float`).
    pub unorm16_moments: bool,
    /// The limits user data is checked against.
    pub limits: DeviceLimits,
    errors: Arc<Mutex<ErrorSink>>,
}

impl GpuContext {
    /// Opens a device for offscreen rendering.
    pub fn headless() -> Result<Self, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        pollster::block_on(Self::open(instance, None))
    }

    /// Opens a device that can present to `surface`, created from `instance`.
    pub fn for_surface(instance: wgpu::Instance, surface: &wgpu::Surface<'_>) -> Result<Self, GpuError> {
        pollster::block_on(Self::open(instance, Some(surface)))
    }

    async fn open(instance: wgpu::Instance, surface: Option<&wgpu::Surface<'_>>) -> Result<Self, GpuError> {
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter: false,
                compatible_surface: surface,
                ..Default::default()
            })
            .await
            .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
        let adapter_info = adapter.get_info();
        let available = adapter.features();
        let wanted = wgpu::Features::TIMESTAMP_QUERY
            | wgpu::Features::DEPTH_CLIP_CONTROL
            | wgpu::Features::PIPELINE_STATISTICS_QUERY
            | wgpu::Features::MULTIVIEW
            | wgpu::Features::FLOAT32_FILTERABLE
            | wgpu::Features::TEXTURE_FORMAT_16BIT_NORM
            | wgpu::Features::CLIP_DISTANCES
            | wgpu::Features::INDIRECT_FIRST_INSTANCE
            // NOTE: without it only WebGPU's guaranteed sample counts (1 and 4, and not for
            // every format) may be used.
            | wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES;
        let required_features = available & wanted;
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("penumbra"),
                required_features,
                required_limits: requested_limits(&adapter.limits()),
                ..Default::default()
            })
            .await
            .map_err(|e| GpuError::Device {
                adapter: adapter_info.name.clone(),
                message: e.to_string(),
            })?;
        let errors = Arc::new(Mutex::new(ErrorSink::default()));
        let sink = Arc::clone(&errors);
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            log::error!("GPU error: {error}");
            // NOTE: a poisoned lock only means another thread panicked while pushing; the
            // list is still usable.
            let mut sink = sink.lock().unwrap_or_else(|p| p.into_inner());
            if sink.kept.len() < MAX_KEPT_ERRORS {
                sink.kept.push(error.to_string());
            } else {
                sink.dropped += 1;
            }
        }));
        let multiview_views = if required_features.contains(wgpu::Features::MULTIVIEW) {
            device.limits().max_multiview_view_count
        } else {
            0
        };
        Ok(Self {
            limits: DeviceLimits::of(&device),
            errors,
            instance,
            adapter,
            device,
            queue,
            timestamps: required_features.contains(wgpu::Features::TIMESTAMP_QUERY),
            unclipped_depth: required_features.contains(wgpu::Features::DEPTH_CLIP_CONTROL),
            clip_distances: required_features.contains(wgpu::Features::CLIP_DISTANCES),
            indirect_first_instance: required_features.contains(wgpu::Features::INDIRECT_FIRST_INSTANCE),
            pipeline_statistics: required_features.contains(wgpu::Features::PIPELINE_STATISTICS_QUERY),
            multiview_views,
            unorm16_moments: required_features.contains(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM),
            moments_format: if required_features.contains(wgpu::Features::FLOAT32_FILTERABLE) {
                wgpu::TextureFormat::Rgba32Float
            } else {
                wgpu::TextureFormat::Rgba16Float
            },
            adapter_info,
        })
    }

    /// True where the device filters 32-bit float textures (`FLOAT32_FILTERABLE`), which
    /// 32-bit moments need.
    pub fn filters_fp32(&self) -> bool {
        self.moments_format == wgpu::TextureFormat::Rgba32Float
    }

    /// The shadow-memory budget sized to this device: wgpu reports no memory size, so it
    /// follows the kind of adapter — [`GPU_BUDGET`] for a discrete GPU, [`SOFTWARE_BUDGET`]
    /// for a CPU (software Vulkan, whose memory is the process's own), [`SHARED_BUDGET`]
    /// otherwise — with this device's moment formats.
    pub fn shadow_memory_budget(&self) -> ShadowMemoryBudget {
        let bytes = match self.adapter_info.device_type {
            wgpu::DeviceType::DiscreteGpu => GPU_BUDGET,
            wgpu::DeviceType::Cpu => SOFTWARE_BUDGET,
            _ => SHARED_BUDGET,
        };
        let vsm_texel = u64::from(self.moments_format.block_copy_size(None).unwrap_or(16));
        ShadowMemoryBudget {
            bytes,
            costs: MemoryCosts {
                vsm_texel,
                sun_depth_texel: DEFAULT_SUN_DEPTH_TEXEL_BYTES,
                support: self.moment_support(),
            },
        }
    }

    /// The moment formats the device can store and filter.
    pub fn moment_support(&self) -> MomentSupport {
        MomentSupport {
            fp32_filterable: self.filters_fp32(),
            unorm16: self.unorm16_moments,
        }
    }

    /// True where textures of `format` can be rendered with `samples` samples per pixel on
    /// this device (1 always; 2 and 4 as the adapter reports, or as WebGPU guarantees where
    /// the device does not use the adapter's own format capabilities).
    pub fn supports_samples(&self, format: wgpu::TextureFormat, samples: u32) -> bool {
        samples <= 1 || self.format_flags(format).sample_count_supported(samples)
    }

    /// What this device can do with textures of `format` (sample counts, multisample
    /// resolve, filtering): the adapter's own capabilities where the device uses them
    /// (`TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES`), else what WebGPU guarantees.
    pub fn format_flags(&self, format: wgpu::TextureFormat) -> wgpu::TextureFormatFeatureFlags {
        let features = self.device.features();
        if features.contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES) {
            self.adapter.get_texture_format_features(format).flags
        } else {
            format.guaranteed_format_features(features).flags
        }
    }

    /// The device errors reported since the last call (each a message; a last line counts
    /// those not kept), emptying the list.
    pub fn take_errors(&self) -> Vec<String> {
        let mut sink = self.errors.lock().unwrap_or_else(|p| p.into_inner());
        let mut errors = std::mem::take(&mut sink.kept);
        if sink.dropped > 0 {
            errors.push(format!("and {} more GPU errors", sink.dropped));
            sink.dropped = 0;
        }
        errors
    }

    /// One line naming the adapter, its driver and backend.
    pub fn describe(&self) -> String {
        let i = &self.adapter_info;
        format!("{} ({:?}, driver {} {})", i.name, i.backend, i.driver, i.driver_info)
    }
}
