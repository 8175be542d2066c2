use glam::{DVec2, I64Vec2};
use proptest::prelude::*;

use super::*;

fn layout() -> PageLayout {
    PageLayout::new(4096, 128).unwrap()
}

/// The pages of `level` within `radius` pages of the window's centre (what receivers around
/// the camera would mark), sorted.
fn around(level: u32, window: &PageRect, radius: i64) -> Vec<PageKey> {
    let centre = (window.min + window.max) / 2;
    let near = PageRect {
        min: centre - I64Vec2::splat(radius),
        max: centre + I64Vec2::splat(radius),
    };
    let mut keys: Vec<_> = near.pages().map(|p| PageKey::new(level, p)).collect();
    keys.sort();
    keys
}

/// Every mapped entry names a physical page that names it back, and no physical page is
/// mapped twice.
fn consistent(pages: &VirtualPages) -> Result<(), String> {
    let mut owners = vec![None; pages.pool.len()];
    for (level, table) in pages.tables.iter().enumerate() {
        for (entry, e) in table.iter().enumerate() {
            let Some(e) = e else { continue };
            if pages.layout.entry(e.page) != entry {
                return Err(format!(
                    "level {level} entry {entry} holds page {} of another entry",
                    e.page
                ));
            }
            if owners[e.physical as usize]
                .replace((level as u32, entry as u32))
                .is_some()
            {
                return Err(format!("physical page {} is mapped twice", e.physical));
            }
        }
    }
    for (p, page) in pages.pool.iter().enumerate() {
        if page.owner != owners[p] {
            return Err(format!(
                "physical page {p} names {:?}, the tables {:?}",
                page.owner, owners[p]
            ));
        }
    }
    Ok(())
}

#[test]
fn a_layout_out_of_range_is_refused_with_what_is_expected() {
    assert_eq!(
        PageLayout::new(3000, 128).unwrap_err().to_string(),
        "virtual_resolution 3000 must be a power of two from 4096 to 16384"
    );
    assert_eq!(
        PageLayout::new(32768, 128).unwrap_err().to_string(),
        "virtual_resolution 32768 must be a power of two from 4096 to 16384"
    );
    assert_eq!(
        PageLayout::new(8192, 100).unwrap_err().to_string(),
        "page_size 100 must be 64, 128, 256 or 512"
    );
    let l = PageLayout::new(16384, 128).unwrap();
    assert_eq!((l.pages_per_side(), l.entries()), (128, 16384));
}

#[test]
fn a_footprint_covers_the_pages_its_filter_reads() {
    let l = layout();
    let inside = l.footprint(DVec2::new(64.5, 64.5), 3.0);
    assert_eq!(
        inside.pages().count(),
        1,
        "a small filter inside a page reads that page"
    );
    let corner = l.footprint(DVec2::new(127.5, 127.5), 3.0);
    assert_eq!(
        (corner.min, corner.max),
        (I64Vec2::ZERO, I64Vec2::ONE),
        "a filter at a corner reads four"
    );
    let below = l.footprint(DVec2::new(-0.5, 5.0), 0.0);
    assert_eq!(below.min, I64Vec2::new(-1, 0), "negative texels lie in negative pages");
}

#[test]
fn a_still_frame_draws_no_page() {
    let l = layout();
    let mut pages = VirtualPages::new(l, 1, 64);
    let window = [l.window(I64Vec2::ZERO)];
    let needed = around(0, &window[0], 2);
    let first = pages.allocate(1, &needed, &window);
    assert_eq!((first.draw.len(), first.kept), (25, 0));
    for &(_, p) in &first.draw {
        pages.mark_drawn(p);
    }
    let second = pages.allocate(2, &needed, &window);
    assert_eq!((second.draw.len(), second.kept), (0, 25), "{second:?}");
    assert!(second.evicted.is_empty() && second.overflowed.is_empty());
}

#[test]
fn a_full_pool_evicts_the_least_recently_needed_pages() {
    let l = layout();
    let mut pages = VirtualPages::new(l, 1, 4);
    let window = [l.window(I64Vec2::ZERO)];
    let key = |x, y| PageKey::new(0, I64Vec2::new(x, y));
    // Frame 1 needs a and b, frame 2 c and d: the pool is full.
    pages.allocate(1, &[key(0, 0), key(1, 0)], &window);
    pages.allocate(2, &[key(2, 0), key(3, 0)], &window);
    let third = pages.allocate(3, &[key(2, 0), key(4, 0)], &window);
    assert_eq!(
        third.evicted,
        vec![key(0, 0)],
        "the page last needed longest ago goes first"
    );
    assert_eq!(third.overflowed, vec![]);
    assert_eq!(pages.lookup(key(4, 0)), Some(0), "it takes the evicted page's place");
    assert_eq!(pages.lookup(key(0, 0)), None);
    assert_eq!(pages.lookup(key(1, 0)), Some(1), "the rest stay resident");
    consistent(&pages).unwrap();
}

