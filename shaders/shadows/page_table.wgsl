// A paged clipmap's page table (penumbra::math::pages, penumbra::math::page_sampling): each
// level is a virtual texture of `side` texels a side cut into pages; its resident pages lie
// side by side in `page_atlas` (physical page p at tile (p mod tiles, p / tiles), upright),
// and `page_table` maps a grid page to its physical page. A filter's tap at a level's UV goes
// through `page_uv`; a receiver checks first that every page its filter reads is resident
// (`footprint_resident`).
#define_import_path penumbra::shadows::page_table

#import penumbra::contract::PAGE_NONE
#import penumbra::shadows::bindings::{page_atlas, page_table}

// The atlas UV of the texel at UV `uv` of a paged level, clamped half a texel inside its page
// (a bilinear tap never reads a neighbouring tile), or (-1, -1) when its page is not
// resident. `page`: xy the grid page of the window's first page, z the page side in texels;
// `level`: the level's place in the table; `texel`: 1 / the level's side in texels.
fn page_uv(page: vec4<f32>, level: u32, texel: f32, uv: vec2<f32>) -> vec2<f32> {
    return page_uv_inset(page, level, texel, uv, 0.5);
}

// `page_uv` clamped `inset` texels of the level inside the page: half a texel of the mip
// level a bilinear tap reads (2^lod / 2) keeps it within the page's tile there.
fn page_uv_inset(page: vec4<f32>, level: u32, texel: f32, uv: vec2<f32>, inset: f32) -> vec2<f32> {
    let side = round(1.0 / texel);
    let size = page.z;
    let n = side / size;
    // Texels from the window's first texel: x along the light frame's x, y up its y.
    let t = vec2<f32>(uv.x, 1.0 - uv.y) * side;
    let local = clamp(floor(t / size), vec2<f32>(0.0), vec2<f32>(n - 1.0));
    let grid = page.xy + local;
    let wrapped = grid - n * floor(grid / n);
    let count = u32(n);
    let entry = page_table[level * count * count + u32(wrapped.y) * count + u32(wrapped.x)];
    let held = vec2<i32>(entry.page_x, entry.page_y) == vec2<i32>(grid);
    if entry.physical == PAGE_NONE || !all(held) {
        return vec2<f32>(-1.0);
    }
    let atlas = f32(textureDimensions(page_atlas).x);
    let tiles = u32(atlas / size);
    let tile = vec2<f32>(f32(entry.physical % tiles), f32(entry.physical / tiles));
    let inside = clamp(t - local * size, vec2<f32>(inset), vec2<f32>(size - inset));
    return vec2<f32>(tile.x * size + inside.x, tile.y * size + size - inside.y) / atlas;
}

// Whether the pages a filter reads within `reach` (level UV) of `uv` are resident: the pages
// of the footprint's four corners and its centre, which are all the pages it overlaps while
// it is at most a page wide (128² pages and larger; with 64² pages PCSS's widest footprint
// may also touch the pages beside an edge's middle, whose taps read lit if those are missing).
//
// NOTE: five lookups, not a loop over a grid: a loop here, in the code of every light, made
// lavapipe's loop limiter stop the light loop of frames with thousands of lights.
fn footprint_resident(page: vec4<f32>, level: u32, texel: f32, uv: vec2<f32>, reach: f32) -> bool {
    let lo = page_uv(page, level, texel, uv - vec2<f32>(reach)).x;
    let hi = page_uv(page, level, texel, uv + vec2<f32>(reach)).x;
    let a = page_uv(page, level, texel, uv + vec2<f32>(reach, -reach)).x;
    let b = page_uv(page, level, texel, uv + vec2<f32>(-reach, reach)).x;
    let centre = page_uv(page, level, texel, uv).x;
    return min(min(min(lo, hi), min(a, b)), centre) >= 0.0;
}
