//! One import for an app: `use penumbra::prelude::*;` brings the plugins, the components an
//! app spawns (lights, camera, meshes, shadow flags), the settings, the headless helpers, the
//! scene loader, and the `glam` and `bevy_app` types the API takes, so an app needs no
//! matching versions of those crates of its own. The crates themselves are re-exported at the
//! crate root ([`crate::glam`], [`crate::wgpu`], [`crate::bevy_app`], [`crate::bevy_ecs`]).

pub use bevy_app::App;
pub use glam::{Mat4, Quat, Vec2, Vec3, Vec4};

pub use crate::app::{headless_app, spawn_scene};
pub use crate::ecs::{
    AlphaMode, AmbientLight, Camera3d, DirectionalLight, GlobalTransform, Material, MaterialHandle, Materials, Mesh3d,
    MeshHandle, MeshMaterial3d, Meshes, NotShadowCaster, NotShadowReceiver, PointLight, ShadowDiagnostics,
    ShadowLightBudget, ShadowPlugin, ShadowStats, SpotLight, Static, Transform,
};
pub use crate::mesh::{cuboid, plane, sphere};
pub use crate::render::{DepthPrepass, GpuContext, Msaa, RenderOptions, RenderPlugin, Renderer};
pub use crate::scene::SceneDesc;
pub use crate::settings::{
    CascadeFit, CascadeSettings, ContactShadows, MomentFormat, MomentSettings, PcssQuality, ShadowBias,
    ShadowDebugView, ShadowFilterSettings, ShadowMapSettings, ShadowMode, ShadowSettings, VsmSettings,
};
