// A sun's moment shadows (EVSM2, EVSM4, MSM): turns each redrawn cascade's depth into the
// moments its technique filters (`resolve`), then pre-filters them with a separable Gaussian
// (`blur`, once along each axis: from the moments into a one-layer scratch, and back), and
// with contact hardening averages them down a mip chain (`downsample`, one level at a time).
// Reverse-Z orthographic depth is linear in the distance from the light, so d = 1 − z grows
// away from the light from 0 (the box's light side) to 1 (its far side); the moments are of d
// remapped from the cascade's receiver span [depth_start, 1] to [0, 1] (casters above every
// receiver clamp to 0), so the format's precision and the warp cover the depths receivers
// have. Without contact hardening, half-float EVSM moments are stored with their variance
// rounded down, so rounding never lights a caster's foot (with it, a foot compares the depth
// itself, and rounding to the nearest keeps penumbrae their width).
//
// EVSM2 stores its moments with their coverage, (o·w, o·w², o), o being 1 where a caster was
// drawn and 0 in an empty texel, so the test can light a footprint's empty share.
//
// With PAGES, the entries are `page_bake`: a paged sun's drawn pages (the allocation's list)
// turned into moments and blurred in one step, each page on its own (taps past its edge
// repeat its edge texels), into the moments atlas laid out as the pool's; and, with contact
// hardening, `page_downsample`: one mip level of those pages from the level before, each
// page's tile averaged down on its own (an atlas of pages of a power-of-two side keeps its
// tiles aligned at every level).
//
// Shader defs: MOMENTS_RGBA32 (the moments are `rgba32float`), MOMENTS_RGBA16_UNORM
// (`rgba16unorm`: MSM only), else `rgba16float`; PAGES.

#import penumbra::contract::{SHADOW_FILTER_EVSM2, SHADOW_FILTER_EVSM4}
#import penumbra::shadows::moments::{negative_warp, positive_warp}
#import penumbra::shadows::msm::{msm_moments, msm_quantize}

struct CascadeMomentsJob {
    // The cascade's layer in the source (depth, moments or scratch) and the destination.
    src_layer: u32,
    dst_layer: u32,
    // Texels per side of the cascade's view (its corner of the layer).
    size: u32,
    // 3: EVSM2, 4: EVSM4, 5: MSM.
    technique: u32,
    // The warp exponents of this cascade (EVSM).
    c_positive: f32,
    c_negative: f32,
    // Blur radius in texels (the Gaussian's sigma is half of it); 0: no blur.
    radius: f32,
    // Blur: 0 along x, 1 along y. Downsample: the side of the level read, in texels.
    axis: u32,
    // Where the cascade's receivers start in d (`ShadowView::range.w`).
    depth_start: f32,
    // 1: half-float EVSM moments are stored with their variance rounded down
    // (`half_moments_rounded_down`).
    variance_down: u32,
}

@group(0) @binding(0) var depth_layers: texture_depth_2d_array;
#ifdef MOMENTS_RGBA32
@group(0) @binding(1) var moments_out: texture_storage_2d_array<rgba32float, write>;
#else ifdef MOMENTS_RGBA16_UNORM
@group(0) @binding(1) var moments_out: texture_storage_2d_array<rgba16unorm, write>;
#else
@group(0) @binding(1) var moments_out: texture_storage_2d_array<rgba16float, write>;
#endif
#ifdef PAGES
const MAX_PAGED_LEVELS: u32 = 8u;

// How one paged level's pages are baked (`CascadeMomentsJob`'s per-level fields).
struct PageLevelMoments {
    technique: u32,
    c_positive: f32,
    c_negative: f32,
    radius: f32,
    depth_start: f32,
    variance_down: u32,
    _pad0: u32,
    _pad1: u32,
}

struct PageMoments {
    // Tiles per side of the atlas; texels per page side.
    tiles: u32,
    page_size: u32,
    _pad0: u32,
    _pad1: u32,
    level: array<PageLevelMoments, MAX_PAGED_LEVELS>,
}

@group(0) @binding(2) var<uniform> pages: PageMoments;
// Per page drawn this frame: (level << 24 | table entry, physical page).
@group(0) @binding(3) var<storage, read> draws: array<vec2<u32>>;
// y: the pages drawn this frame (the allocation's counters).
@group(0) @binding(4) var<storage, read> counters: vec4<u32>;
// The level before the one `page_downsample` writes.
@group(0) @binding(5) var moments_in: texture_2d_array<f32>;
// The job of the page being baked, filled from its level's entry.
var<private> job: CascadeMomentsJob;

