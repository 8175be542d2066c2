//! How a sun's shadow is divided into maps ([`SunLayout`]): cascades, a clipmap, or a
//! virtual clipmap of pages, with the defaults a scene file may leave out.

use serde::{Deserialize, Serialize};

use crate::math::pages::atlas_tiles;

/// How a sun's shadow is divided into maps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SunLayout {
    /// Cascaded shadow maps ([`ShadowMapSettings::cascades`](crate::settings::ShadowMapSettings::cascades)): the view frustum cut by view
    /// depth, each slice fitted with its own map.
    #[default]
    Cascades,
    /// A clipmap ([`crate::math::clipmap`]): `levels` (1–8) concentric squares in the
    /// light's frame centred on the camera, level `i` covering `level0_extent · 2^i` metres
    /// (0.5–100 000 for level 0) with the same texels, snapped to whole texels; a receiver
    /// samples the finest level that holds it and blends into the next across a band of
    /// `blend_width` of the level's half side; shadows fade out over the last level's edge.
    /// Turning the camera changes no level.
    Clipmap {
        /// Number of levels, 1–8 (6 when a file leaves it out).
        #[serde(default = "default_levels")]
        levels: u32,
        /// Side of the finest level, metres (32 when a file leaves it out).
        #[serde(default = "default_level0_extent")]
        level0_extent: f32,
    },
    /// Experimental: a clipmap whose levels are virtual textures
    /// ([`crate::math::pages`]): each level `virtual_resolution`² texels (4096–16384, a
    /// power of two) cut into pages of `page_size`² texels (64–512, a power of two); only
    /// the pages some visible pixel reads get one of the `pool_pages` pages of a shared pool
    /// and are drawn, and a page stays drawn until a caster over it moves or the light turns.
    /// Every filter works on it; EVSM and MSM bake their moments page by page (a fixed blur
    /// stops at a page's edge; contact hardening averages each page down its own mips). One sun per frame is
    /// paged: a second paged sun is drawn as a plain clipmap.
    VirtualClipmap {
        /// Number of levels, 1–8 (6 when a file leaves it out).
        #[serde(default = "default_levels")]
        levels: u32,
        /// Side of the finest level, metres (32 when a file leaves it out).
        #[serde(default = "default_level0_extent")]
        level0_extent: f32,
        /// Texels per side of every level (16384 when a file leaves it out).
        #[serde(default = "default_virtual_resolution")]
        virtual_resolution: u32,
        /// Texels per side of a page (128 when a file leaves it out).
        #[serde(default = "default_page_size")]
        page_size: u32,
        /// Pages of the shared pool (2048 when a file leaves it out: an atlas of 46² pages of
        /// 128², 132 MiB; see [`SunLayout::pool_bytes`]).
        #[serde(default = "default_pool_pages")]
        pool_pages: u32,
    },
}

/// A virtual clipmap level's side when none is given, texels.
pub const DEFAULT_VIRTUAL_RESOLUTION: u32 = 16384;
/// A virtual clipmap's page side when none is given, texels.
pub const DEFAULT_PAGE_SIZE: u32 = 128;
/// A virtual clipmap's pool when none is given, pages.
pub const DEFAULT_POOL_PAGES: u32 = 2048;

fn default_virtual_resolution() -> u32 {
    DEFAULT_VIRTUAL_RESOLUTION
}

fn default_page_size() -> u32 {
    DEFAULT_PAGE_SIZE
}

fn default_pool_pages() -> u32 {
    DEFAULT_POOL_PAGES
}

fn default_levels() -> u32 {
    6
}

fn default_level0_extent() -> f32 {
    32.0
}

/// The most clipmap levels a sun can have.
pub const MAX_CLIPMAP_LEVELS: u32 = crate::math::clipmap::MAX_CLIPMAP_LEVELS as u32;

impl SunLayout {
    /// The virtual clipmap's defaults: 6 levels, the finest 32 m wide, 16384² texels each in
    /// 128² pages, a pool of 2048 pages.
    pub fn virtual_clipmap() -> Self {
        SunLayout::VirtualClipmap {
            levels: default_levels(),
            level0_extent: default_level0_extent(),
            virtual_resolution: default_virtual_resolution(),
            page_size: default_page_size(),
            pool_pages: default_pool_pages(),
        }
    }

    /// The clipmap's levels and the side of its finest level (None for cascades).
    pub fn clipmap_levels(&self) -> Option<(u32, f32)> {
        match *self {
            SunLayout::Cascades => None,
            SunLayout::Clipmap { levels, level0_extent }
            | SunLayout::VirtualClipmap {
                levels, level0_extent, ..
            } => Some((levels, level0_extent)),
        }
    }

    /// Bytes of the shared page pool of a paged clipmap: its atlas, the smallest square of
    /// pages that holds `pool_pages`, at 32-bit depth (0 for other layouts).
    pub fn pool_bytes(&self) -> u64 {
        let side = u64::from(self.pool_side());
        side * side * 4
    }

    /// Texels per side of a paged clipmap's pool atlas (0 for other layouts).
    pub fn pool_side(&self) -> u32 {
        match *self {
            SunLayout::VirtualClipmap {
                page_size, pool_pages, ..
            } => atlas_tiles(pool_pages) * page_size,
            _ => 0,
        }
    }
}
