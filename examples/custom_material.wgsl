// A material of your own that receives penumbra's shadows: cel shading with ink hatching in
// the shadow. It keeps the forward shader's interface (vs_main / fs_main, bind groups 0–2,
// the ALPHA_MASK def), takes its vertex stage from penumbra::forward_io, and calls the one
// public entry point, `blend_cascade_shadow`, which picks the cascade, blends and fades, and
// filters with whatever the light's ShadowSettings ask for (PCF or PCSS): the material does
// not need to know.
#import penumbra::frame::frame
#import penumbra::forward_io::{ForwardVertexOutput, forward_vertex}
#import penumbra::mesh::INSTANCE_FLAG_RECEIVE_SHADOWS
#import penumbra::shadow::blend_cascade_shadow

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

// The colour of the hatching lines: a deep blue ink.
const INK: vec3<f32> = vec3<f32>(0.0, 0.0, 0.2);

@fragment
fn fs_main(in: ForwardVertexOutput, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let base = in.base_color * textureSample(base_color_texture, base_color_sampler, in.uv);
#ifdef ALPHA_MASK
    if base.a < in.cutoff {
        discard;
    }
#endif
    var normal = normalize(in.world_normal);
    if !front_facing {
        normal = -normal;
    }
    let n_dot_l = max(dot(normal, -frame.sun_direction), 0.0);
    var visibility = 1.0;
    if (in.flags & INSTANCE_FLAG_RECEIVE_SHADOWS) != 0u && n_dot_l > 0.0 {
        let view_depth = -(frame.view_from_world * vec4<f32>(in.world_position, 1.0)).z;
        visibility = blend_cascade_shadow(in.world_position, normal, view_depth, in.clip_position.xy);
    }
    // Three flat bands of sunlight instead of a smooth ramp.
    let light = n_dot_l * visibility;
    let band = select(select(0.0, 0.55, light > 0.05), 1.0, light > 0.6);
    var color = base.rgb * (frame.ambient + frame.sun_color * frame.sun_illuminance * band);
    // Diagonal ink lines where the sun is mostly blocked (not on faces turned away from it).
    let pixel = vec2<i32>(in.clip_position.xy);
    if n_dot_l > 0.0 && visibility < 0.5 && (pixel.x + pixel.y) % 6 < 2 {
        color = INK;
    }
    return vec4<f32>(saturate(color), 1.0);
}
