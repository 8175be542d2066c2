//! The paged clipmap's state shared by its passes and the materials: the page allocator
//! (whose table group 3 binds as `page_table`) and the size of the pool's atlas (the paged
//! storage's depth array, one layer of `tiles × tiles` pages). Made when a sun turns its
//! virtual clipmap on, remade when its layout, levels or pool change.

use crate::ecs::light_views::FrameLights;
use crate::math::pages::{PageLayout, atlas_tiles};
use crate::render::shadows::page_allocate::{MAX_PAGED_LEVELS, PageAllocator};
use crate::settings::SunLayout;
use crate::shader::ShaderLibrary;

/// Names of the page passes' timings, in order.
pub const PAGE_PASSES: [&str; 4] = [
    "shadow page marking",
    "shadow page allocation",
    "shadow page drawing",
    "shadow page moments",
];

/// What a pool is made for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoolKey {
    /// How its levels are cut into pages.
    pub layout: PageLayout,
    /// Its levels (at most [`MAX_PAGED_LEVELS`]).
    pub levels: u32,
    /// Its physical pages.
    pub pool_pages: u32,
}

impl PoolKey {
    /// The pool the frame's paged sun needs (None without one).
    pub fn of(lights: &FrameLights) -> Option<Self> {
        let sun = lights.paged_sun()?;
        let SunLayout::VirtualClipmap { pool_pages, .. } = sun.settings.map.layout else {
            return None;
        };
        Some(Self {
            layout: sun.paged?,
            levels: (sun.cascades.count as u32).min(MAX_PAGED_LEVELS as u32),
            pool_pages,
        })
    }

    /// Tiles per side of the atlas: the smallest square that holds the pool.
    pub fn tiles(&self) -> u32 {
        atlas_tiles(self.pool_pages)
    }

    /// Texels per side of the atlas.
    pub fn atlas_side(&self) -> u32 {
        self.tiles() * self.layout.page_size
    }
}

/// A paged sun's allocator and what it was made for.
pub struct PagePool {
    /// The allocator: tables, pool records, draw list and counters.
    pub allocator: PageAllocator,
    /// What it was made for.
    pub key: PoolKey,
}

impl PagePool {
    /// Empty tables and pool for `key`.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, library: &mut ShaderLibrary, key: PoolKey) -> Self {
        Self {
            allocator: PageAllocator::new(device, queue, library, key.layout, key.levels, key.pool_pages),
            key,
        }
    }
}
