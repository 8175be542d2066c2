// Depth prepass: the camera's depth of every opaque and alpha-masked receiver, written before
// the lighting pass so that it shades each covered pixel once. The vertex stage is the one
// every forward material shares (`penumbra::forward_io`, whose clip position is @invariant),
// so the lighting pass finds exactly the depth written here. The opaque pipeline has no
// fragment stage; the masked one discards texels below the material's alpha cutoff. When the
// frame resolves shadows in a compute pass, the `*_normal` stages also write each pixel's
// normal (facing the camera) and whether it receives shadows, for the resolve; when the frame
// lights the prepass's pixels of untextured materials (penumbra's deferred lighting), the
// `*_id` stages also write each pixel's shading id: its instance, or SHADING_ID_NONE where the
// lighting pass draws the surface again.
#import penumbra::contract::{INSTANCE_FLAG_RECEIVE_SHADOWS, INSTANCE_FLAG_UNTEXTURED, SHADING_ID_NONE}
#import penumbra::forward_io::{ForwardVertexOutput, forward_vertex, transmission}
#import penumbra::normal_packing::pack_normal

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

// Whether the material's alpha test discards this fragment.
fn alpha_discarded(in: ForwardVertexOutput) -> bool {
    // NOTE: the same sample as the forward shader's alpha test (implicit level of detail), so
    // both passes discard the same texels.
    let alpha = textureSample(base_color_texture, base_color_sampler, in.uv).a * in.base_color.a;
    return alpha < in.cutoff;
}

// The unit normal facing the camera, as the forward shader computes it, and whether the
// instance receives shadows, packed (penumbra::normal_packing).
fn surface_normal(in: ForwardVertexOutput, front_facing: bool) -> u32 {
    var normal = normalize(in.world_normal);
    if !front_facing {
        normal = -normal;
    }
    return pack_normal(normal, (in.flags & INSTANCE_FLAG_RECEIVE_SHADOWS) != 0u, transmission(in) > 0.0);
}

@fragment
fn fs_masked(in: ForwardVertexOutput) {
    if alpha_discarded(in) {
        discard;
    }
}

@fragment
fn fs_normal(in: ForwardVertexOutput, @builtin(front_facing) front_facing: bool) -> @location(0) u32 {
    return surface_normal(in, front_facing);
}

@fragment
fn fs_masked_normal(in: ForwardVertexOutput, @builtin(front_facing) front_facing: bool) -> @location(0) u32 {
    if alpha_discarded(in) {
        discard;
    }
    return surface_normal(in, front_facing);
}

// The normal and the shading id of a pixel.
struct NormalAndId {
    @location(0) normal: u32,
    @location(1) id: u32,
}

// The pixel's normal, and its instance where its material is opaque and untextured (lit from
// the prepass), SHADING_ID_NONE elsewhere.
fn normal_and_id(in: ForwardVertexOutput, front_facing: bool) -> NormalAndId {
    let untextured = (in.flags & INSTANCE_FLAG_UNTEXTURED) != 0u;
    return NormalAndId(surface_normal(in, front_facing), select(SHADING_ID_NONE, in.instance, untextured));
}

@fragment
fn fs_normal_id(in: ForwardVertexOutput, @builtin(front_facing) front_facing: bool) -> NormalAndId {
    return normal_and_id(in, front_facing);
}

@fragment
fn fs_masked_normal_id(in: ForwardVertexOutput, @builtin(front_facing) front_facing: bool) -> NormalAndId {
    if alpha_discarded(in) {
        discard;
    }
    return normal_and_id(in, front_facing);
}
