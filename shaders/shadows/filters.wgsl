// Shadow-map filters, shared by every layout (cascades, spot lights): hardware comparison
// taps with receiver-plane depth, the PCF grid, rotated-Poisson PCF, and PCSS's blocker
// search and variable-width filter. Each takes the depth array to read and a `MapSample`:
// the receiver already projected into one view by its layout module.
//
// The PCSS sample counts are the shader defs of penumbra::shadows::common. A sample of a
// paged clipmap level reads every tap through the page table (`map_compare`, `map_gather`).
#define_import_path penumbra::shadows::filters

#import penumbra::contract::SHADOW_FLAG_BLOCKER_EARLY_OUT
#import penumbra::shadows::bindings::{
    page_atlas, shadow_compare, shadow_compare_wrap, shadow_point, shadow_point_wrap,
}
#import penumbra::shadows::page_table::page_uv
#import penumbra::shadows::types::Light
#import penumbra::shadows::common::{
    RECEIVER_PLANE_EPSILON_TEXELS, blocker_samples, blocker_tap, filter_tap, sixteen_tap,
}

// A receiver projected into one shadow view, in the UV space of the view's layer.
struct MapSample {
    uv: vec2<f32>,
    // Reverse-Z depth of the receiver in the view (1 near the light, 0 far).
    depth: f32,
    // Receiver-plane depth gradient: change of depth per unit of layer UV, clamped to the
    // layout's steepest slope.
    dz_duv: vec2<f32>,
    // The same gradient clamped only to MAX_TRUE_SLOPE, for PCSS (see `pcss_tap_depth`).
    dz_duv_true: vec2<f32>,
    layer: u32,
    // Step between PCF taps in layer UV along u and v: one texel, or less where a texel is
    // wider than MAX_FILTER_STEP_METRES.
    filter_step: vec2<f32>,
    // One texel, in layer UV.
    texel: f32,
    // A paged level (z > 0): xy the grid page of its window's first page, z the page side in
    // texels; `uv` is then the level's UV and `layer` its place in the page table. A level
    // whose layer wraps: w > 0 (z = 0), and taps past the layer's edges wrap round to the
    // opposite edge.
    page: vec4<f32>,
}

// A hardware 2x2 comparison at `uv` (layer UV) against `depth`: of `map`'s layer (wrapping
// round its edges for a layer that wraps), or of the page pool's atlas through the page table
// for a paged level (lit where the page is missing).
fn map_compare(map: texture_depth_2d_array, p: MapSample, uv: vec2<f32>, depth: f32) -> f32 {
    if p.page.z > 0.0 {
        let at = page_uv(p.page, p.layer, p.texel, uv);
        if at.x < 0.0 {
            return 1.0;
        }
        return textureSampleCompareLevel(page_atlas, shadow_compare, at, 0, depth);
    }
    if p.page.w > 0.0 {
        return textureSampleCompareLevel(map, shadow_compare_wrap, uv, p.layer, depth);
    }
    return textureSampleCompareLevel(map, shadow_compare, uv, p.layer, depth);
}

// The 2x2 raw depths around `uv` (layer UV), as `map_compare` reads them (far, 0, where a
// page is missing).
fn map_gather(map: texture_depth_2d_array, p: MapSample, uv: vec2<f32>) -> vec4<f32> {
    if p.page.z > 0.0 {
        let at = page_uv(p.page, p.layer, p.texel, uv);
        if at.x < 0.0 {
            return vec4<f32>(0.0);
        }
        return textureGather(page_atlas, shadow_point, at, 0);
    }
    if p.page.w > 0.0 {
        return textureGather(map, shadow_point_wrap, uv, p.layer);
    }
    return textureGather(map, shadow_point, uv, p.layer);
}

// Comparison depth for a tap at `offset_uv` from the receiver: the receiver plane's depth
// there, moved towards the light by a fraction of a texel of slope, and never past the far
// end of the view's depth (0).
//
// NOTE: a receiver past a clipmap level's depth range (its range bounds the casters, not the
// receivers) is compared at depth 0; its plane's gradient then took taps below 0, where every
// empty texel (0) compared as a blocker and shadowed ground no caster was over.
fn tap_depth(p: MapSample, offset_uv: vec2<f32>) -> f32 {
    let slack = RECEIVER_PLANE_EPSILON_TEXELS * p.texel * (abs(p.dz_duv.x) + abs(p.dz_duv.y));
    return max(p.depth + dot(p.dz_duv, offset_uv) + slack, 0.0);
}

// One hardware 2x2 comparison tap: 1 lit, 0 shadowed.
//
// NOTE: taps are not clamped to the view's rectangle: each layer holds one view and is
// cleared to the far depth (0) around it, so a kernel reaching past a smaller view's corner
// reads "no caster" there, as it does past the edge of a full layer.
fn compare_tap(map: texture_depth_2d_array, p: MapSample, offset_uv: vec2<f32>) -> f32 {
    return map_compare(map, p, p.uv + offset_uv, tap_depth(p, offset_uv));
}

