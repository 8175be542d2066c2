//! The ECS layer: components, asset stores, resources and the thin systems that call the pure
//! math each frame.

pub mod assets;
pub mod camera_runs;
pub mod caster_changes;
pub mod clipmap_scroll;
pub mod components;
pub mod culling;
pub mod draw_groups;
pub mod footprints;
pub mod frame_lights;
pub mod instance_changes;
pub mod instance_rows;
pub mod instance_sync;
pub mod instances;
pub mod layout_views;
pub mod light_checks;
pub mod light_views;
pub mod lights;
pub mod lod_table;
pub mod mobility;
pub mod origin;
pub mod placement;
pub mod plugin;
pub mod receiver_culling;
pub mod shadow_lods;
pub mod shadow_memory;
pub mod shadow_runs;
pub mod shadow_views;
pub mod single_pass;
pub mod skinning;
pub mod stats;
pub mod view;
pub mod view_cache;
pub mod view_culling;
pub mod view_list;
pub mod view_lod;
pub mod view_order;

pub use assets::{AlphaMode, ImageData, ImageHandle, Images, Material, MaterialHandle, Materials, MeshHandle, Meshes};
pub use bevy_transform::components::{GlobalTransform, Transform};
pub use components::{
    AmbientLight, Camera3d, DirectionalLight, Mesh3d, MeshMaterial3d, NotShadowCaster, NotShadowReceiver, ViewportSize,
};
pub use draw_groups::{DrawBatch, DrawGroup, InstanceRun, ShadowRun, ViewDrawGroups};
pub use instance_changes::InstanceSync;
pub use instances::RenderInstances;
pub use light_views::{FrameLights, PointLightView, SpotLightView, SunView};
pub use lights::{PointLight, SpotLight};
pub use mobility::{Static, StaticChanges};
pub use origin::RenderOrigin;
pub use plugin::{ShadowPlugin, ShadowSystems};
pub use shadow_memory::{ShadowMemory, ShadowMemoryBudget};
pub use skinning::{
    AnimationClock, AnimationPlayer, SkinSource, SkinSourceHandle, SkinSources, SkinnedMesh, SkinningFrame,
};
pub use stats::{ShadowDiagnostics, ShadowStats};
pub use view::{ActiveView, SeenByCamera};
pub use view_list::{CullVolume, ShadowLightBudget, ShadowStorage, ShadowView, ShadowViewKind, ShadowViews};
pub use view_lod::CameraLod;
