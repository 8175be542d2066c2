//! WGSL shader library: the modules under `shaders/` composed with naga_oil into the
//! pipelines' shaders, one variant per shader-def set. Everything here is pure naga work (no
//! GPU), so `cargo test` validates every variant.

pub mod contract;
pub mod instance;
mod library;
mod variant;

pub use library::{ShaderError, ShaderLibrary};
pub use variant::{ForwardVariant, ShadowFilter};
