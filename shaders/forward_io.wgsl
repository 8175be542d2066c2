// The vertex stage every forward material shares: fetch the instance, transform the vertex
// to world and clip space, and pass on what the fragment stage needs. A material's own
// shader imports it and writes only its fragment stage (see examples/custom_material.wgsl).
#define_import_path penumbra::forward_io

#import penumbra::frame::frame
#import penumbra::mesh::{draw_indices, instance_normal, instance_position, instances}

struct ForwardVertexOutput {
    // @invariant: the depth prepass computes it with the same function, and the lighting
    // pass must find exactly the depth the prepass wrote.
    @builtin(position) @invariant clip_position: vec4<f32>,
    @location(0) world_position: vec3<f32>,
    @location(1) world_normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) base_color: vec4<f32>,
    // Alpha below this is discarded (masked materials only).
    @location(4) @interpolate(flat) cutoff: f32,
    // The instance flags (INSTANCE_FLAG_RECEIVE_SHADOWS) in bits 0–7 and the diffuse
    // transmission in bits 8–15 (255 = 1; read it with `transmission`).
    @location(5) @interpolate(flat) flags: u32,
    // The instance's index in the instance array (the prepass writes it as the pixel's
    // shading id).
    @location(6) @interpolate(flat) instance: u32,
}

// The share of the light on the surface's other side that this side shows (diffuse
// transmission; 0 for solids).
fn transmission(in: ForwardVertexOutput) -> f32 {
    return f32((in.flags >> 8u) & 0xffu) / 255.0;
}

// Diffuse transmission `t` quantised to a byte (255 = 1), as the vertex stage passes it on.
fn transmission_byte(t: f32) -> u32 {
    return u32(round(saturate(t) * 255.0));
}

// The vertex stage for vertex `position`/`normal`/`uv` of draw instance `instance_index`.
fn forward_vertex(instance_index: u32, position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>) -> ForwardVertexOutput {
    let slot = draw_indices[instance_index];
    let instance = instances[slot];
    let world = vec4<f32>(instance_position(instance, position), 1.0);
    var out: ForwardVertexOutput;
    out.clip_position = frame.clip_from_world * world;
    out.world_position = world.xyz;
    out.world_normal = instance_normal(instance, normal);
    out.uv = uv;
    out.base_color = instance.base_color;
    out.cutoff = instance.alpha_cutoff;
    // NOTE: in the flags, so that it costs no interpolant of its own.
    let share = transmission_byte(instance.transmission);
    out.flags = (instance.flags & 0xffu) | (share << 8u);
    out.instance = slot;
    return out;
}
