// Depth prepass: the camera's depth of every opaque and alpha-masked receiver, written before
// the lighting pass so that it shades each covered pixel once. The vertex stage is the one
// every forward material shares (`penumbra::forward_io`, whose clip position is @invariant),
// so the lighting pass finds exactly the depth written here. The opaque pipeline has no
// fragment stage; the masked one discards texels below the material's alpha cutoff.
#import penumbra::forward_io::{ForwardVertexOutput, forward_vertex}

@group(2) @binding(0) var base_color_texture: texture_2d<f32>;
@group(2) @binding(1) var base_color_sampler: sampler;

@vertex
fn vs_main(
    @builtin(instance_index) instance_index: u32,
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
) -> ForwardVertexOutput {
    return forward_vertex(instance_index, position, normal, uv);
}

@fragment
fn fs_masked(in: ForwardVertexOutput) {
    // NOTE: the same sample as the forward shader's alpha test (implicit level of detail), so
    // both passes discard the same texels.
    let alpha = textureSample(base_color_texture, base_color_sampler, in.uv).a * in.base_color.a;
    if alpha < in.cutoff {
        discard;
    }
}