// Fixed (2R+1)² grid of comparison taps, `filter_step` apart (R at most 5).
fn pcf_grid(map: texture_depth_2d_array, p: MapSample, radius: u32) -> f32 {
    let r = i32(min(radius, 5u));
    var sum = 0.0;
    for (var y = -r; y <= r; y++) {
        for (var x = -r; x <= r; x++) {
            sum += compare_tap(map, p, vec2<f32>(f32(x), f32(y)) * p.filter_step);
        }
    }
    let side = f32(2 * r + 1);
    return sum / (side * side);
}

// 16 comparison taps of a rotated Poisson disc of `radius` (layer UV); one tap at radius 0.
fn pcf_poisson(map: texture_depth_2d_array, p: MapSample, radius: f32, rotation: mat2x2<f32>) -> f32 {
    if radius <= 0.0 {
        return compare_tap(map, p, vec2<f32>(0.0));
    }
    var sum = 0.0;
    for (var i = 0u; i < 16u; i++) {
        sum += compare_tap(map, p, rotation * sixteen_tap(i) * radius);
    }
    return sum / 16.0;
}

// Comparison depth of a PCSS tap: `tap_depth`, or the true (unclamped) receiver plane where
// that is nearer the light. A stored depth behind the receiver's own tangent plane cannot
// shade it, but where the slope was clamped the clamped plane falls behind the surface on the
// side that rises towards the light, and PCSS's wide search and kernel then find the
// receiver's own faces there (a caster's top face under a sun 0.5° above the horizon).
//
// NOTE: the true plane carries no slack: the slack scales with the slope, and 0.5 texel of an
// uncapped slope (115 at 0.5°) lets real blockers a metre away fail (10.6 % of the umbra lit
// with MAX_RECEIVER_SLOPE at 200). PCF keeps `tap_depth` alone: its kernel spans about a
// texel, where the clamped plane plus slack already holds, and the true plane there only lit
// more contact shadow (5 of 498 umbra pixels instead of 3 under that sun).
fn pcss_tap_depth(p: MapSample, offset_uv: vec2<f32>) -> f32 {
    return max(tap_depth(p, offset_uv), p.depth + dot(p.dz_duv_true, offset_uv));
}

// What the blocker search found: the mean depth of the blocking texels and how many of the
// `4 · blocker_samples(light)` gathered texels block.
struct Blockers {
    depth: f32,
    count: f32,
}

// What a blocker search that found `count` blocking texels settles: 1 (no blocker: lit), 0
// (every gathered texel blocks and the light's flags ask for the early-out: umbra) or -1 (a
// penumbra to filter).
fn search_settled(count: f32, light: Light) -> f32 {
    let total_taps = 4.0 * f32(blocker_samples(light));
    let early_out = (light.flags & SHADOW_FLAG_BLOCKER_EARLY_OUT) != 0u;
    return select(select(-1.0, 0.0, early_out && count >= total_taps), 1.0, count == 0.0);
}

// Gathers `samples` 2x2 footprints over a rotated Poisson disc of `radius`
// (layer UV, stretched by `aspect`) and averages the depth of those nearer the light than
// the receiver's plane.
fn find_blockers(
    map: texture_depth_2d_array,
    p: MapSample,
    radius: f32,
    aspect: vec2<f32>,
    rotation: mat2x2<f32>,
    samples: u32,
) -> Blockers {
    var sum = 0.0;
    var count = 0.0;
    for (var i = 0u; i < samples; i++) {
        let offset = rotation * blocker_tap(i, samples) * radius * aspect;
        let depths = map_gather(map, p, p.uv + offset);
        let reference = pcss_tap_depth(p, offset);
        let is_blocker = vec4<f32>(depths > vec4<f32>(reference));
        sum += dot(depths, is_blocker);
        count += dot(is_blocker, vec4<f32>(1.0));
    }
    return Blockers(sum / max(count, 1.0), count);
}

// `samples` comparison taps over a rotated Poisson disc of `radius` (layer UV,
// stretched by `aspect`), faded towards lit where the search found few blockers (it only
// grazed the penumbra's outer edge).
fn pcss_filter(
    map: texture_depth_2d_array,
    p: MapSample,
    radius: f32,
    aspect: vec2<f32>,
    rotation: mat2x2<f32>,
    blocker_count: f32,
    samples: u32,
) -> f32 {
    var lit = 0.0;
    for (var i = 0u; i < samples; i++) {
        let offset = rotation * filter_tap(i, samples) * radius * aspect;
        lit += map_compare(map, p, p.uv + offset, pcss_tap_depth(p, offset));
    }
    lit /= f32(samples);
    return mix(1.0, lit, smoothstep(0.0, 4.0, blocker_count));
}
