//! Single-pass cascade lists: each sun's casters listed once, with the cascades each one
//! touches packed into the high bits of its index entry, so a multiview pass can draw every
//! cascade of the sun with one instanced draw per batch and drop, in the vertex stage, the
//! instances outside the view being rasterised (`shaders/caster.wgsl`, `MULTIVIEW`).

use crate::ecs::assets::MeshHandle;
use crate::ecs::draw_groups::DrawKey;
use crate::ecs::draw_groups::{DrawGroup, push_instance};
use crate::math::cascades::MAX_SUN_VIEWS;

pub use crate::shader::contract::CASCADE_MASK_SHIFT;

/// Instances past this index cannot be packed; a scene with more gets no single-pass lists
/// and renders each cascade in its own pass.
pub const MAX_PACKED_INSTANCES: usize = 1 << CASCADE_MASK_SHIFT;

/// Whether a frame renders each sun's cascades in one multiview pass: it was asked for
/// (`asked`), the device renders at least two views per pass (`multiview_views`), and every
/// one of the `instances` can be packed into an entry. The one place this is decided: culling
/// makes the single-pass lists exactly when it holds, and the depth pass draws a run of
/// cascades in one pass exactly where a list exists.
pub fn single_pass_cascades(asked: bool, multiview_views: u32, instances: usize) -> bool {
    asked && multiview_views >= 2 && instances <= MAX_PACKED_INSTANCES
}

/// The entry of `instance` drawn into the cascades of `mask` (bit `c`: cascade `c`).
pub fn pack_entry(instance: u32, mask: u8) -> u32 {
    debug_assert!((instance as usize) < MAX_PACKED_INSTANCES);
    instance | u32::from(mask) << CASCADE_MASK_SHIFT
}

/// The instance and cascade mask of an entry made by [`pack_entry`].
pub fn unpack_entry(entry: u32) -> (u32, u8) {
    (
        entry & (MAX_PACKED_INSTANCES as u32 - 1),
        (entry >> CASCADE_MASK_SHIFT) as u8,
    )
}

/// One sun's casters for a single-pass draw of its cascades.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SinglePassGroup {
    /// Index of the sun's first cascade in [`ShadowViews::views`](crate::ecs::view_list::ShadowViews::views);
    /// its cascades follow in order.
    pub first_view: u32,
    /// Number of cascades.
    pub views: u32,
    /// Every caster of any of the cascades, once, as instanced draws over packed entries.
    pub group: DrawGroup,
}

/// A sun's list as culling keeps it between frames.
#[derive(Debug, Default)]
pub struct SunList {
    /// Packed entries, in draw order.
    pub list: Vec<u32>,
    /// Batches over `list` (starting at 0).
    pub group: DrawGroup,
}

impl SunList {
    /// Rebuilds the list from each caster's cascade mask (casters sorted by draw key, so
    /// the batches come out in draw order); `keys` gives each instance's draw key and `lods`
    /// (indexed by mesh; empty: none) the mesh each mesh draws into each cascade. A caster
    /// whose cascades draw different levels of its mesh gets an entry per level, each with
    /// the cascades that draw it: every cascade holds what its own pass would draw.
    pub fn build(&mut self, casters: &[u32], masks: &[u8], keys: &[DrawKey], lods: &[[MeshHandle; MAX_SUN_VIEWS]]) {
        self.list.clear();
        self.group.clear();
        let mut start = 0;
        while start < casters.len() {
            let key = keys[casters[start] as usize];
            let run = casters[start..]
                .iter()
                .take_while(|&&i| keys[i as usize] == key)
                .count();
            let row = lods
                .get(key.mesh.0 as usize)
                .copied()
                .unwrap_or([key.mesh; MAX_SUN_VIEWS]);
            for (mesh, cascades) in level_masks(&row) {
                let key = DrawKey { mesh, ..key };
                for (&instance, &mask) in casters[start..start + run].iter().zip(&masks[start..]) {
                    if mask & cascades != 0 {
                        push_instance(
                            &mut self.group,
                            &mut self.list,
                            key,
                            pack_entry(instance, mask & cascades),
                        );
                    }
                }
            }
            start += run;
        }
    }
}

/// The distinct meshes of a row of cascade levels, each with the bits of the cascades that
/// draw it, in the order of their first cascade.
fn level_masks(row: &[MeshHandle; MAX_SUN_VIEWS]) -> impl Iterator<Item = (MeshHandle, u8)> {
    let mut out = [(row[0], 0u8); MAX_SUN_VIEWS];
    let mut n = 0;
    for (c, &mesh) in row.iter().enumerate() {
        match out[..n].iter_mut().find(|(m, _)| *m == mesh) {
            Some(slot) => slot.1 |= 1 << c,
            None => {
                out[n] = (mesh, 1 << c);
                n += 1;
            }
        }
    }
    out.into_iter().take(n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ecs::assets::{MaterialHandle, MeshHandle};

    #[test]
    fn entries_round_trip_the_largest_instance_and_every_mask() {
        for instance in [0, 1, 12_345, MAX_PACKED_INSTANCES as u32 - 1] {
            for mask in 0..16u8 {
                assert_eq!(unpack_entry(pack_entry(instance, mask)), (instance, mask));
            }
        }
    }

    #[test]
    fn a_caster_gets_an_entry_per_level_its_cascades_draw() {
        let key = |mesh| DrawKey {
            mesh: MeshHandle(mesh),
            material: MaterialHandle(0),
            masked: false,
            double_sided: false,
        };
        // Mesh 0 draws itself into cascades 0 and 1, mesh 5 into 2 and mesh 6 into 3.
        let mut row = [MeshHandle(6); MAX_SUN_VIEWS];
        row[..3].copy_from_slice(&[MeshHandle(0), MeshHandle(0), MeshHandle(5)]);
        let mut sun = SunList::default();
        sun.build(&[0, 1], &[0b0110, 0b1000], &[key(0), key(0)], &[row]);
        assert_eq!(
            sun.list.iter().map(|&e| unpack_entry(e)).collect::<Vec<_>>(),
            [(0, 0b0010), (0, 0b0100), (1, 0b1000)]
        );
        let batches: Vec<(u32, u32, u32)> = sun.group.opaque.iter().map(|b| (b.mesh.0, b.first, b.count)).collect();
        assert_eq!(batches, [(0, 0, 1), (5, 1, 1), (6, 2, 1)]);
    }

    #[test]
    fn a_sun_list_holds_each_caster_once_with_its_cascades() {
        let key = |mesh| DrawKey {
            mesh: MeshHandle(mesh),
            material: MaterialHandle(0),
            masked: false,
            double_sided: false,
        };
        let keys = [key(0), key(0), key(1), key(1)];
        let mut sun = SunList::default();
        sun.build(&[0, 1, 2, 3], &[0b0011, 0, 0b0100, 0b1000], &keys, &[]);
        assert_eq!(
            sun.list.iter().map(|&e| unpack_entry(e)).collect::<Vec<_>>(),
            [(0, 0b0011), (2, 0b0100), (3, 0b1000)]
        );
        let counts: Vec<(u32, u32)> = sun.group.opaque.iter().map(|b| (b.first, b.count)).collect();
        assert_eq!(counts, [(0, 1), (1, 2)]);
        assert!(sun.group.masked.is_empty());
    }
}
