// Marks the pages of a paged clipmap that the frame's receivers read, by the rules of
// `math::pages::mark_receiver`: each covered pixel of the camera's depth is taken back to the
// world and into the light's frame, finds the finest level (from the first whose texel is at
// least the pixel's width there) whose window holds it with the margin, and sets the bits of
// the pages its filter's footprint touches there (and in the next level inside the blend
// band, and in the coarsest level, which an overflow falls back to). One thread per pixel; the bitset is a bit per table
// entry, level by level. With MSAA (MULTISAMPLED) the depth is multisampled and each pixel is
// read at sample 0.

const MAX_LEVELS: u32 = 8u;

struct Mark {
    // World (relative to the render origin) from the camera's clip space (reverse-Z).
    world_from_clip: mat4x4<f32>,
    // The light's frame from world: rotation only.
    light_from_world: mat4x4<f32>,
    size: vec2<u32>,
    levels: u32,
    pages_per_side: u32,
    page_size: f32,
    virtual_resolution: f32,
    // Texels the filter reads around a receiver; texels a window keeps clear; blend band;
    // the smallest texel a receiver reads per metre of its view depth (0: any).
    radius: f32,
    margin: f32,
    blend: f32,
    pixel: f32,
    _pad1: f32,
    _pad2: f32,
    // Per level: xy the window's first grid texel, z the texel's side in metres.
    level: array<vec4<f32>, MAX_LEVELS>,
}

#ifdef MULTISAMPLED
@group(0) @binding(0) var depth: texture_depth_multisampled_2d;
#else
@group(0) @binding(0) var depth: texture_depth_2d;
#endif
@group(0) @binding(1) var<uniform> mark: Mark;
@group(0) @binding(2) var<storage, read_write> needed: array<atomic<u32>>;

// Sets the bits of the pages of level `k` that the filter reads around light-frame `xy`.
fn mark_footprint(k: u32, xy: vec2<f32>) {
    let at = xy / mark.level[k].z;
    let lo = vec2<i32>(floor(floor(at - mark.radius) / mark.page_size));
    let hi = vec2<i32>(floor(floor(at + mark.radius) / mark.page_size));
    let n = i32(mark.pages_per_side);
    let base = k * mark.pages_per_side * mark.pages_per_side;
    for (var y = lo.y; y <= hi.y; y++) {
        for (var x = lo.x; x <= hi.x; x++) {
            let entry = u32(((y % n) + n) % n) * mark.pages_per_side + u32(((x % n) + n) % n);
            let bit = base + entry;
            atomicOr(&needed[bit >> 5u], 1u << (bit & 31u));
        }
    }
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= mark.size) {
        return;
    }
    let d = textureLoad(depth, vec2<i32>(id.xy), 0);
    if d <= 0.0 {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(mark.size);
    let ndc = vec2<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    let world = mark.world_from_clip * vec4<f32>(ndc, d, 1.0);
    let xy = (mark.light_from_world * vec4<f32>(world.xyz / world.w, 0.0)).xy;
    // NOTE: clip w is the view depth, so the point's homogeneous w is its inverse.
    let pixel = mark.pixel / world.w;
    var first = mark.levels - 1u;
    for (var i = 0u; i < mark.levels; i++) {
        if mark.level[i].z >= pixel {
            first = i;
            break;
        }
    }
    for (var i = first; i < mark.levels; i++) {
        let first = mark.level[i].xy;
        let texel = mark.level[i].z;
        let lo = (first + mark.margin) * texel;
        let hi = (first + mark.virtual_resolution - mark.margin) * texel;
        if any(xy < lo) || any(xy > hi) {
            continue;
        }
        mark_footprint(i, xy);
        let band = mark.blend * 0.5 * mark.virtual_resolution * texel;
        let inside = min(min(xy.x - lo.x, xy.y - lo.y), min(hi.x - xy.x, hi.y - xy.y));
        let blends = i + 1u < mark.levels && inside < band;
        if blends {
            mark_footprint(i + 1u, xy);
        }
        // The coarsest level too, which a pool that overflowed falls back to.
        let coarsest = mark.levels - 1u;
        if coarsest > i + u32(blends) {
            mark_footprint(coarsest, xy);
        }
        return;
    }
}