// Fills `job` for the page of list entry `d` (its level's parameters; `size` its side).
fn page_job(d: vec2<u32>, size: u32) {
    let level = pages.level[min(d.x >> 24u, MAX_PAGED_LEVELS - 1u)];
    job = CascadeMomentsJob(
        0u, 0u, size, level.technique, level.c_positive, level.c_negative, level.radius, 0u,
        level.depth_start, level.variance_down,
    );
}
#else
@group(0) @binding(2) var<uniform> job: CascadeMomentsJob;
@group(0) @binding(3) var moments_in: texture_2d_array<f32>;
#endif

// The moments of one texel at depth `d` (0 at the light's side); `occupied`: a caster was
// drawn there.
fn texel_moments(d: f32, occupied: bool) -> vec4<f32> {
    if job.technique == SHADOW_FILTER_EVSM2 {
        let o = select(0.0, 1.0, occupied);
        let w = positive_warp(d, job.c_positive);
        return vec4<f32>(o * w, o * w * w, o, 0.0);
    }
    if job.technique == SHADOW_FILTER_EVSM4 {
        let p = positive_warp(d, job.c_positive);
        let n = negative_warp(d, job.c_negative);
        return vec4<f32>(p, p * p, n, n * n);
    }
#ifdef MOMENTS_RGBA32
    // 32-bit channels hold the raw power moments.
    return msm_moments(d);
#else
    // 16-bit channels need the optimised quantisation.
    return msm_quantize(msm_moments(d));
#endif
}

// The half float nearest `x` (ties away from zero), as an f32: the 13 mantissa bits a half
// float lacks rounded off (`pack2x16float` needs a capability not every device has). For `x`
// in the half floats' normal range.
fn half_nearest(x: f32) -> f32 {
    return bitcast<f32>((bitcast<u32>(x) + 0x1000u) & 0xffffe000u);
}

// The largest half float at or below `x` ≥ 0: the lacking bits cut.
fn half_at_or_below(x: f32) -> f32 {
    return bitcast<f32>(bitcast<u32>(x) & 0xffffe000u);
}

// A pair of moments (m, m²) as half floats whose variance about the stored mean is never above
// the pair's: the mean rounded to the nearest, the second moment down. Rounded to the
// nearest, a uniform occluder got a variance of up to about a thousandth of m², which
// Chebyshev's bound reads as depth spread: receivers within centimetres behind it were lit.
fn half_moments_rounded_down(m: vec2<f32>) -> vec2<f32> {
    let mean = half_nearest(m.x);
    let variance = max(m.y - m.x * m.x, 0.0);
    return vec2<f32>(mean, half_at_or_below(mean * mean + variance));
}

// Writes one texel of moments; half-float EVSM moments through `half_moments_rounded_down`
// when the job asks for it.
fn store_moments(texel: vec2<u32>, layer: u32, m: vec4<f32>) {
#ifdef MOMENTS_RGBA32
    textureStore(moments_out, texel, layer, m);
#else ifdef MOMENTS_RGBA16_UNORM
    textureStore(moments_out, texel, layer, m);
#else
    var out = m;
    if job.variance_down != 0u && (job.technique == SHADOW_FILTER_EVSM2 || job.technique == SHADOW_FILTER_EVSM4) {
        out = vec4<f32>(half_moments_rounded_down(m.xy), half_moments_rounded_down(m.zw));
    }
    textureStore(moments_out, texel, layer, out);
#endif
}

