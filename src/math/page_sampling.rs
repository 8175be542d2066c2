//! Where a receiver of a paged clipmap reads its depth: the finest level whose window holds
//! it (with the filter's margin) whose page is resident, falling back to coarser levels when
//! its own page did not fit the pool (an overflow), and the texel of the pool's atlas that
//! holds the grid position. The sampler's rules, as the CPU mirror the GPU's sampling is
//! compared with.

use glam::DVec2;

use crate::math::pages::{PageKey, PagedLevel, VirtualPages};

/// Where a grid position of a level lives in the pool.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PagedTexel {
    /// The level read (the finest holding the receiver, or a coarser one after an overflow).
    pub level: usize,
    /// The physical page holding it.
    pub physical: u32,
    /// The position in the atlas, texels (continuous; rows downwards).
    pub atlas: DVec2,
}

/// The atlas position of grid position `at` (texels of its level, continuous; light-frame y
/// up) in physical page `physical` holding grid page `page`, in an atlas of `tiles` tiles a
/// side of `page_size` texels: a page keeps its level's orientation, so its top row is its
/// largest y.
pub fn atlas_position(at: DVec2, page: DVec2, physical: u32, tiles: u32, page_size: u32) -> DVec2 {
    let size = f64::from(page_size);
    let tile = DVec2::new(f64::from(physical % tiles), f64::from(physical / tiles));
    let inside = at - page * size;
    DVec2::new(tile.x * size + inside.x, tile.y * size + (size - inside.y))
}

/// Where a receiver at light-frame `xy` reads its depth: the finest level whose window holds
/// it `margin` texels inside every edge if its page holding it is resident in `pages` (atlas
/// of `tiles` tiles a side), else the next coarser level, else the coarsest (as the shaders'
/// `paged_level` tries them). None when none of them has it.
pub fn resolve_texel(
    pages: &VirtualPages,
    levels: &[PagedLevel],
    xy: DVec2,
    margin: f64,
    tiles: u32,
) -> Option<PagedTexel> {
    let layout = &pages.layout;
    let side = f64::from(layout.virtual_resolution);
    let first = levels.iter().position(|level| {
        let lo = (level.first_texel.as_dvec2() + DVec2::splat(margin)) * level.texel;
        let hi = (level.first_texel.as_dvec2() + DVec2::splat(side - margin)) * level.texel;
        xy.cmpge(lo).all() && xy.cmple(hi).all()
    })?;
    let coarsest = levels.len() - 1;
    let tries = [first, (first + 1).min(coarsest), coarsest];
    tries.into_iter().find_map(|i| {
        let level = &levels[i];
        let at = xy / level.texel;
        let page = layout.page_of(at.floor().as_i64vec2());
        let physical = pages.lookup(PageKey::new(i as u32, page))?;
        Some(PagedTexel {
            level: i,
            physical,
            atlas: atlas_position(at, page.as_dvec2(), physical, tiles, layout.page_size),
        })
    })
}

#[cfg(test)]
mod tests {
    use glam::I64Vec2;

    use super::*;
    use crate::math::pages::{PageLayout, PageRect};

    fn levels() -> [PagedLevel; 2] {
        [
            PagedLevel {
                first_texel: I64Vec2::ZERO,
                texel: 1.0,
            },
            PagedLevel {
                first_texel: I64Vec2::splat(-2048),
                texel: 2.0,
            },
        ]
    }

    fn windows(layout: &PageLayout) -> [PageRect; 2] {
        levels().map(|l| layout.window(l.first_texel))
    }

    #[test]
    fn a_resident_page_gives_its_tile_with_the_page_upright() {
        let layout = PageLayout::new(4096, 128).unwrap();
        let mut pages = VirtualPages::new(layout, 2, 8);
        let key = PageKey::new(0, I64Vec2::new(3, 5));
        pages.allocate(1, &[key], &windows(&layout));
        let xy = DVec2::new(3.0 * 128.0 + 10.25, 5.0 * 128.0 + 100.5);
        let texel = resolve_texel(&pages, &levels(), xy, 8.0, 4).expect("resident");
        assert_eq!((texel.level, texel.physical), (0, 0));
        // Tile (0, 0): x inside the page, the row counted from the page's top (largest y).
        assert_eq!(texel.atlas, DVec2::new(10.25, 128.0 - 100.5));
    }

    #[test]
    fn an_overflowed_page_falls_back_to_the_coarser_level() {
        let layout = PageLayout::new(4096, 128).unwrap();
        let mut pages = VirtualPages::new(layout, 2, 1);
        let fine = PageKey::new(0, I64Vec2::new(3, 5));
        let coarse = PageKey::new(1, I64Vec2::new(1, 2));
        let a = pages.allocate(1, &[coarse, fine], &windows(&layout));
        assert_eq!(a.overflowed, vec![fine], "the pool holds one page");
        let xy = DVec2::new(3.0 * 128.0 + 10.0, 5.0 * 128.0 + 10.0);
        let texel = resolve_texel(&pages, &levels(), xy, 8.0, 4).expect("the coarse page");
        assert_eq!((texel.level, texel.physical), (1, 0));
        assert_eq!(
            resolve_texel(&pages, &levels(), DVec2::splat(-3000.0), 8.0, 4),
            None,
            "no resident page"
        );
        assert_eq!(
            resolve_texel(&pages, &levels(), DVec2::splat(1e6), 8.0, 4),
            None,
            "outside every level"
        );
    }
}
