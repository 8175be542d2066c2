//! Virtual shadow pages: each clipmap level made a virtual texture of
//! [`PageLayout::virtual_resolution`]² texels cut into square pages of
//! [`PageLayout::page_size`]², of which only the pages some pixel samples are given memory in
//! a shared pool of physical pages. Pure math: the rules the GPU's mark and allocate passes
//! follow, and the mirror the tests compare them with.
//!
//! A level's window starts on a whole page of its grid ([`snap_to_pages`]), so it covers
//! exactly `n = virtual_resolution / page_size` pages a side and its page table is addressed
//! toroidally: grid page `(x, y)` lives at entry `(x mod n, y mod n)`
//! ([`PageLayout::entry`]). A window that moves keeps the entries of the pages it still covers;
//! an entry whose page left the window holds a page no receiver asks for, and is reclaimed.
//!
//! Each frame: the pages a receiver's filter reads are marked ([`mark_receiver`]);
//! [`VirtualPages::allocate`] keeps the marked pages that are resident, maps the others to
//! free physical pages, evicts the least recently needed pages only when none is free, and
//! reports the pages it could not map (overflow: their receivers read a coarser level);
//! [`VirtualPages::invalidate`] marks the resident pages a moving caster touched for redrawing.

use glam::{DVec2, I64Vec2};

/// Smallest virtual side of a level, texels.
pub const MIN_VIRTUAL_RESOLUTION: u32 = 4096;
/// Largest virtual side of a level, texels.
pub const MAX_VIRTUAL_RESOLUTION: u32 = 16384;
/// Page sides accepted, texels.
pub const PAGE_SIZES: [u32; 4] = [64, 128, 256, 512];
/// Frames of not being needed past which pages count as equally old when the pool chooses
/// which to evict.
pub const MAX_PAGE_AGE: u64 = 63;

/// How a level's virtual texture is cut into pages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PageLayout {
    /// Texels per side of a level.
    pub virtual_resolution: u32,
    /// Texels per side of a page.
    pub page_size: u32,
}

/// What is wrong with a page layout.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum PageLayoutError {
    /// The virtual side is out of range or not a power of two.
    #[error("virtual_resolution {0} must be a power of two from 4096 to 16384")]
    VirtualResolution(u32),
    /// The page side is not one of [`PAGE_SIZES`].
    #[error("page_size {0} must be 64, 128, 256 or 512")]
    PageSize(u32),
}

impl PageLayout {
    /// A layout, checked.
    pub fn new(virtual_resolution: u32, page_size: u32) -> Result<Self, PageLayoutError> {
        let range = MIN_VIRTUAL_RESOLUTION..=MAX_VIRTUAL_RESOLUTION;
        if !range.contains(&virtual_resolution) || !virtual_resolution.is_power_of_two() {
            return Err(PageLayoutError::VirtualResolution(virtual_resolution));
        }
        if !PAGE_SIZES.contains(&page_size) {
            return Err(PageLayoutError::PageSize(page_size));
        }
        Ok(Self {
            virtual_resolution,
            page_size,
        })
    }

    /// Pages per side of a level.
    pub fn pages_per_side(&self) -> u32 {
        self.virtual_resolution / self.page_size
    }

    /// Entries of a level's page table.
    pub fn entries(&self) -> usize {
        (self.pages_per_side() as usize).pow(2)
    }

    /// The grid page holding grid texel `texel`.
    pub fn page_of(&self, texel: I64Vec2) -> I64Vec2 {
        texel.div_euclid(I64Vec2::splat(i64::from(self.page_size)))
    }

    /// The table entry of grid page `page`: `(x mod n, y mod n)`, rows of `n`.
    pub fn entry(&self, page: I64Vec2) -> usize {
        let n = i64::from(self.pages_per_side());
        (page.y.rem_euclid(n) * n + page.x.rem_euclid(n)) as usize
    }

    /// The pages a filter reading every texel within `radius` texels of grid position `at`
    /// (in texels, continuous) touches.
    pub fn footprint(&self, at: DVec2, radius: f64) -> PageRect {
        let lo = (at - DVec2::splat(radius)).floor().as_i64vec2();
        let hi = (at + DVec2::splat(radius)).floor().as_i64vec2();
        PageRect {
            min: self.page_of(lo),
            max: self.page_of(hi),
        }
    }

