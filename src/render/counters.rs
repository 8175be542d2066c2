//! How many GPU objects the renderer has created, so tests (and the inspector) can check that
//! a settings change rebuilt only what it must: a new resolution recreates the shadow storage
//! and the bind group that samples it, a new cascade count recreates nothing.

/// Running totals of GPU objects created since the renderer was built.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderCounters {
    /// Shadow storage textures allocated (cascade and spot arrays; not the 1×1 stand-ins).
    pub shadow_maps: u32,
    /// Forward (receiver) pipelines built.
    pub forward_pipelines: u32,
    /// Shadow-caster pipelines built (one per distinct key: masked or not, bias, clamp).
    pub caster_pipelines: u32,
    /// Shadow bind groups (lights, views, shadow storage) rebuilt because a buffer or a
    /// storage texture was replaced: the plain group, and while the frame resolves visibility
    /// the lighting pass's group that also binds the resolved visibility.
    pub shadow_groups: u32,
    /// Transient textures and buffers the render graph's pool created (the camera depth;
    /// again only when the target's size changes).
    pub transient_resources: u32,
    /// Frames whose paged-sun pages were marked and allocated (a frame that would mark what
    /// the last marked frame did skips them).
    pub page_markings: u32,
}
