//! The mesh each caster mesh draws in each view of a sun's set (`lod_table`): its shadow
//! LOD for the view's texel size and its largest caster, shared by the cascade culling and
//! the clipmap's strips.

use crate::ecs::assets::MeshHandle;
use crate::ecs::draw_groups::DrawKey;
use crate::ecs::instances::RenderInstances;
use crate::ecs::shadow_lods::ShadowLods;
use crate::math::cascades::{Cascade, MAX_SUN_VIEWS};

/// Fills `table` with the mesh each mesh is drawn with into each of `cascades` (its shadow
/// LOD for the cascade's texel size and its largest caster); empty when no mesh has levels.
pub(crate) fn lod_table(
    lods: &ShadowLods,
    instances: &RenderInstances,
    cascades: &[Cascade],
    table: &mut Vec<[MeshHandle; MAX_SUN_VIEWS]>,
) {
    table.clear();
    if lods.is_empty() {
        return;
    }
    for (m, &radius) in instances.mesh_caster_radius.iter().enumerate() {
        let mesh = MeshHandle(m as u32);
        let mut row = [mesh; MAX_SUN_VIEWS];
        for (slot, cascade) in row.iter_mut().zip(cascades) {
            *slot = lods.pick(mesh, radius, cascade.texel_world_size);
        }
        table.push(row);
    }
}

/// `key` with the mesh cascade `c` draws (from [`lod_table`]'s table).
pub(crate) fn lod_key(table: &[[MeshHandle; MAX_SUN_VIEWS]], key: DrawKey, c: usize) -> DrawKey {
    match table.get(key.mesh.0 as usize) {
        Some(row) => DrawKey { mesh: row[c], ..key },
        None => key,
    }
}
