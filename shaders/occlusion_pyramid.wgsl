// The depth pyramid of the occlusion culling, in one storage buffer (level after level, rows
// top to bottom): level 0 copies the camera's depth (`FIRST`), each further level keeps the
// farthest depth (reverse-Z: the smallest value) of the 2 × 2 texels of the level above it,
// and of the extra row and column an odd-sized level leaves over at its last texels, so every
// texel bounds all the pixels under it. The CPU mirror is `math::occlusion::Pyramid`.

struct Level {
    // This level's size and first texel in the buffer.
    size: vec2<u32>,
    offset: u32,
    // The level above's first texel (its size is `above`).
    above_offset: u32,
    above: vec2<u32>,
    _pad: vec2<u32>,
}

@group(0) @binding(0) var<uniform> level: Level;
@group(0) @binding(1) var<storage, read_write> pyramid: array<f32>;
#ifdef FIRST
@group(0) @binding(2) var depth: texture_depth_2d;
#endif

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= level.size.x || id.y >= level.size.y {
        return;
    }
    let out = level.offset + id.y * level.size.x + id.x;
#ifdef FIRST
    pyramid[out] = textureLoad(depth, id.xy, 0);
#else
    let start = id.xy * 2u;
    // The last texel of a row or column also covers what an odd size leaves over.
    let end = select(min(start + 1u, level.above - 1u), level.above - 1u, id.xy == level.size - 1u);
    var farthest = 1.0;
    for (var y = start.y; y <= end.y; y++) {
        for (var x = start.x; x <= end.x; x++) {
            farthest = min(farthest, pyramid[level.above_offset + y * level.above.x + x]);
        }
    }
    pyramid[out] = farthest;
#endif
}
