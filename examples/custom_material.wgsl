// A material of your own that receives penumbra's shadows: cel shading with ink hatching in
// the shadow. It keeps the forward shader's interface (vs_main / fs_main, bind groups 0–3,
// the ALPHA_MASK def, and ALPHA_TO_COVERAGE under MSAA), takes its vertex stage from penumbra::forward_io, and loops over the
// frame's lights with penumbra::lights: `shadow_visibility(light, surface)` picks the
// cascade or spot view, blends and fades, and filters with whatever the light's
// ShadowSettings ask for (PCF or PCSS). The material does not know which lights, layouts or
// filters exist, so it keeps compiling and shadowing as new ones are added.
#import penumbra::frame::frame
#import penumbra::forward_io::{ForwardVertexOutput, forward_vertex}
#import penumbra::lights::{get_light, light_count, light_incidence, make_surface, shadow_visibility}
#import penumbra::contract::INSTANCE_FLAG_RECEIVE_SHADOWS

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
#ifdef ALPHA_TO_COVERAGE
    // Under MSAA the pipeline turns the returned alpha into sample coverage: 0.5 on the
    // cutoff, sharpened to about a pixel, instead of a hard discard.
    let coverage = saturate((base.a - in.cutoff) / max(fwidth(base.a), 1e-4) + 0.5);
#else ifdef ALPHA_MASK
    if base.a < in.cutoff {
        discard;
    }
#endif
    var normal = normalize(in.world_normal);
    if !front_facing {
        normal = -normal;
    }
    let view_depth = -(frame.view_from_world * vec4<f32>(in.world_position, 1.0)).z;
    let surface = make_surface(in.world_position, normal, view_depth, in.clip_position.xy);
    let receives = (in.flags & INSTANCE_FLAG_RECEIVE_SHADOWS) != 0u;
    var lit = frame.ambient;
    // Ink where a light that faces the surface is mostly blocked.
    var inked = false;
    for (var i = 0u; i < light_count(); i++) {
        let light = get_light(i);
        let incidence = light_incidence(light, in.world_position);
        let n_dot_l = max(dot(normal, incidence.to_light), 0.0);
        var visibility = 1.0;
        if receives && n_dot_l > 0.0 {
            visibility = shadow_visibility(light, surface);
        }
        // Three flat bands of light instead of a smooth ramp.
        let amount = n_dot_l * visibility;
        let band = select(select(0.0, 0.55, amount > 0.05), 1.0, amount > 0.6);
        lit += incidence.radiance * band;
        inked = inked || (n_dot_l > 0.0 && visibility < 0.5 && any(incidence.radiance > vec3<f32>(0.05)));
    }
    var color = base.rgb * lit;
    let pixel = vec2<i32>(in.clip_position.xy);
    if inked && (pixel.x + pixel.y) % 6 < 2 {
        color = INK;
    }
#ifdef ALPHA_TO_COVERAGE
    return vec4<f32>(saturate(color), coverage);
#else
    return vec4<f32>(saturate(color), 1.0);
#endif
}
