//! Host mirror of the WGSL `Instance` (`shaders/mesh.wgsl`): what the ECS writes per
//! drawable instance and every pass reads. The layout test in `render::gpu_types` compares
//! it with naga's layout of the WGSL.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};

/// Mirror of WGSL `Instance` (80 bytes: a million instances fit a 128 MiB storage binding).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct InstanceGpu {
    /// World from local transform: its first three rows (the fourth is `0 0 0 1`; see
    /// [`InstanceGpu::world_rows`]). The shaders derive the normal transform from it.
    pub world_rows: [Vec4; 3],
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

impl InstanceGpu {
    /// The first three rows of the affine transform `world_from_local` (its fourth row must be
    /// `0 0 0 1`).
    pub fn world_rows(world_from_local: &Mat4) -> [Vec4; 3] {
        [0, 1, 2].map(|i| world_from_local.row(i))
    }

    /// The world-from-local transform the rows hold.
    pub fn world_from_local(&self) -> Mat4 {
        let [x, y, z] = self.world_rows;
        Mat4::from_cols(x, y, z, Vec4::W).transpose()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Quat, Vec3};

    #[test]
    fn an_affine_transform_survives_its_rows() {
        let m = Mat4::from_scale_rotation_translation(
            Vec3::new(2.0, -0.5, 3.0),
            Quat::from_rotation_y(0.7),
            Vec3::new(1.0, 2.0, -4.0),
        );
        let instance = InstanceGpu {
            world_rows: InstanceGpu::world_rows(&m),
            ..InstanceGpu::default()
        };
        assert_eq!(instance.world_from_local(), m);
        assert_eq!(size_of::<InstanceGpu>(), 80);
    }
}
