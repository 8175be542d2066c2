// A material of your own that receives penumbra's shadows: cel shading with ink hatching in
// the shadow. It keeps the forward shader's interface (vs_main / fs_main, bind groups 0–2,
// the ALPHA_MASK def) and calls the one public entry point, `blend_cascade_shadow`, which
// picks the cascade, blends and fades, and filters with whatever the light's ShadowSettings
// ask for (PCF or PCSS): the material does not need to know.
#import penumbra::frame::frame
#import penumbra::mesh::{fetch_instance, INSTANCE_FLAG_RECEIVE_SHADOWS}
#import penumbra::shadow::blend_cascade_shadow

@group(2) @binding(0) var base_color_texture: texture_2d<f32>;
@group(2) @binding(1) var base_color_sampler: sampler;

struct VertexOutput {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) world_position: vec3<f32>,
    @location(1) world_normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) base_color: vec4<f32>,
    @location(4) @interpolate(flat) cutoff: f32,
    @location(5) @interpolate(flat) flags: u32,
}

@vertex
fn vs_main(
    @builtin(instance_index) instance_index: u32,
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
) -> VertexOutput {
    let instance = fetch_instance(instance_index);
    let world = instance.world_from_local * vec4<f32>(position, 1.0);
    var out: VertexOutput;
    out.clip_position = frame.clip_from_world * world;
    out.world_position = world.xyz;
    out.world_normal = (instance.normal_from_local * vec4<f32>(normal, 0.0)).xyz;
    out.uv = uv;
    out.base_color = instance.base_color;
    out.cutoff = instance.alpha_cutoff;
    out.flags = instance.flags;
    return out;
}

// The colour of the hatching lines: a deep blue ink.
const INK: vec3<f32> = vec3<f32>(0.0, 0.0, 0.2);

@fragment
fn fs_main(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
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
