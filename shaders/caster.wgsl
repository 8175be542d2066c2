// Shadow casters: transforms instances into one shadow view's light clip space (a cascade or
// a spot light). The opaque pipeline uses only `vs_main` (no fragment stage, so depth testing
// runs early); the masked pipeline adds `fs_masked`, which discards texels below the
// material's alpha cutoff.
//
// With `MULTIVIEW`, one pass renders a run of a sun's cascades (one array layer per view):
// the draw list holds each caster once, its entry packing the instance index with the mask
// of cascades it touches (`penumbra::ecs::single_pass`), and an instance outside the view
// being rasterised is moved off screen, so each cascade still draws only its own casters.
#import penumbra::contract::CASCADE_MASK_SHIFT
#import penumbra::mesh::{instances, draw_indices, instance_position}

struct CasterView {
    clip_from_world: mat4x4<f32>,
    // This view's bit in a single-pass entry's cascade mask.
    view_bit: u32,
}

#ifdef MULTIVIEW
// Entries of the caster-view buffer are 256 bytes apart (the dynamic-offset alignment).
struct CasterViewEntry {
    @size(256) view: CasterView,
}

// Bound with a dynamic offset at the run's first view; view `i` of the pass is entry `i`.
@group(0) @binding(0) var<uniform> caster_views: array<CasterViewEntry, 4>;

#else
// Bound with a dynamic offset: one entry per shadow view.
@group(0) @binding(0) var<uniform> caster_view: CasterView;
#endif
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
#ifdef MULTIVIEW
    @builtin(view_index) view_index: u32,
#endif
    @location(0) position: vec3<f32>,
    @location(2) uv: vec2<f32>,
) -> VertexOutput {
    var out: VertexOutput;
    let entry = draw_indices[instance_index];
#ifdef MULTIVIEW
    let view = caster_views[view_index].view;
    if ((entry >> CASCADE_MASK_SHIFT) & view.view_bit) == 0u {
        // Not a caster of this view: every vertex lands on one point outside the clip
        // volume (in x, which depth clamping leaves alone), so no triangle is rasterised.
        out.clip_position = vec4<f32>(2.0, 2.0, 0.5, 1.0);
        return out;
    }
    let instance = instances[entry & ((1u << CASCADE_MASK_SHIFT) - 1u)];
#else
    let view = caster_view;
    let instance = instances[entry];
#endif
    let world = vec4<f32>(instance_position(instance, position), 1.0);
    out.clip_position = view.clip_from_world * world;
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