    /// The pages of a window whose first texel is `first_texel` (a whole page).
    pub fn window(&self, first_texel: I64Vec2) -> PageRect {
        let min = self.page_of(first_texel);
        PageRect {
            min,
            max: min + I64Vec2::splat(i64::from(self.pages_per_side()) - 1),
        }
    }
}

/// Tiles per side of the square atlas that holds a pool of `pool_pages` pages.
pub fn atlas_tiles(pool_pages: u32) -> u32 {
    (f64::from(pool_pages).sqrt().ceil() as u32).max(1)
}

/// The first texel of a window of `resolution` texels centred as near as it can be on grid
/// position `centre` (texels) while starting on a whole page.
pub fn snap_to_pages(centre: DVec2, layout: &PageLayout) -> I64Vec2 {
    let page = f64::from(layout.page_size);
    let half = f64::from(layout.virtual_resolution) / 2.0;
    ((centre - DVec2::splat(half)) / page).round().as_i64vec2() * i64::from(layout.page_size)
}

/// A paged level's window: where it starts on the grid and how wide its texels are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PagedLevel {
    /// Grid texel of the window's first texel (a whole page).
    pub first_texel: I64Vec2,
    /// Side of a texel, metres.
    pub texel: f64,
}

/// How receivers mark the pages they read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarkRule {
    /// Texels a receiver's filter reads around it (PCF radius, PCSS search, moment blur).
    pub radius: f64,
    /// Texels a level's window keeps clear of its edge for the receivers it serves
    /// (at least `radius`).
    pub margin: f64,
    /// Band of a window's half side, along the inner edge of the margin, where a receiver
    /// also reads the next level (it blends into it).
    pub blend: f64,
    /// The smallest texel a receiver reads, metres per metre of its view depth (a pixel's
    /// width at that depth): a receiver reads no level finer than its pixel. 0: any level.
    pub pixel: f64,
}

/// The width of a pixel per metre of view depth for a camera of `clip_from_world` (a
/// perspective projection) seen in an image `height` pixels tall.
pub fn pixel_per_depth(clip_from_world: glam::Mat4, height: u32) -> f64 {
    // NOTE: the clip matrix's y row is the view's y axis scaled by cot(fov / 2).
    let cot = f64::from(clip_from_world.row(1).truncate().length());
    2.0 / (cot * f64::from(height.max(1))).max(1e-30)
}

/// The first level a receiver at view depth `view_depth` may read under `rule`: the finest
/// whose texel is at least its pixel (the last when none is).
pub fn density_level(levels: &[PagedLevel], view_depth: f64, rule: &MarkRule) -> usize {
    let pixel = view_depth * rule.pixel;
    let coarse = levels.len().saturating_sub(1);
    levels.iter().position(|l| l.texel >= pixel).unwrap_or(coarse)
}

/// Appends the pages a receiver at light-frame `xy` and view depth `view_depth` reads to
/// `out`: its filter's footprint in the finest level, from its [`density_level`] on, whose
/// window holds it with the rule's margin, in the next level too inside the blend band, and
/// in the coarsest level (what the pool serves first, so a receiver whose own pages
/// overflowed it still reads a level). Nothing outside every level.
pub fn mark_receiver(
    layout: &PageLayout,
    levels: &[PagedLevel],
    (xy, view_depth): (DVec2, f64),
    rule: &MarkRule,
    out: &mut Vec<PageKey>,
) {
    let side = f64::from(layout.virtual_resolution);
    let first = density_level(levels, view_depth, rule);
    for (i, level) in levels.iter().enumerate().skip(first) {
        let lo = (level.first_texel.as_dvec2() + DVec2::splat(rule.margin)) * level.texel;
        let hi = (level.first_texel.as_dvec2() + DVec2::splat(side - rule.margin)) * level.texel;
        if xy.cmplt(lo).any() || xy.cmpgt(hi).any() {
            continue;
        }
        let mut footprint = |k: usize| {
            let at = xy / levels[k].texel;
            let pages = layout.footprint(at, rule.radius);
            out.extend(pages.pages().map(|p| PageKey::new(k as u32, p)));
        };
        footprint(i);
        let band = rule.blend * 0.5 * side * level.texel;
        let inside = (xy - lo).min(hi - xy).min_element();
        let blends = i + 1 < levels.len() && inside < band;
        if blends {
            footprint(i + 1);
        }
        // NOTE: the coarsest level too, which a pool that overflowed falls back to.
        let coarsest = levels.len() - 1;
        if coarsest > i + usize::from(blends) {
            footprint(coarsest);
        }
        return;
    }
}

