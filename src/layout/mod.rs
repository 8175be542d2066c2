//! Shadow layouts described once: the storages a layout renders its views into (what
//! [`ShadowStorage`] names, with its label, its sampled dimension and its bindings) and the
//! shadow bind group (group 3) built from those descriptions ([`group`]). Everything here is
//! plain data: the ECS, the shader library and the renderer all read it, and it imports
//! none of them.

pub mod group;

/// The storage a shadow view renders into: one depth array per layout (and, for the layouts
/// that filter moments, one moment array beside it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShadowStorage {
    /// The cascades of every shadowed sun, a layer each.
    Cascades,
    /// Every shadowed spot light, a layer each.
    Spots,
    /// Every shadowed point light, six layers (a cube) each.
    Points,
    /// A paged clipmap's levels: virtual textures whose resident pages share one pool (an
    /// atlas, one layer), found through a page table; drawn by the page passes, not the
    /// depth pass.
    Pages,
}

/// What the renderer needs to know about one storage.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StorageDesc {
    /// Label of its depth array (and the start of its other resources' labels).
    pub label: &'static str,
    /// Label of its moment array.
    pub moments_label: &'static str,
    /// WGSL name of its depth array in the shadow group.
    pub maps_binding: &'static str,
    /// WGSL name of its moment array in the shadow group.
    pub moments_binding: &'static str,
    /// What its depth array holds, for the generated WGSL's comment.
    pub doc: &'static str,
    /// Sampled as a cube array (hardware face selection), so every light in it shares one
    /// face size; otherwise a 2D array whose lights each keep their own size.
    pub cube: bool,
    /// Its views can be rendered in one multiview pass per light (a sun's cascades).
    pub single_pass: bool,
    /// How its moments are made.
    pub moments: StorageMoments,
    /// What one of a light's views in it is called in pass labels (`cascade 2`, `face 5`), or
    /// empty for a storage with one view per light.
    pub view_word: &'static str,
    /// Its views are virtual (a page table maps their pages into one atlas layer), drawn by
    /// the page passes; the storage also binds its page table ([`group::Slot::PageTable`]).
    pub paged: bool,
    /// Its views are a sun's (orthographic: depth linear along the light), so its depth
    /// array takes the format [`RenderOptions::sun_depth`](crate::render::RenderOptions::sun_depth)
    /// asks for; the others are always 32-bit floats.
    pub sun_depth: bool,
}

/// How a storage's moments are made from its depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StorageMoments {
    /// VSM (z, z²) of each light that asks for it, blurred per light (the VSM moments pass).
    Vsm,
    /// EVSM2, EVSM4 or MSM of each redrawn view, filtered into mips (the cascade moments
    /// pass).
    Baked,
    /// EVSM2, EVSM4 or MSM of a paged sun's drawn pages, baked by the pages node into an
    /// atlas laid out as the pool's (no mips).
    Paged,
    /// None: its lights filter depth only (its moments binding holds a 1×1 stand-in).
    None,
}

impl ShadowStorage {
    /// Every storage, in the order of the renderer's arrays.
    pub const ALL: [ShadowStorage; 4] = [
        ShadowStorage::Cascades,
        ShadowStorage::Spots,
        ShadowStorage::Points,
        ShadowStorage::Pages,
    ];

    /// Number of storages.
    pub const COUNT: usize = Self::ALL.len();

    /// Its position in [`ALL`](Self::ALL): the index of its arrays in the renderer's lists.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The storages whose moments are made `how`, in [`ALL`](Self::ALL)'s order.
    pub fn with_moments(how: StorageMoments) -> impl Iterator<Item = ShadowStorage> {
        Self::ALL.into_iter().filter(move |s| s.desc().moments == how)
    }

    /// Its description.
    pub fn desc(self) -> &'static StorageDesc {
        match self {
            ShadowStorage::Cascades => &CASCADES,
            ShadowStorage::Spots => &SPOTS,
            ShadowStorage::Points => &POINTS,
            ShadowStorage::Pages => &PAGES,
        }
    }
}

const CASCADES: StorageDesc = StorageDesc {
    label: "cascade shadow maps",
    moments_label: "cascade shadow moments",
    view_word: "cascade",
    maps_binding: "cascade_maps",
    moments_binding: "cascade_moments",
    doc: "Every cascade of every shadowed sun, one layer each; its moments (EVSM2, EVSM4 or MSM) a layer per cascade.",
    cube: false,
    single_pass: true,
    moments: StorageMoments::Baked,
    paged: false,
    sun_depth: true,
};

const SPOTS: StorageDesc = StorageDesc {
    label: "spot shadow maps",
    moments_label: "spot shadow moments",
    view_word: "",
    maps_binding: "spot_maps",
    moments_binding: "spot_moments",
    doc: "Every shadowed spot light, one layer each; its VSM moments (z, z²) beside it.",
    cube: false,
    single_pass: false,
    moments: StorageMoments::Vsm,
    paged: false,
    sun_depth: false,
};

const POINTS: StorageDesc = StorageDesc {
    label: "point shadow cubes",
    moments_label: "point shadow moments",
    view_word: "face",
    maps_binding: "point_maps",
    moments_binding: "point_moments",
    doc: "Every shadowed point light's six faces, sampled as a cube (index: first layer / 6); its VSM moments beside it.",
    cube: true,
    single_pass: false,
    moments: StorageMoments::Vsm,
    paged: false,
    sun_depth: false,
};

const PAGES: StorageDesc = StorageDesc {
    label: "shadow page pool",
    moments_label: "shadow page moments",
    view_word: "level",
    maps_binding: "page_atlas",
    moments_binding: "page_moments",
    doc: "The pool of a paged clipmap: its resident pages side by side in one layer (`page_table` finds them); its moments (EVSM2, EVSM4 or MSM) laid out the same.",
    cube: false,
    single_pass: false,
    moments: StorageMoments::Paged,
    paged: true,
    sun_depth: false,
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_storage_sits_at_its_index_with_its_own_labels() {
        for (i, storage) in ShadowStorage::ALL.into_iter().enumerate() {
            assert_eq!(storage.index(), i);
            let others = ShadowStorage::ALL.iter().filter(|s| **s != storage);
            for other in others {
                assert_ne!(storage.desc().label, other.desc().label);
                assert_ne!(storage.desc().moments_label, other.desc().moments_label);
            }
        }
    }
}
