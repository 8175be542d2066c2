//! Host mirror of the WGSL `Instance` (`shaders/mesh.wgsl`): what the ECS writes per
//! drawable instance and every pass reads. The layout test in `render::gpu_types` compares
//! it with naga's layout of the WGSL.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};

/// Mirror of WGSL `Instance`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct InstanceGpu {
    /// World from local transform.
    pub world_from_local: Mat4,
    /// Inverse transpose of the upper 3×3 (in a 4×4 for alignment).
    pub normal_from_local: Mat4,
    /// Base colour factor (linear RGBA).
    pub base_color: Vec4,
    /// Alpha cutoff for masked materials, 0 for opaque.
    pub alpha_cutoff: f32,
    /// `INSTANCE_FLAG_*` bits.
    pub flags: u32,
    /// Diffuse transmission ([`Material::effective_transmission`](crate::ecs::assets::Material::effective_transmission)).
    pub transmission: f32,
    /// Padding to the WGSL size.
    pub _pad: u32,
}
