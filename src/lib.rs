//! penumbra: cascaded, soft and measured sun shadows for bevy_ecs apps, rendered with wgpu.
//!
//! Layers, from the bottom: [`math`] (pure cascade math, no GPU or ECS), [`settings`],
//! [`mesh`] (CPU meshes), [`ecs`] (components, resources, the per-frame systems and
//! [`ShadowPlugin`](ecs::ShadowPlugin)), [`shader`] (the WGSL library composed with
//! naga_oil), [`render`] (wgpu passes and the render graph) and [`scene`] (RON scene files).
//! [`gltf`](mod@gltf) reads glTF 2.0 models as pure data; [`asset_io`] confines the files
//! they and scenes name to an asset root. [`prelude`] is the one import an app needs.
//!
//! # Features
//!
//! With `default-features = false` the crate builds what rendering shadows needs and nothing
//! else: the plugin, the render graph, the WGSL library and RON scenes. Optional parts:
//!
//! - `gltf`: glTF 2.0 models ([`gltf`](mod@gltf), scene objects with `model:`).
//! - `bench`: the ray-traced [`reference`](mod@reference), the error
//!   [`analysis`](mod@analysis) and its plots, and the [`bench`](mod@bench) runner.
//! - `cli`: the `penumbra` command line (implies `bench` and `gltf`); on by default.
//! - `viewer`: the windowed viewer and its egui inspector; on by default.
#![warn(missing_docs)]

/// The `bevy_app` this crate is built with (its `App` is what [`ecs::ShadowPlugin`] plugs into).
pub use bevy_app;
/// The `bevy_ecs` this crate is built with (components and resources are its types).
pub use bevy_ecs;
/// The `glam` this crate is built with (every vector and matrix of the API).
pub use glam;
/// The `wgpu` this crate is built with (the renderer's device, textures and passes).
pub use wgpu;

/// The commit this crate was built from: the short hash of the checkout's `HEAD`, with
/// `-dirty` when its sources (`src`, `shaders`, `Cargo.toml`, `Cargo.lock`, `build.rs`) had
/// uncommitted changes, or `unknown` when it was not built from a git checkout. Embedded at
/// build time by `build.rs`; reports name it as the code they measured.
pub const BUILD_COMMIT: &str = env!("PENUMBRA_BUILD_COMMIT");

#[cfg(feature = "bench")]
pub mod analysis;
pub mod app;
pub mod asset_io;
#[cfg(feature = "bench")]
pub mod bench;
pub mod diagnostic;
pub mod ecs;
pub mod export;
#[cfg(feature = "gltf")]
pub mod gltf;
pub mod layout;
pub mod math;
pub mod mesh;
pub mod prelude;
#[cfg(feature = "bench")]
pub mod reference;
pub mod render;
pub mod scene;
pub mod settings;
pub mod shader;
pub mod text;
pub mod viewer;