/// A rectangle of grid pages, both corners included.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PageRect {
    /// The smallest page.
    pub min: I64Vec2,
    /// The largest page.
    pub max: I64Vec2,
}

impl PageRect {
    /// Whether it holds `page`.
    pub fn contains(&self, page: I64Vec2) -> bool {
        page.cmpge(self.min).all() && page.cmple(self.max).all()
    }

    /// The pages it shares with `other` (None when it shares none).
    pub fn intersect(&self, other: &PageRect) -> Option<PageRect> {
        let r = PageRect {
            min: self.min.max(other.min),
            max: self.max.min(other.max),
        };
        r.min.cmple(r.max).all().then_some(r)
    }

    /// Its pages, row by row.
    pub fn pages(&self) -> impl Iterator<Item = I64Vec2> + use<> {
        let (min, max) = (self.min, self.max);
        (min.y..=max.y).flat_map(move |y| (min.x..=max.x).map(move |x| I64Vec2::new(x, y)))
    }
}

/// A page a frame needs: its level and grid page.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct PageKey {
    /// The clipmap level.
    pub level: u32,
    /// The grid page (y then x order).
    pub page: (i64, i64),
}

impl PageKey {
    /// The key of grid page `page` of `level`.
    pub fn new(level: u32, page: I64Vec2) -> Self {
        Self {
            level,
            page: (page.y, page.x),
        }
    }

    /// Its grid page.
    pub fn grid(&self) -> I64Vec2 {
        I64Vec2::new(self.page.1, self.page.0)
    }
}

/// One entry of a level's page table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PageEntry {
    /// The grid page it maps.
    pub page: I64Vec2,
    /// Its physical page.
    pub physical: u32,
}

/// One page of the physical pool.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PhysicalPage {
    /// The level and table entry that map it (None: free).
    pub owner: Option<(u32, u32)>,
    /// The last frame a receiver needed it.
    pub last_needed: u64,
    /// Whether it holds its page's depth (drawn since it was mapped or invalidated).
    pub drawn: bool,
}

/// What [`VirtualPages::allocate`] did this frame.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Allocation {
    /// Needed pages already resident and drawn.
    pub kept: u32,
    /// Pages to draw this frame (newly mapped, or resident but invalidated), with their
    /// physical page, in the order needed.
    pub draw: Vec<(PageKey, u32)>,
    /// Pages evicted to make room (least recently needed first).
    pub evicted: Vec<PageKey>,
    /// Needed pages left unmapped: the pool held no page for them.
    pub overflowed: Vec<PageKey>,
}

/// Every level's page table and the physical pool.
#[derive(Clone, Debug, PartialEq)]
pub struct VirtualPages {
    /// How the levels are cut.
    pub layout: PageLayout,
    /// Per level, its table ([`PageLayout::entry`] order); None where no page is mapped.
    pub tables: Vec<Vec<Option<PageEntry>>>,
    /// The pool.
    pub pool: Vec<PhysicalPage>,
}

impl VirtualPages {
    /// Tables for `levels` levels and a pool of `pool_pages` pages, all free.
    pub fn new(layout: PageLayout, levels: u32, pool_pages: u32) -> Self {
        Self {
            layout,
            tables: vec![vec![None; layout.entries()]; levels as usize],
            pool: vec![PhysicalPage::default(); pool_pages as usize],
        }
    }

    /// The physical page holding `key` (None: not resident).
    pub fn lookup(&self, key: PageKey) -> Option<u32> {
        let table = self.tables.get(key.level as usize)?;
        let entry = table[self.layout.entry(key.grid())]?;
        (entry.page == key.grid()).then_some(entry.physical)
    }

    /// Frees the physical page `physical` and its table entry.
    fn free(&mut self, physical: u32) {
        if let Some((level, entry)) = self.pool[physical as usize].owner.take() {
            self.tables[level as usize][entry as usize] = None;
        }
        self.pool[physical as usize].drawn = false;
    }

