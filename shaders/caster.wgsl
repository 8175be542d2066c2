// Shadow casters: transforms instances into one shadow view's light clip space (a cascade or
// a spot light). The opaque pipeline uses only `vs_main` (no fragment stage, so depth testing
// runs early); the masked pipeline adds `fs_masked`, which discards texels below the
// material's alpha cutoff.
#import penumbra::mesh::{fetch_instance, Instance}

struct CasterView {
    clip_from_world: mat4x4<f32>,
}

// Bound with a dynamic offset: one entry per shadow view.
@group(0) @binding(0) var<uniform> caster_view: CasterView;
@group(2) @binding(0) var base_color_texture: texture_2d<f32>;
@group(2) @binding(1) var base_color_sampler: sampler;

struct VertexOutput {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) alpha: f32,
    @location(2) @interpolate(flat) cutoff: f32,
}

@vertex
fn vs_main(
    @builtin(instance_index) instance_index: u32,
    @location(0) position: vec3<f32>,
    @location(2) uv: vec2<f32>,
) -> VertexOutput {
    let instance = fetch_instance(instance_index);
    let world = instance.world_from_local * vec4<f32>(position, 1.0);
    var out: VertexOutput;
    out.clip_position = caster_view.clip_from_world * world;
    out.uv = uv;
    out.alpha = instance.base_color.a;
    out.cutoff = instance.alpha_cutoff;
    return out;
}

@fragment
fn fs_masked(in: VertexOutput) {
    let alpha = textureSampleLevel(base_color_texture, base_color_sampler, in.uv, 0.0).a * in.alpha;
    if alpha < in.cutoff {
        discard;
    }
}
