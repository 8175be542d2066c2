// Allocates the physical pages of a paged clipmap for one frame, on the GPU, by the rules of
// `math::pages` (its `VirtualPages::allocate` is the mirror the tests compare with). One
// workgroup of 256 threads, in four phases separated by barriers:
//   1. pages whose table entry left its level's window are freed;
//   2. every needed page (a bit of `needed`, coarsest level first, then in table-entry
//      order, so an overflow leaves the coarse levels a fine level falls back to) that is
//      resident is kept (stamped with the frame; listed for drawing if it was invalidated),
//      and the others are counted: each thread takes a run of entries (whole words of the
//      bitset, skipping a word with no bit set), and a prefix sum gives every missing page
//      its rank;
//   3. the pool is ordered: free pages (lowest first), then pages not needed this frame, the
//      longest unneeded first (age capped at `max_age` frames), lowest first among equals —
//      as far as the missing pages need;
//   4. the missing page of rank r takes the r-th page of that order (evicting it from its
//      entry if it held one), or overflows when the order is shorter.
// The draw list holds the pages to draw this frame (their `drawn` flag is set: they are
// drawn in the same frame).

const NONE: u32 = 0xffffffffu;
const THREADS: u32 = 256u;
const MAX_LEVELS: u32 = 8u;

struct Params {
    frame: u32,
    levels: u32,
    // Pages per side of a level (its table is n² entries).
    pages_per_side: u32,
    pool_pages: u32,
    max_age: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    // Per level: xy the grid page of its window's first page.
    windows: array<vec4<i32>, MAX_LEVELS>,
}

struct Entry {
    physical: u32,
    page_x: i32,
    page_y: i32,
    _pad: u32,
}

struct Page {
    // level << 24 | table entry, or NONE.
    owner: u32,
    last_needed: u32,
    drawn: u32,
    _pad: u32,
}

