//! Shadow LODs: coarser meshes a caster may be drawn with into a shadow map whose texels are
//! larger than what the coarser mesh loses. A cascade far from the camera covers a wide area
//! with the same texels; a 1 024-triangle sphere a few texels wide draws the same shadow
//! with 64 triangles. Each level states its geometric error relative to the mesh's bounding
//! radius; a cascade draws every instance of a mesh with the coarsest level whose error, for
//! the largest instance of that mesh, stays under half a texel (so all instances of a mesh
//! keep one instanced draw per cascade). The camera view picks from the same levels by their
//! size on screen ([`crate::ecs::view_lod`]).

use bevy_ecs::resource::Resource;

use crate::ecs::assets::MeshHandle;

/// Largest geometric error of a level, in texels of the map it is drawn into.
pub const MAX_ERROR_TEXELS: f32 = 0.5;

/// One coarser version of a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowLod {
    /// The coarser mesh.
    pub mesh: MeshHandle,
    /// How far its surface may lie from the full mesh's, as a fraction of the bounding
    /// radius of an instance.
    pub relative_error: f32,
}

/// The shadow LODs of each mesh (none by default). Changing them redraws every shadow map.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct ShadowLods {
    levels: Vec<Vec<ShadowLod>>,
}

impl ShadowLods {
    /// Sets the coarser levels of `mesh` (any order; levels with a non-finite or negative
    /// error are ignored).
    pub fn set(&mut self, mesh: MeshHandle, mut levels: Vec<ShadowLod>) {
        levels.retain(|l| l.relative_error.is_finite() && l.relative_error >= 0.0);
        levels.sort_by(|a, b| a.relative_error.total_cmp(&b.relative_error));
        let i = mesh.0 as usize;
        if self.levels.len() <= i {
            self.levels.resize_with(i + 1, Vec::new);
        }
        self.levels[i] = levels;
    }

    /// Removes every level.
    pub fn clear(&mut self) {
        self.levels.clear();
    }

    /// True when no mesh has a level.
    pub fn is_empty(&self) -> bool {
        self.levels.iter().all(Vec::is_empty)
    }

    /// Whether `mesh` is a coarser level of some mesh.
    pub fn is_level(&self, mesh: MeshHandle) -> bool {
        self.levels.iter().flatten().any(|l| l.mesh == mesh)
    }

    /// The levels of `mesh`, finest first.
    pub fn get(&self, mesh: MeshHandle) -> &[ShadowLod] {
        self.levels.get(mesh.0 as usize).map_or(&[], Vec::as_slice)
    }

    /// The mesh to draw instances of `mesh` with (the largest of bounding radius `radius`)
    /// into a map whose texels are `texel` wide (world units): the coarsest level whose error
    /// stays under [`MAX_ERROR_TEXELS`], else `mesh` itself.
    pub fn pick(&self, mesh: MeshHandle, radius: f32, texel: f32) -> MeshHandle {
        let budget = MAX_ERROR_TEXELS * texel;
        self.get(mesh)
            .iter()
            .rev()
            .find(|l| l.relative_error * radius <= budget)
            .map_or(mesh, |l| l.mesh)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_coarsest_level_within_half_a_texel_is_picked() {
        let mut lods = ShadowLods::default();
        let level = |mesh, relative_error| ShadowLod {
            mesh: MeshHandle(mesh),
            relative_error,
        };
        lods.set(MeshHandle(2), vec![level(4, 0.08), level(3, 0.02), level(5, f32::NAN)]);
        assert_eq!(lods.get(MeshHandle(2)).len(), 2);
        let pick = |radius, texel| lods.pick(MeshHandle(2), radius, texel).0;
        // Radius 1: errors 0.02 and 0.08 against half-texel budgets.
        assert_eq!(pick(1.0, 0.01), 2, "texels too fine for either level");
        assert_eq!(pick(1.0, 0.05), 3);
        assert_eq!(pick(1.0, 0.2), 4);
        // A mesh without levels, and one past the table, draw themselves.
        assert_eq!(lods.pick(MeshHandle(0), 1.0, 100.0), MeshHandle(0));
        assert_eq!(lods.pick(MeshHandle(9), 1.0, 100.0), MeshHandle(9));
        assert!(!lods.is_empty());
        assert!(lods.is_level(MeshHandle(3)) && !lods.is_level(MeshHandle(2)));
        lods.clear();
        assert!(lods.is_empty());
    }
}
