// Draws a paged clipmap's pages into the pool atlas, on the GPU, from the allocation's list of
// pages to draw (`pages_allocate.wgsl`):
//   `cull` (compute, a thread per caster and list slot) appends each slot whose page the
//   caster's bounding sphere reaches, seen from the light, to that caster's instance list,
//   counting them in its indirect draw;
//   `clear_vs` (an instance per slot) overwrites each listed page's tile with the far depth;
//   `caster_vs` (an instance per listed slot of one caster, reading list entry
//   `caster_id.x + instance_index`: the caster's list starts there, given by the caster-id
//   uniform or, where indirect draws may start past instance 0, by the draw's first
//   instance) places the caster's vertices in
//   the slot's page as its level sees them, moved onto the page's tile, and clips them to the
//   tile (clip distances); the opaque pipeline has no fragment stage, the alpha-masked one
//   adds `fs_masked`, which discards texels below the material's alpha cutoff.
// A physical page p is the tile (p mod tiles, p / tiles) of the atlas, rows downwards; a page
// keeps its level's orientation (light-frame y up), so the sampler maps a level position to
// the atlas with the same affine step.

enable clip_distances;

const MAX_LEVELS: u32 = 8u;

#import penumbra::indirect::DrawArgs

struct Level {
    // The level's clip space (its whole window, reverse-Z) from world.
    clip_from_world: mat4x4<f32>,
    // xy: the grid page of the window's first page; z: texel side, metres.
    window: vec4<f32>,
}

struct Render {
    light_from_world: mat4x4<f32>,
    // Tiles per side of the atlas, texels per page side, texels per atlas side.
    tiles: u32,
    page_size: f32,
    atlas_side: f32,
    pages_per_side: u32,
    casters: u32,
    slots: u32,
    levels: u32,
    _pad: u32,
    level: array<Level, MAX_LEVELS>,
}

struct Entry {
    physical: u32,
    page_x: i32,
    page_y: i32,
    _pad: u32,
}

struct Caster {
    world_from_local: mat4x4<f32>,
    // xyz: world centre of its bounding sphere; w: radius.
    sphere: vec4<f32>,
    // x: base colour alpha; y: alpha cutoff (0 for opaque casters).
    material: vec4<f32>,
}


@group(0) @binding(0) var<uniform> render: Render;
@group(0) @binding(1) var<storage, read> draws: array<vec2<u32>>;
// x: pages kept, y: pages to draw (the allocation's counters).
@group(0) @binding(2) var<storage, read> counters: vec4<u32>;
@group(0) @binding(3) var<storage, read> table: array<Entry>;
@group(0) @binding(4) var<storage, read> casters: array<Caster>;

// The level, grid page and physical page of list slot `slot`.
struct Slot {
    level: u32,
    page: vec2<i32>,
    physical: u32,
}

fn slot_at(slot: u32) -> Slot {
    let d = draws[slot];
    let level = d.x >> 24u;
    let e = table[level * render.pages_per_side * render.pages_per_side + (d.x & 0xffffffu)];
    return Slot(level, vec2<i32>(e.page_x, e.page_y), d.y);
}

// The NDC rectangle (min xy, max xy) of physical page `p`'s tile.
fn tile_rect(p: u32) -> vec4<f32> {
    let tile = vec2<f32>(f32(p % render.tiles), f32(p / render.tiles));
    let size = 2.0 * render.page_size / render.atlas_side;
    let min_x = -1.0 + tile.x * size;
    let max_y = 1.0 - tile.y * size;
    return vec4<f32>(min_x, max_y - size, min_x + size, max_y);
}

#ifdef CULL
@group(0) @binding(5) var<storage, read_write> lists: array<u32>;
@group(0) @binding(6) var<storage, read_write> args: array<DrawArgs>;

@compute @workgroup_size(64)
fn cull(@builtin(global_invocation_id) id: vec3<u32>) {
    let caster = id.x;
    let slot = id.y;
    if caster >= render.casters || slot >= min(counters.y, render.slots) {
        return;
    }
    let s = slot_at(slot);
    let texel = render.level[s.level].window.z;
    let side = render.page_size * texel;
    let lo = vec2<f32>(s.page) * side;
    let sphere = casters[caster].sphere;
    let xy = (render.light_from_world * vec4<f32>(sphere.xyz, 0.0)).xy;
    let nearest = clamp(xy, lo, lo + side);
    if distance(nearest, xy) > sphere.w {
        return;
    }
    let k = atomicAdd(&args[caster].instance_count, 1u);
    lists[caster * render.slots + k] = slot;
}
#else
@group(0) @binding(5) var<storage, read> lists: array<u32>;
// x: the first list entry of the caster drawn (0 where the draw's first instance says it).
@group(1) @binding(0) var<uniform> caster_id: vec4<u32>;

@group(2) @binding(0) var base_color_texture: texture_2d<f32>;
@group(2) @binding(1) var base_color_sampler: sampler;

struct Placed {
    @builtin(position) position: vec4<f32>,
    @builtin(clip_distances) clip: array<f32, 4>,
    @location(0) uv: vec2<f32>,
    // x: base colour alpha; y: alpha cutoff.
    @location(1) @interpolate(flat) material: vec2<f32>,
}

@vertex
fn clear_vs(@builtin(vertex_index) vertex: u32, @builtin(instance_index) slot: u32) -> @builtin(position) vec4<f32> {
    let rect = tile_rect(draws[slot].y);
    var xs = array<f32, 6>(0.0, 1.0, 1.0, 0.0, 1.0, 0.0);
    var ys = array<f32, 6>(0.0, 0.0, 1.0, 0.0, 1.0, 1.0);
    return vec4<f32>(mix(rect.x, rect.z, xs[vertex]), mix(rect.y, rect.w, ys[vertex]), 0.0, 1.0);
}

@vertex
fn caster_vs(
    @location(0) position: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @builtin(instance_index) instance: u32,
) -> Placed {
    let entry = caster_id.x + instance;
    let caster = entry / render.slots;
    let s = slot_at(lists[entry]);
    let level = render.level[s.level];
    let world = casters[caster].world_from_local * vec4<f32>(position, 1.0);
    let clip = level.clip_from_world * world;
    let n = f32(render.pages_per_side);
    let local = vec2<f32>(s.page) - level.window.xy;
    let page_min = -1.0 + 2.0 * local / n;
    let rect = tile_rect(s.physical);
    let scale = n * render.page_size / render.atlas_side;
    let xy = rect.xy + (clip.xy / clip.w - page_min) * scale;
    var out: Placed;
    out.position = vec4<f32>(xy, clip.z / clip.w, 1.0);
    out.clip = array<f32, 4>(xy.x - rect.x, rect.z - xy.x, xy.y - rect.y, rect.w - xy.y);
    out.uv = uv;
    out.material = casters[caster].material.xy;
    return out;
}

// What the masked fragment stage reads of `Placed`.
struct Masked {
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) material: vec2<f32>,
}

@fragment
fn fs_masked(in: Masked) {
    let alpha = textureSampleLevel(base_color_texture, base_color_sampler, in.uv, 0.0).a * in.material.x;
    if alpha < in.material.y {
        discard;
    }
}
#endif