    /// Serves frame `frame`'s `needed` pages (without repeats, in the order they are served:
    /// the GPU serves the coarsest level first, so that an overflow leaves the levels a finer
    /// one falls back to; those outside their level's window `windows[level]` are left out):
    /// keeps the resident ones, frees pages that left their window, maps the others, in the
    /// order given, to free pages (lowest first), evicting the least
    /// recently needed pages (ages past [`MAX_PAGE_AGE`] frames alike; ties: lowest physical
    /// page) when none is free; what still has no page overflows.
    pub fn allocate(&mut self, frame: u64, needed: &[PageKey], windows: &[PageRect]) -> Allocation {
        let mut out = Allocation::default();
        for physical in 0..self.pool.len() as u32 {
            let Some((level, entry)) = self.pool[physical as usize].owner else {
                continue;
            };
            let page = self.tables[level as usize][entry as usize].map(|e| e.page);
            let inside = windows
                .get(level as usize)
                .is_some_and(|w| page.is_some_and(|p| w.contains(p)));
            if !inside {
                self.free(physical);
            }
        }
        let mut missing = Vec::new();
        for &key in needed {
            // NOTE: a page outside its level's window would share an entry with one inside.
            if !windows.get(key.level as usize).is_some_and(|w| w.contains(key.grid())) {
                continue;
            }
            match self.lookup(key) {
                Some(physical) => {
                    let page = &mut self.pool[physical as usize];
                    page.last_needed = frame;
                    if page.drawn {
                        out.kept += 1;
                    } else {
                        out.draw.push((key, physical));
                    }
                }
                None => missing.push(key),
            }
        }
        let mut free: Vec<u32> = (0..self.pool.len() as u32)
            .filter(|&p| self.pool[p as usize].owner.is_none())
            .rev()
            .collect();
        // NOTE: the oldest first (ages past MAX_PAGE_AGE alike), the lowest among equals;
        // taken from the end.
        let age = |p: u32| (frame - self.pool[p as usize].last_needed).min(MAX_PAGE_AGE);
        let mut victims: Vec<u32> = (0..self.pool.len() as u32)
            .filter(|&p| {
                let page = &self.pool[p as usize];
                page.owner.is_some() && page.last_needed < frame
            })
            .collect();
        victims.sort_by_key(|&p| (age(p), std::cmp::Reverse(p)));
        for key in missing {
            let physical = match free.pop() {
                Some(p) => p,
                None => match victims.pop() {
                    Some(p) => {
                        let (level, entry) = self.pool[p as usize].owner.expect("a victim is mapped");
                        let page = self.tables[level as usize][entry as usize].expect("its entry").page;
                        out.evicted.push(PageKey::new(level, page));
                        self.free(p);
                        p
                    }
                    None => {
                        out.overflowed.push(key);
                        continue;
                    }
                },
            };
            let entry = self.layout.entry(key.grid());
            let table = &mut self.tables[key.level as usize];
            // NOTE: a window's pages have distinct entries, and an entry whose page left the
            // window was freed above.
            debug_assert!(table[entry].is_none(), "entry {entry} of level {} is taken", key.level);
            table[entry] = Some(PageEntry {
                page: key.grid(),
                physical,
            });
            self.pool[physical as usize] = PhysicalPage {
                owner: Some((key.level, entry as u32)),
                last_needed: frame,
                drawn: false,
            };
            out.draw.push((key, physical));
        }
        out
    }

    /// Marks physical page `physical` as holding its page's depth.
    pub fn mark_drawn(&mut self, physical: u32) {
        if let Some(page) = self.pool.get_mut(physical as usize) {
            page.drawn = page.owner.is_some();
        }
    }

    /// Marks every resident page of `level` inside `pages` for redrawing (a caster's old and
    /// new bounds); returns how many.
    pub fn invalidate(&mut self, level: u32, pages: &PageRect) -> u32 {
        let Some(table) = self.tables.get(level as usize) else {
            return 0;
        };
        let mut count = 0;
        for entry in table.iter().flatten() {
            if pages.contains(entry.page) {
                let page = &mut self.pool[entry.physical as usize];
                count += u32::from(page.drawn);
                page.drawn = false;
            }
        }
        count
    }

    /// Marks every resident page for redrawing (the light turned); returns how many.
    pub fn invalidate_all(&mut self) -> u32 {
        let mut count = 0;
        for page in &mut self.pool {
            count += u32::from(page.drawn);
            page.drawn = false;
        }
        count
    }
}

#[cfg(test)]
#[path = "pages_tests.rs"]
mod tests;
