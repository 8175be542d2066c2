//! How many GPU objects the renderer has created, so tests (and the inspector) can check that
//! a settings change rebuilt only what it must: a new resolution recreates the shadow map and
//! the bind group that samples it, a new cascade count recreates nothing.

/// Running totals of GPU objects created since the renderer was built.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderCounters {
    /// Shadow-map textures allocated.
    pub shadow_maps: u32,
    /// Forward (receiver) pipelines built.
    pub forward_pipelines: u32,
    /// Shadow-caster pipeline pairs (opaque + masked) built.
    pub caster_pipelines: u32,
    /// View bind groups (frame and shadow uniforms plus the shadow map) built.
    pub view_groups: u32,
}
