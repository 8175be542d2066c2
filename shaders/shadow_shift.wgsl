// Moves a clipmap level's depth by whole texels when its window moves: a triangle over the
// whole target, each texel taking the source texel `shift` away (the same grid texel, which
// the moved window holds at another place), or the far depth (0) where the source holds
// nothing (the strips the window newly covers, drawn next). Depth test `Always`.

struct Shift {
    // Target texel + offset = source texel.
    offset: vec2<i32>,
    // Texels per side of the source.
    side: i32,
    _pad: i32,
}

// The moved layer alone (a view of one layer, so only it changes state for the read).
@group(0) @binding(0) var source: texture_depth_2d;
@group(0) @binding(1) var<uniform> shift: Shift;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @builtin(frag_depth) f32 {
    let texel = vec2<i32>(floor(position.xy)) + shift.offset;
    if any(texel < vec2<i32>(0)) || any(texel >= vec2<i32>(shift.side)) {
        return 0.0;
    }
    return textureLoad(source, texel, 0);
}