#[test]
fn pages_past_the_pool_overflow_and_are_reported() {
    let l = layout();
    let mut pages = VirtualPages::new(l, 2, 6);
    let windows = [l.window(I64Vec2::ZERO), l.window(I64Vec2::ZERO)];
    let mut needed = around(0, &windows[0], 1);
    needed.extend([PageKey::new(1, I64Vec2::new(16, 16))]);
    let a = pages.allocate(1, &needed, &windows);
    assert_eq!(a.draw.len(), 6);
    assert_eq!(a.overflowed.len(), 4, "10 pages needed, 6 in the pool: {a:?}");
    assert!(a.evicted.is_empty(), "no page needed this frame is evicted");
    for key in &a.overflowed {
        assert_eq!(pages.lookup(*key), None, "an overflowed page reads as not resident");
    }
    consistent(&pages).unwrap();
}

#[test]
fn a_moving_window_keeps_the_pages_it_still_covers_and_frees_the_rest() {
    let l = layout();
    let mut pages = VirtualPages::new(l, 1, 4096);
    let before = [l.window(I64Vec2::ZERO)];
    let all: Vec<_> = before[0].pages().map(|p| PageKey::new(0, p)).collect();
    for &(_, p) in &pages.allocate(1, &all, &before).draw {
        pages.mark_drawn(p);
    }
    // One page right and two down.
    let after = [l.window(I64Vec2::new(128, -256))];
    let mut now: Vec<_> = after[0].pages().map(|p| PageKey::new(0, p)).collect();
    now.sort();
    let a = pages.allocate(2, &now, &after);
    let n = l.pages_per_side();
    assert_eq!(a.kept, (n - 1) * (n - 2), "the pages both windows cover stay");
    assert_eq!(
        a.draw.len() as u32,
        n * n - (n - 1) * (n - 2),
        "only the newly covered pages are drawn"
    );
    assert!(a.evicted.is_empty() && a.overflowed.is_empty());
    consistent(&pages).unwrap();
}

#[test]
fn invalidating_a_caster_redraws_only_its_pages() {
    let l = layout();
    let mut pages = VirtualPages::new(l, 1, 64);
    let window = [l.window(I64Vec2::ZERO)];
    let needed = around(0, &window[0], 2);
    for &(_, p) in &pages.allocate(1, &needed, &window).draw {
        pages.mark_drawn(p);
    }
    let centre = (window[0].min + window[0].max) / 2;
    let caster = PageRect {
        min: centre,
        max: centre + I64Vec2::X,
    };
    assert_eq!(pages.invalidate(0, &caster), 2);
    let a = pages.allocate(2, &needed, &window);
    assert_eq!(a.draw.len(), 2);
    assert!(a.draw.iter().all(|(k, _)| caster.contains(k.grid())));
    assert_eq!(pages.invalidate_all(), 23, "the light turning redraws every drawn page");
}

#[test]
fn a_window_snaps_to_whole_pages_around_its_centre() {
    let l = layout();
    for centre in [
        DVec2::new(0.0, 0.0),
        DVec2::new(-1000.3, 77.9),
        DVec2::new(1e6 + 0.5, -3e5),
    ] {
        let first = snap_to_pages(centre, &l);
        assert_eq!(first % 128, I64Vec2::ZERO, "{centre}: {first}");
        let middle = first.as_dvec2() + DVec2::splat(2048.0);
        assert!(
            (middle - centre).abs().max_element() <= 64.0,
            "{centre}: window centred at {middle}"
        );
    }
}

