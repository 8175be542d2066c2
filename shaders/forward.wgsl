// Forward shading of receivers: the shipped material's lighting (penumbra::shading: Lambert
// diffuse from every light of the frame times its shadow, plus a flat ambient term) of its
// base colour times its texture. Back faces (drawn for double-sided materials) are lit
// with the flipped normal, which also offsets their shadow lookups. Shader defs: ALPHA_MASK
// (discard below the cutoff; with ALPHA_TO_COVERAGE, under MSAA, no discard: the alpha,
// sharpened around the cutoff, sets the pixel's sample coverage),
// SHADOW_DEBUG_CASCADES (tint by the focus light's cascade, or a point light's cube face; the
// contact-shadow debug view is chosen at run time, `frame.debug_contact`),
// ANALYSIS_OUTPUTS (also write the focus light's shadow factor, world position and normal of
// every pixel, for scoring against a reference), SHADOW_SPOT and SHADOW_POINT (spot- and
// point-light shadows) and the filter defs of penumbra::shadows.
#import penumbra::contract::{INSTANCE_FLAG_RECEIVE_SHADOWS, LIGHT_DIRECTIONAL, LIGHT_POINT, LIGHT_SPOT}
#import penumbra::frame::frame
#import penumbra::forward_io::{ForwardVertexOutput, forward_vertex, transmission}
#import penumbra::lights::{get_light, light_count, make_surface}
#import penumbra::shading::{display_color, shade}
#import penumbra::shadows::cascades::cascade_index
#ifdef SHADOW_POINT
#import penumbra::shadows::point::point_face
#endif
#ifdef SHADOW_SPOT
#import penumbra::shadows::spot::spot_covers
#endif

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

struct FragmentOutput {
    @location(0) color: vec4<f32>,
#ifdef ANALYSIS_OUTPUTS
    // Of the focus light: r = shadow factor multiplied into its term, g = cascade index (-1
    // past max_distance or outside a spot light's view; 0 inside it), b = 1 where the shadow
    // was evaluated (receiver facing the light), a = n·l.
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
#ifdef ALPHA_TO_COVERAGE
    // The cutoff crossed within about a pixel: 0.5 on the cutoff, 0 and 1 a pixel's alpha
    // change either side, so the pipeline's alpha-to-coverage antialiases the cut-out edge.
    let coverage = saturate((base.a - in.cutoff) / max(fwidth(base.a), 1e-4) + 0.5);
#else ifdef ALPHA_MASK
    if base.a < in.cutoff {
        discard;
    }
#endif
    // NOTE: the flipped normal of a back face is also what make_surface offsets the shadow
    // lookup along (normal offset, receiver plane), so an underside facing the sun is lit.
    var normal = normalize(in.world_normal);
    if !front_facing {
        normal = -normal;
    }
    let view_depth = -(frame.view_from_world * vec4<f32>(in.world_position, 1.0)).z;
    let surface = make_surface(in.world_position, normal, view_depth, in.clip_position.xy);
    let receives = (in.flags & INSTANCE_FLAG_RECEIVE_SHADOWS) != 0u;
#ifdef TRANSMISSION
    let through_share = transmission(in);
#else
    let through_share = 0.0;
#endif

    let shading = shade(surface, receives, through_share);
#ifdef ANALYSIS_OUTPUTS
    let focus = shading.focus;
#endif
    let color = display_color(base.rgb, shading.direct, surface);
    var out: FragmentOutput;
    out.color = vec4<f32>(color, 1.0);
#ifdef ALPHA_TO_COVERAGE
    // NOTE: the pipeline writes only the colour channels; the alpha drives the coverage.
    out.color.a = coverage;
#endif
#ifdef ANALYSIS_OUTPUTS
    var focus_cascade = -1;
    if frame.focus_light < light_count() {
        let light = get_light(frame.focus_light);
        if light.kind == LIGHT_DIRECTIONAL {
            focus_cascade = cascade_index(light, surface);
        }
#ifdef SHADOW_SPOT
        if light.kind == LIGHT_SPOT && spot_covers(light, surface) {
            focus_cascade = 0;
        }
#endif
#ifdef SHADOW_POINT
        if light.kind == LIGHT_POINT {
            focus_cascade = point_face(light, surface);
        }
#endif
    }
    out.shadow = vec4<f32>(focus.x, f32(focus_cascade), focus.z, focus.w);
    out.position = vec4<f32>(in.world_position, 1.0);
    out.normal = vec4<f32>(normal, view_depth);
#endif
    return out;
}