struct Counters {
    kept: atomic<u32>,
    draws: atomic<u32>,
    evicted: atomic<u32>,
    overflowed: atomic<u32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> needed: array<u32>;
@group(0) @binding(2) var<storage, read_write> table: array<Entry>;
@group(0) @binding(3) var<storage, read_write> pool: array<Page>;
@group(0) @binding(4) var<storage, read_write> order: array<u32>;
@group(0) @binding(5) var<storage, read_write> counters: Counters;
// Per page drawn: (level << 24 | entry, physical page).
@group(0) @binding(6) var<storage, read_write> draws: array<vec2<u32>>;

var<workgroup> sums: array<u32, THREADS>;
// 1 once the pool's order holds a page for every missing page (phase 3 stops there).
var<workgroup> ordered_enough: u32;

// Exclusive prefix sum of `value` over the workgroup, and the total (x, y). Called by every
// thread.
fn scan(tid: u32, value: u32) -> vec2<u32> {
    sums[tid] = value;
    workgroupBarrier();
    for (var offset = 1u; offset < THREADS; offset <<= 1u) {
        var add = 0u;
        if tid >= offset {
            add = sums[tid - offset];
        }
        workgroupBarrier();
        sums[tid] += add;
        workgroupBarrier();
    }
    let result = vec2<u32>(sums[tid] - value, sums[THREADS - 1u]);
    workgroupBarrier();
    return result;
}

fn entries_per_level() -> u32 {
    return params.pages_per_side * params.pages_per_side;
}

// The grid page of `level`'s window that lives at table entry `entry`.
fn entry_page(level: u32, entry: u32) -> vec2<i32> {
    let n = i32(params.pages_per_side);
    let first = params.windows[level].xy;
    let at = vec2<i32>(i32(entry % params.pages_per_side), i32(entry / params.pages_per_side));
    return first + ((at - first) % n + n) % n;
}

fn inside_window(level: u32, page: vec2<i32>) -> bool {
    let first = params.windows[level].xy;
    let last = first + vec2<i32>(i32(params.pages_per_side) - 1);
    return level < params.levels && all(page >= first) && all(page <= last);
}

fn is_needed(index: u32) -> bool {
    return ((needed[index >> 5u] >> (index & 31u)) & 1u) != 0u;
}

// Whether needed entry `index` holds its page.
fn resident(index: u32, page: vec2<i32>) -> bool {
    let e = table[index];
    return e.physical != NONE && e.page_x == page.x && e.page_y == page.y;
}

// What entry `index` asks for this frame: 0 nothing (not needed), 1 its page, which is
// resident, 2 its page, which is missing.
fn state(index: u32) -> u32 {
    if !is_needed(index) {
        return 0u;
    }
    let per_level = entries_per_level();
    let page = entry_page(index / per_level, index % per_level);
    return select(2u, 1u, resident(index, page));
}

fn add_draw(key: u32, physical: u32) {
    pool[physical].drawn = 1u;
    let at = atomicAdd(&counters.draws, 1u);
    draws[at] = vec2<u32>(key, physical);
}

// The table index of the `q`-th needed candidate: the coarsest level's entries first.
fn candidate(q: u32) -> u32 {
    let per_level = entries_per_level();
    return (params.levels - 1u - q / per_level) * per_level + q % per_level;
}

// The run [start, end) of `total` items thread `tid` takes.
fn run(tid: u32, total: u32) -> vec2<u32> {
    let size = (total + THREADS - 1u) / THREADS;
    return vec2<u32>(min(tid * size, total), min((tid + 1u) * size, total));
}

// The run [start, end) of the `total` needed candidates thread `tid` takes: whole words of
// the bitset (a level's table is a multiple of 32 entries), so a thread skips a word with no
// bit set at once.
fn candidate_run(tid: u32, total: u32) -> vec2<u32> {
    let size = ((total + THREADS - 1u) / THREADS + 31u) / 32u * 32u;
    return vec2<u32>(min(tid * size, total), min((tid + 1u) * size, total));
}

// Whether candidate table index `i` starts a word of the bitset with no bit set.
fn empty_word(i: u32) -> bool {
    return (i & 31u) == 0u && needed[i >> 5u] == 0u;
}

// Age class of pool page `p` (0: not a candidate for eviction).
fn age(p: u32) -> u32 {
    let page = pool[p];
    if page.owner == NONE || page.last_needed >= params.frame {
        return 0u;
    }
    return min(params.frame - page.last_needed, params.max_age);
}

@compute @workgroup_size(256)
fn main(@builtin(local_invocation_index) tid: u32) {
    let per_level = entries_per_level();
    // 1. Free the pages whose entry left its window.
    for (var p = tid; p < params.pool_pages; p += THREADS) {
        let owner = pool[p].owner;
        if owner != NONE {
            let level = owner >> 24u;
            let index = level * per_level + (owner & 0xffffffu);
            let e = table[index];
            if !inside_window(level, vec2<i32>(e.page_x, e.page_y)) {
                table[index].physical = NONE;
                pool[p].owner = NONE;
                pool[p].drawn = 0u;
            }
        }
    }
    storageBarrier();
    workgroupBarrier();
    // 2. Keep the resident needed pages; count the missing ones.
    let total = params.levels * per_level;
    let mine = candidate_run(tid, total);
    var missing = 0u;
    for (var q = mine.x; q < mine.y; q++) {
        let i = candidate(q);
        if empty_word(i) {
            q += 31u;
            continue;
        }
        let wanted = state(i);
        if wanted == 1u {
            let p = table[i].physical;
            pool[p].last_needed = params.frame;
            if pool[p].drawn == 0u {
                add_draw((i / per_level) << 24u | (i % per_level), p);
            } else {
                atomicAdd(&counters.kept, 1u);
            }
        }
        missing += u32(wanted == 2u);
    }
    let ranked = scan(tid, missing);
    let rank = ranked.x;
    storageBarrier();
    workgroupBarrier();
    // 3. Order the pool: free pages, then the candidates for eviction, oldest first.
    let pages = run(tid, params.pool_pages);
    var free = 0u;
    for (var p = pages.x; p < pages.y; p++) {
        free += u32(pool[p].owner == NONE);
    }
    let free_scan = scan(tid, free);
    var at = free_scan.x;
    for (var p = pages.x; p < pages.y; p++) {
        if pool[p].owner == NONE {
            order[at] = p;
            at += 1u;
        }
    }
    var ordered = free_scan.y;
    for (var a = params.max_age; a >= 1u; a--) {
        // NOTE: every thread holds the same totals; the order past the missing pages' count
        // is never read, so a frame with enough free pages (a still frame) sorts no age.
        if tid == 0u {
            ordered_enough = u32(ordered >= ranked.y);
        }
        if workgroupUniformLoad(&ordered_enough) != 0u {
            break;
        }
        var count = 0u;
        for (var p = pages.x; p < pages.y; p++) {
            count += u32(age(p) == a);
        }
        let s = scan(tid, count);
        var k = ordered + s.x;
        for (var p = pages.x; p < pages.y; p++) {
            if age(p) == a {
                order[k] = p;
                k += 1u;
            }
        }
        ordered += s.y;
    }
    storageBarrier();
    workgroupBarrier();
    // 4. Map each missing page to the page of its rank in the order.
    var r = rank;
    for (var q = mine.x; q < mine.y; q++) {
        let i = candidate(q);
        if empty_word(i) {
            q += 31u;
            continue;
        }
        if state(i) != 2u {
            continue;
        }
        let level = i / per_level;
        let page = entry_page(level, i % per_level);
        if r >= ordered {
            atomicAdd(&counters.overflowed, 1u);
            r += 1u;
            continue;
        }
        let p = order[r];
        r += 1u;
        let old = pool[p].owner;
        if old != NONE {
            table[(old >> 24u) * per_level + (old & 0xffffffu)].physical = NONE;
            atomicAdd(&counters.evicted, 1u);
        }
        let key = level << 24u | (i % per_level);
        table[i] = Entry(p, page.x, page.y, 0u);
        pool[p] = Page(key, params.frame, 0u, 0u);
        add_draw(key, p);
    }
}

// A frame whose marking and allocation would repeat the last one's (the pages node skips
// them): its counters are the last frame's, every page drawn then kept now, none evicted.
@compute @workgroup_size(1)
fn still() {
    let drawn = atomicExchange(&counters.draws, 0u);
    atomicAdd(&counters.kept, drawn);
    atomicStore(&counters.evicted, 0u);
}

// Invalidation, before the allocation: the drawn pages a moving caster's old or new bounds
// reach (rectangles of grid pages of one level each), or every page when the light turned,
// are marked for drawing again; their residency stays.
const MAX_INVALIDATIONS: u32 = 64u;

struct Invalidations {
    count: u32,
    all: u32,
    _pad0: u32,
    _pad1: u32,
    // Per rectangle: the smallest and largest grid page (both included).
    rects: array<vec4<i32>, MAX_INVALIDATIONS>,
    // The level of rectangle i: levels[i / 4][i % 4].
    levels: array<vec4<u32>, 16>,
}

@group(0) @binding(7) var<uniform> invalidations: Invalidations;

@compute @workgroup_size(64)
fn invalidate(@builtin(global_invocation_id) id: vec3<u32>) {
    let p = id.x;
    if p >= params.pool_pages || pool[p].owner == NONE {
        return;
    }
    let owner = pool[p].owner;
    let level = owner >> 24u;
    let e = table[level * entries_per_level() + (owner & 0xffffffu)];
    var hit = invalidations.all != 0u;
    for (var i = 0u; i < min(invalidations.count, MAX_INVALIDATIONS); i++) {
        let r = invalidations.rects[i];
        let same = invalidations.levels[i / 4u][i % 4u] == level;
        hit = hit || (same && e.page_x >= r.x && e.page_y >= r.y && e.page_x <= r.z && e.page_y <= r.w);
    }
    if hit {
        pool[p].drawn = 0u;
    }
}