proptest! {
    #[test]
    fn a_windows_pages_have_distinct_entries(x in -1_000_000i64..1_000_000, y in -1_000_000i64..1_000_000) {
        let l = layout();
        let window = l.window(I64Vec2::new(x, y) * 128);
        let mut seen = vec![false; l.entries()];
        for page in window.pages() {
            let e = l.entry(page);
            prop_assert!(!seen[e], "entry {} twice", e);
            seen[e] = true;
        }
        prop_assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn a_walk_keeps_the_tables_and_pool_consistent(
        steps in prop::collection::vec((-3i64..=3, -3i64..=3, 0i64..=6), 1..12),
        pool in 8u32..200,
    ) {
        let l = layout();
        let mut pages = VirtualPages::new(l, 2, pool);
        let mut first = I64Vec2::ZERO;
        for (frame, (dx, dy, radius)) in steps.into_iter().enumerate() {
            first += I64Vec2::new(dx, dy) * 128;
            let windows = [l.window(first), l.window(first / 2 / 128 * 128)];
            let mut needed = around(0, &windows[0], radius);
            needed.extend(around(1, &windows[1], radius / 2));
            let a = pages.allocate(frame as u64 + 1, &needed, &windows);
            for &(_, p) in &a.draw {
                pages.mark_drawn(p);
            }
            consistent(&pages).map_err(TestCaseError::fail)?;
            let served = a.kept as usize + a.draw.len() + a.overflowed.len();
            prop_assert_eq!(served, needed.len(), "every needed page is kept, drawn or overflowed");
            prop_assert!(a.overflowed.is_empty() || pages.pool.iter().all(|p| p.last_needed == frame as u64 + 1),
                "a page overflowed while a page not needed this frame stayed resident");
            for key in &needed {
                let resident = pages.lookup(*key).is_some();
                prop_assert_eq!(resident, !a.overflowed.contains(key));
            }
        }
    }
}

/// Three levels of 1, 2 and 4 m texels, the finest starting at the grid's origin.
fn nested_levels() -> [PagedLevel; 3] {
    let level = |first: i64, texel: f64| PagedLevel {
        first_texel: I64Vec2::splat(first),
        texel,
    };
    [level(0, 1.0), level(-2048, 2.0), level(-2048, 4.0)]
}

#[test]
fn a_receiver_marks_its_level_the_next_inside_the_band_and_the_coarsest() {
    let l = layout();
    let levels = nested_levels();
    let rule = MarkRule {
        radius: 4.0,
        margin: 8.0,
        blend: 0.1,
        pixel: 0.0,
    };
    let mut out = Vec::new();
    mark_receiver(&l, &levels, (DVec2::splat(2112.0), 1.0), &rule, &mut out);
    assert_eq!(
        out,
        vec![PageKey::new(0, I64Vec2::splat(16)), PageKey::new(2, I64Vec2::splat(4))],
        "the middle of level 0 reads one page there, and the coarsest level's"
    );
    out.clear();
    // 20 texels inside level 0's margin: inside its band (0.1 of 2048), so level 1 is read too.
    mark_receiver(&l, &levels, (DVec2::new(28.0, 2112.0), 1.0), &rule, &mut out);
    let levels_read: Vec<u32> = out.iter().map(|k| k.level).collect();
    assert_eq!(levels_read, [0, 1, 2], "{out:?}");
    out.clear();
    // Inside level 0's margin: level 1 serves it (and the coarsest level).
    mark_receiver(&l, &levels, (DVec2::new(4.0, 2112.0), 1.0), &rule, &mut out);
    let mut levels_read: Vec<u32> = out.iter().map(|k| k.level).collect();
    levels_read.dedup();
    assert_eq!(levels_read, [1, 2], "{out:?}");
    out.clear();
    mark_receiver(&l, &levels, (DVec2::splat(1e6), 1.0), &rule, &mut out);
    assert!(out.is_empty(), "outside every level nothing is read");
}

#[test]
fn a_receiver_reads_no_level_finer_than_its_pixel() {
    let l = PageLayout::new(4096, 128).unwrap();
    let levels = &nested_levels()[..2];
    let rule = MarkRule {
        radius: 4.0,
        margin: 8.0,
        blend: 0.0,
        pixel: 0.01,
    };
    // 1 m texels serve pixels up to 1 m: view depth 100 m.
    assert_eq!(density_level(levels, 100.0, &rule), 0);
    assert_eq!(density_level(levels, 150.0, &rule), 1);
    assert_eq!(
        density_level(levels, 1e6, &rule),
        1,
        "the coarsest when none is coarse enough"
    );
    let mut out = Vec::new();
    mark_receiver(&l, levels, (DVec2::splat(2112.0), 150.0), &rule, &mut out);
    assert_eq!(
        out,
        vec![PageKey::new(1, I64Vec2::splat(8))],
        "level 1's page, not level 0's"
    );
}
