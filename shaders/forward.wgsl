// Forward shading of receivers: Lambert diffuse from the sun times the cascaded shadow
// factor, plus a flat ambient term. Shader defs: ALPHA_MASK (discard below the cutoff),
// SHADOW_DEBUG_CASCADES (tint by cascade), ANALYSIS_OUTPUTS (also write the shadow factor,
// world position and normal of every pixel, for scoring against a reference), and the filter
// defs of penumbra::shadow.
#import penumbra::frame::frame
#import penumbra::forward_io::{ForwardVertexOutput, forward_vertex}
#import penumbra::mesh::INSTANCE_FLAG_RECEIVE_SHADOWS
#import penumbra::shadow::{blend_cascade_shadow, cascade_debug_color, shadow_cascade_index}

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

// ACES filmic curve (Narkowicz 2015 fit): rolls highlights off instead of clipping them.
fn tonemap(color: vec3<f32>) -> vec3<f32> {
    let x = color * 0.6;
    return saturate((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14));
}

struct FragmentOutput {
    @location(0) color: vec4<f32>,
#ifdef ANALYSIS_OUTPUTS
    // r: shadow factor multiplied into the sun term, g: cascade index (-1 past max_distance),
    // b: 1 where the shadow was evaluated (receiver facing the sun), a: n·l.
    @location(1) shadow: vec4<f32>,
    // xyz: world position, w: 1 (0 where nothing was drawn).
    @location(2) position: vec4<f32>,
    // xyz: unit normal facing the camera, w: view depth.
    @location(3) normal: vec4<f32>,
#endif
}

@fragment
fn fs_main(in: ForwardVertexOutput, @builtin(front_facing) front_facing: bool) -> FragmentOutput {
    let texel = textureSample(base_color_texture, base_color_sampler, in.uv);
    let base = in.base_color * texel;
#ifdef ALPHA_MASK
    if base.a < in.cutoff {
        discard;
    }
#endif
    var normal = normalize(in.world_normal);
    if !front_facing {
        normal = -normal;
    }
    let to_sun = -frame.sun_direction;
    let n_dot_l = max(dot(normal, to_sun), 0.0);
    let view_depth = -(frame.view_from_world * vec4<f32>(in.world_position, 1.0)).z;

    var visibility = 1.0;
    let evaluated = (in.flags & INSTANCE_FLAG_RECEIVE_SHADOWS) != 0u && n_dot_l > 0.0;
    if evaluated {
        visibility = blend_cascade_shadow(in.world_position, normal, view_depth, in.clip_position.xy);
    }
    let sun = frame.sun_color * frame.sun_illuminance * n_dot_l * visibility;
    var color = base.rgb * (frame.ambient + sun) * frame.exposure;
#ifdef SHADOW_DEBUG_CASCADES
    color = mix(color, color * cascade_debug_color(view_depth) * 1.6, 0.6);
#endif
    var out: FragmentOutput;
    out.color = vec4<f32>(tonemap(color), 1.0);
#ifdef ANALYSIS_OUTPUTS
    let cascade = f32(shadow_cascade_index(view_depth));
    out.shadow = vec4<f32>(visibility, cascade, select(0.0, 1.0, evaluated), n_dot_l);
    out.position = vec4<f32>(in.world_position, 1.0);
    out.normal = vec4<f32>(normal, view_depth);
#endif
    return out;
}