#ifdef PAGES
// The moments of the drawn page of list slot `group.y`, texel by texel (workgroup `group.x`
// of the page's 8×8 blocks): the Gaussian of radius `radius` over the page's depth, each tap
// turned into moments (taps past the page's edge repeat its edge texels).
@compute @workgroup_size(8, 8, 1)
fn page_bake(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_id) local: vec3<u32>) {
    if group.y >= counters.y {
        return;
    }
    let d = draws[group.y];
    let size = pages.page_size;
    page_job(d, size);
    let blocks = size / 8u;
    let at = vec2<i32>(vec2<u32>(group.x % blocks, group.x / blocks) * 8u + local.xy);
    let tile = vec2<i32>(vec2<u32>(d.y % pages.tiles, d.y / pages.tiles) * size);
    let r = i32(ceil(job.radius));
    let sigma = max(0.5 * job.radius, 0.5);
    let last = i32(size) - 1;
    var sum = vec4<f32>(0.0);
    var weights = 0.0;
    for (var y = -r; y <= r; y++) {
        for (var x = -r; x <= r; x++) {
            let w = exp(-0.5 * f32(x * x + y * y) / (sigma * sigma));
            let texel = tile + clamp(at + vec2<i32>(x, y), vec2<i32>(0), vec2<i32>(last));
            let z = clamp(textureLoad(depth_layers, texel, 0, 0), 0.0, 1.0);
            let depth = saturate((1.0 - z - job.depth_start) / max(1.0 - job.depth_start, 1e-6));
            sum += w * texel_moments(depth, z > 0.0);
            weights += w;
        }
    }
    store_moments(vec2<u32>(tile + at), 0u, sum / weights);
}

// One mip level of the drawn page of list slot `group.y` (workgroup `group.x` of its 8×8
// blocks): each texel the mean of the 2×2 texels it covers in the level before.
@compute @workgroup_size(8, 8, 1)
fn page_downsample(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_id) local: vec3<u32>) {
    if group.y >= counters.y {
        return;
    }
    let d = draws[group.y];
    let size = max(textureDimensions(moments_out).x / pages.tiles, 1u);
    page_job(d, size);
    let blocks = max(size / 8u, 1u);
    let at = vec2<u32>(group.x % blocks, group.x / blocks) * 8u + local.xy;
    if any(at >= vec2<u32>(size)) {
        return;
    }
    let texel = vec2<u32>(d.y % pages.tiles, d.y / pages.tiles) * size + at;
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        let src = vec2<i32>(texel * 2u + vec2<u32>(k & 1u, k >> 1u));
        sum += textureLoad(moments_in, src, 0, 0);
    }
    store_moments(texel, 0u, 0.25 * sum);
}
#else
// Depth to moments: one invocation per texel of the cascade's view.
@compute @workgroup_size(8, 8, 1)
fn resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= job.size || id.y >= job.size {
        return;
    }
    let z = clamp(textureLoad(depth_layers, id.xy, job.src_layer, 0), 0.0, 1.0);
    let d = saturate((1.0 - z - job.depth_start) / max(1.0 - job.depth_start, 1e-6));
    // NOTE: an empty texel holds the cleared far depth, exactly 0.
    store_moments(id.xy, job.dst_layer, texel_moments(d, z > 0.0));
}

// One axis of the separable Gaussian pre-blur; taps past the view's edge repeat its edge
// texel (the view may not fill its layer, and the next view's texels are not its own).
@compute @workgroup_size(8, 8, 1)
fn blur(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= job.size || id.y >= job.size {
        return;
    }
    let r = i32(ceil(job.radius));
    let sigma = max(0.5 * job.radius, 0.5);
    let step = select(vec2<i32>(1, 0), vec2<i32>(0, 1), job.axis == 1u);
    let last = i32(job.size) - 1;
    var sum = vec4<f32>(0.0);
    var weights = 0.0;
    for (var k = -r; k <= r; k++) {
        let w = exp(-0.5 * f32(k * k) / (sigma * sigma));
        let texel = clamp(vec2<i32>(id.xy) + step * k, vec2<i32>(0), vec2<i32>(last));
        sum += w * textureLoad(moments_in, texel, job.src_layer, 0);
        weights += w;
    }
    store_moments(id.xy, job.dst_layer, sum / weights);
}

// One mip level of the cascade's view from the level before: the mean of the 2×2 texels each
// texel covers (an odd side repeats its last texel).
@compute @workgroup_size(8, 8, 1)
fn downsample(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= job.size || id.y >= job.size {
        return;
    }
    let last = vec2<i32>(i32(job.axis) - 1);
    let base = vec2<i32>(id.xy) * 2;
    var sum = vec4<f32>(0.0);
    for (var k = 0; k < 4; k++) {
        let texel = min(base + vec2<i32>(k & 1, k >> 1u), last);
        sum += textureLoad(moments_in, texel, job.src_layer, 0);
    }
    store_moments(id.xy, job.dst_layer, 0.25 * sum);
}
#endif
