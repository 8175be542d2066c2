// Clears part of a shadow layer: a quad over the whole clip square at the reverse-Z far
// depth (0), drawn with depth test `Always` under a scissor rectangle, so a redraw resets
// only the texels the last draw wrote. The quad's corners lie on the clip square's edges:
// no vertex outside it, so nothing is clipped (which keeps a multiview pass's layers right
// on rasterisers that lose them on clipped primitives).

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0),
        vec2<f32>(1.0, -1.0),
        vec2<f32>(-1.0, 1.0),
        vec2<f32>(-1.0, 1.0),
        vec2<f32>(1.0, -1.0),
        vec2<f32>(1.0, 1.0),
    );
    return vec4<f32>(corners[index], 0.0, 1.0);
}
