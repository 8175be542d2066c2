//! The wgpu renderer: device, render graph, the shadow resources and depth pass, the forward
//! pass, GPU timings and headless targets.

pub mod context;
pub mod counters;
pub mod deferred;
pub mod depth_bounds;
pub mod draw;
pub mod draw_args;
pub mod forward_pass;
pub mod fragment_count;
pub mod frame;
pub mod frame_inputs;
pub mod gpu_types;
pub mod graph;
pub mod grow_buffer;
pub mod layouts;
pub mod limits;
pub mod mips;
pub mod occlusion;
mod occlusion_kernels;
pub mod options;
pub mod plugin;
pub mod prepass;
pub mod prepass_keep;
pub mod probe;
pub mod readback;
pub mod renderer;
pub mod report;
pub mod resolve;
pub mod scene_gpu;
pub mod seen_readback;
pub mod shadow_cull;
pub mod shadows;
pub mod skinning;
pub mod target;
pub mod textures;
pub mod timer;
pub mod variant;

pub use context::{GpuContext, GpuError};
pub use counters::RenderCounters;
pub use limits::{DeviceLimits, LimitError};
pub use options::{DeferredLighting, DepthPrepass, Msaa, RenderOptions, SunDepth};
pub use plugin::RenderPlugin;
pub use renderer::Renderer;
pub use report::{FrameReport, PageStats};
pub use timer::PassTiming;
