// Directional cascaded shadow sampling: cascade selection, PCF, PCSS, cascade blend and
// distance fade. A material imports this module and calls `blend_cascade_shadow` once per
// fragment; it reserves bindings 1-5 of group 0 (the view group).
//
// Shader defs:
//   SHADOW_FILTER_PCSS              PCSS instead of the PCF grid
//   PCSS_BLOCKER_SAMPLES (16 | 32)  blocker search taps
//   PCSS_FILTER_SAMPLES (16|25|49)  filter taps
#define_import_path penumbra::shadow

#import penumbra::shadow_types::{
    PoissonTaps, ShadowUniforms, SHADOW_FLAG_ENABLED, SHADOW_FLAG_BLOCKER_EARLY_OUT,
    SHADOW_FLAG_RECEIVER_PLANE, SHADOW_FLAG_TEMPORAL,
}

@group(0) @binding(1) var<uniform> shadow: ShadowUniforms;
@group(0) @binding(2) var shadow_map: texture_depth_2d_array;
// Comparison sampler: returns 1 where the reference depth is >= the stored depth (reverse-Z:
// the receiver is at least as close to the light as the nearest caster, so it is lit).
@group(0) @binding(3) var shadow_compare: sampler_comparison;
// Nearest-neighbour sampler for raw depth reads (PCSS blocker search).
@group(0) @binding(4) var shadow_point: sampler;
@group(0) @binding(5) var<uniform> poisson_taps: PoissonTaps;

// Largest PCSS kernel radius, in texels: bounds the cost where layered casters make the
// average blocker depth far from the receiver.
const MAX_PENUMBRA_TEXELS: f32 = 32.0;
// Steepest receiver slope (world depth change per metre sideways) the receiver-plane bias
// follows; steeper surfaces are treated as this slope, which keeps the bias finite at grazing
// angles.
const MAX_RECEIVER_SLOPE: f32 = 40.0;
// Receiver-plane bias leaves this much extra depth (in texels of slope) for quantisation.
const RECEIVER_PLANE_EPSILON_TEXELS: f32 = 0.5;
// Steepest receiver slope PCSS's true-plane comparison follows: a surface within 0.006° of
// the light direction; it only keeps the gradient finite (a surface containing the light
// direction has an infinite one).
const MAX_TRUE_SLOPE: f32 = 1.0e4;
// Largest step between filter taps, and smallest filter radius, in metres: in a cascade whose
// texels are larger (very wide views, far cascades) the kernel shrinks below a texel instead
// of smearing each shadow edge over several large texels.
const MAX_FILTER_STEP_METRES: f32 = 0.01;
// Largest normal offset, in metres: large texels would otherwise move a receiver out of a
// thin umbra.
const MAX_NORMAL_OFFSET_METRES: f32 = 0.02;
// Share of the normal offset applied to a surface that faces the light: it still moves a
// little towards the light, so its own depth never ties with the stored one.
const MIN_NORMAL_OFFSET_SHARE: f32 = 0.1;
const GOLDEN_RATIO_FRACT: f32 = 0.618033988749;
const TAU: f32 = 6.283185307;

// Which cascade a fragment samples, and how far it is into the blend band towards the next.
struct CascadeSelection {
    index: u32,
    // 0 inside the cascade, rising to 1 at its far end when blending is on.
    blend: f32,
}

// A receiver projected into one cascade.
struct ShadowProjection {
    uv: vec2<f32>,
    // Reverse-Z depth of the receiver in the cascade (1 near the light, 0 far).
    depth: f32,
    // Receiver-plane depth gradient: change of depth per unit of UV, at most
    // MAX_RECEIVER_SLOPE.
    dz_duv: vec2<f32>,
    // The same gradient clamped only to MAX_TRUE_SLOPE, for PCSS (see `pcss_tap_depth`).
    dz_duv_true: vec2<f32>,
    layer: u32,
    // Step between filter taps in UV along u and v: one texel, or less where a texel is wider
    // than MAX_FILTER_STEP_METRES.
    filter_step: vec2<f32>,
}

// Maps a view-space depth to a cascade and a blend factor towards the next cascade.
fn select_cascade(view_depth: f32) -> CascadeSelection {
    let count = max(shadow.cascade_count, 1u);
    var index = count - 1u;
    for (var i = 0u; i < count; i++) {
        if view_depth < shadow.cascades[i].range.y {
            index = i;
            break;
        }
    }
    var blend = 0.0;
    if index + 1u < count {
        let near = shadow.cascades[index].range.x;
        let far = shadow.cascades[index].range.y;
        let width = shadow.blend_width * (far - near);
        if width > 0.0 {
            blend = saturate((view_depth - (far - width)) / width);
        }
    }
    return CascadeSelection(index, blend);
}

// 1 where shadows are at full strength, falling smoothly to 0 at max_distance.
fn shadow_distance_fade(view_depth: f32) -> f32 {
    let end = shadow.max_distance;
    let width = shadow.fade_width * end;
    if width <= 0.0 {
        return select(0.0, 1.0, view_depth < end);
    }
    return 1.0 - smoothstep(end - width, end, view_depth);
}

// Row `i` of the upper 3x3 of a column-major matrix.
fn linear_row(m: mat4x4<f32>, i: u32) -> vec3<f32> {
    return vec3<f32>(m[0][i], m[1][i], m[2][i]);
}

// Projects a receiver into cascade `index`, offset along its normal, and derives the depth
// gradient of the receiver's plane in shadow UV space.
//
// NOTE: the gradient comes from the surface normal, not from screen-space derivatives: it
// needs no uniform control flow, is defined at cascade and silhouette edges (where
// derivatives mix unrelated pixels), and costs a few dot products. For the plane n·p = c, the
// map world -> (u, v, z) has rows a_i; the plane's covector in (u, v, z) is
// m_i = (a_i · n) / |a_i|², so dz = -(m.x du + m.y dv) / m.z.
fn project_to_cascade(index: u32, world_pos: vec3<f32>, normal: vec3<f32>) -> ShadowProjection {
    let cascade = shadow.cascades[index];
    let m = cascade.clip_from_world;
    let texel_world = cascade.params.x;
    // NOTE: the offset grows as the surface turns away from the light (MIN_NORMAL_OFFSET_SHARE
    // of it facing the light, the full normal_offset at grazing angles), where depth changes
    // fastest across a texel; it never exceeds MAX_NORMAL_OFFSET_METRES.
    let slope = max(saturate(1.0 - abs(dot(normal, shadow.light_direction))), MIN_NORMAL_OFFSET_SHARE);
    let offset = min(shadow.normal_offset * texel_world, MAX_NORMAL_OFFSET_METRES) * slope;
    let offset_pos = world_pos + normal * offset;
    let clip = m * vec4<f32>(offset_pos, 1.0);
    var out: ShadowProjection;
    out.uv = vec2<f32>(clip.x * 0.5 + 0.5, 0.5 - clip.y * 0.5);
    // NOTE: a receiver past the box's far plane (depth < 0) is compared as if on it: a
    // stored caster (depth > 0) still shadows it, an empty texel (cleared to 0) does not.
    out.depth = max(clip.z, 0.0);
    out.layer = index;
    // World size of a texel along u and along v (params.w is width_x / width_y).
    let texel_metres = vec2<f32>(texel_world, texel_world / max(cascade.params.w, 1e-30));
    out.filter_step = shadow.texel_size * min(vec2<f32>(1.0), MAX_FILTER_STEP_METRES / max(texel_metres, vec2<f32>(1e-30)));
    out.dz_duv = vec2<f32>(0.0);
    out.dz_duv_true = vec2<f32>(0.0);
    if (shadow.flags & SHADOW_FLAG_RECEIVER_PLANE) != 0u {
        let a0 = linear_row(m, 0u) * 0.5;
        let a1 = linear_row(m, 1u) * -0.5;
        let a2 = linear_row(m, 2u);
        let cov = vec3<f32>(
            dot(a0, normal) / max(dot(a0, a0), 1e-30),
            dot(a1, normal) / max(dot(a1, a1), 1e-30),
            dot(a2, normal) / max(dot(a2, a2), 1e-30),
        );
        // Largest gradient allowed: MAX_RECEIVER_SLOPE in world units, converted to NDC depth
        // per UV (width_x / depth_range).
        let width_x = texel_world / shadow.texel_size;
        let max_gradient = MAX_RECEIVER_SLOPE * width_x / max(cascade.range.z, 1e-6);
        let denom = select(cov.z, 1e-30, abs(cov.z) < 1e-30);
        let max_true = MAX_TRUE_SLOPE * width_x / max(cascade.range.z, 1e-6);
        out.dz_duv_true = clamp(-cov.xy / denom, vec2<f32>(-max_true), vec2<f32>(max_true));
        out.dz_duv = clamp(out.dz_duv_true, vec2<f32>(-max_gradient), vec2<f32>(max_gradient));
    }
    return out;
}

// Comparison depth for a tap at `offset_uv` from the receiver: the receiver plane's depth
// there, moved towards the light by a fraction of a texel of slope.
fn tap_depth(p: ShadowProjection, offset_uv: vec2<f32>) -> f32 {
    let slack = RECEIVER_PLANE_EPSILON_TEXELS * shadow.texel_size
        * (abs(p.dz_duv.x) + abs(p.dz_duv.y));
    return p.depth + dot(p.dz_duv, offset_uv) + slack;
}

// One hardware 2x2 comparison tap: 1 lit, 0 shadowed.
fn compare_tap(p: ShadowProjection, offset_uv: vec2<f32>) -> f32 {
    return textureSampleCompareLevel(
        shadow_map, shadow_compare, p.uv + offset_uv, p.layer, tap_depth(p, offset_uv)
    );
}

// Fixed (2R+1)² grid of comparison taps, one texel apart.
fn sample_shadow_pcf(p: ShadowProjection) -> f32 {
    let r = i32(min(shadow.pcf_radius, 5u));
    var sum = 0.0;
    for (var y = -r; y <= r; y++) {
        for (var x = -r; x <= r; x++) {
            sum += compare_tap(p, vec2<f32>(f32(x), f32(y)) * p.filter_step);
        }
    }
    let side = f32(2 * r + 1);
    return sum / (side * side);
}

// Interleaved gradient noise (Jimenez 2014): a per-pixel value in [0, 1) with little
// low-frequency content.
fn interleaved_gradient_noise(pixel: vec2<f32>) -> f32 {
    return fract(52.9829189 * fract(dot(pixel, vec2<f32>(0.06711056, 0.00583715))));
}

// Rotation applied to the Poisson patterns at this pixel (and frame, when temporal).
fn poisson_rotation(frag_coord: vec2<f32>) -> mat2x2<f32> {
    var n = interleaved_gradient_noise(floor(frag_coord));
    if (shadow.flags & SHADOW_FLAG_TEMPORAL) != 0u {
        n = fract(n + f32(shadow.frame_index % 4096u) * GOLDEN_RATIO_FRACT);
    }
    let angle = n * TAU;
    let s = sin(angle);
    let c = cos(angle);
    return mat2x2<f32>(vec2<f32>(c, s), vec2<f32>(-s, c));
}

#ifdef SHADOW_FILTER_PCSS
// Comparison depth of a PCSS tap: `tap_depth`, or the true (unclamped) receiver plane where
// that is nearer the light. A stored depth behind the receiver's own tangent plane cannot
// shade it, but where the slope was clamped the clamped plane falls behind the surface on the
// side that rises towards the light, and PCSS's wide search and kernel then find the
// receiver's own faces there (a caster's top face under a sun 0.5° above the horizon).
//
// NOTE: the true plane carries no slack: the slack scales with the slope, and 0.5 texel of an
// uncapped slope (115 at 0.5°) lets real blockers a metre away fail (10.6 % of the umbra lit
// with MAX_RECEIVER_SLOPE at 200). PCF keeps `tap_depth` alone: its kernel spans about a
// texel, where the clamped plane plus slack already holds, and the true plane there only lit
// more contact shadow (5 of 498 umbra pixels instead of 3 under that sun).
fn pcss_tap_depth(p: ShadowProjection, offset_uv: vec2<f32>) -> f32 {
    return max(tap_depth(p, offset_uv), p.depth + dot(p.dz_duv_true, offset_uv));
}

// Tap `i` of a pattern stored two per vec4.
fn unpack_tap(pair: vec4<f32>, i: u32) -> vec2<f32> {
    return select(pair.xy, pair.zw, (i & 1u) == 1u);
}

// Poisson tap `i` of the blocker search pattern (unit disc).
fn blocker_tap(i: u32) -> vec2<f32> {
#if PCSS_BLOCKER_SAMPLES == 32
    return unpack_tap(poisson_taps.blocker_thirty_two[i / 2u], i);
#else
    return unpack_tap(poisson_taps.blocker_sixteen[i / 2u], i);
#endif
}

// Poisson tap `i` of the filter pattern (unit disc).
fn filter_tap(i: u32) -> vec2<f32> {
#if PCSS_FILTER_SAMPLES == 49
    return unpack_tap(poisson_taps.filter_forty_nine[i / 2u], i);
#else if PCSS_FILTER_SAMPLES == 25
    return unpack_tap(poisson_taps.filter_twenty_five[i / 2u], i);
#else
    return unpack_tap(poisson_taps.filter_sixteen[i / 2u], i);
#endif
}

// Percentage-closer soft shadows: average the depth of occluders found around the receiver,
// size the filter from the receiver-blocker distance, then filter with that kernel.
fn sample_shadow_pcss(p: ShadowProjection, frag_coord: vec2<f32>) -> f32 {
    let cascade = shadow.cascades[p.layer];
    let pcss_scale = cascade.params.z;
    let aspect = vec2<f32>(1.0, cascade.params.w);
    let texel = shadow.texel_size;
    // Smallest kernel radius in u units (the kernel's v extent is the radius times aspect.y).
    let min_radius = min(p.filter_step.x, p.filter_step.y / aspect.y);
    let rotation = poisson_rotation(frag_coord);

    // Blocker search: the widest penumbra any caster between the light-side plane and the
    // receiver could throw, bounded to MAX_PENUMBRA_TEXELS.
    let search_radius = clamp(0.5 * (1.0 - p.depth) * pcss_scale, min_radius, MAX_PENUMBRA_TEXELS * texel);
    var blocker_sum = 0.0;
    var blocker_count = 0.0;
    for (var i = 0u; i < u32(#{PCSS_BLOCKER_SAMPLES}); i++) {
        let offset = rotation * blocker_tap(i) * search_radius * aspect;
        let depths = textureGather(shadow_map, shadow_point, p.uv + offset, p.layer);
        let reference = pcss_tap_depth(p, offset);
        let is_blocker = vec4<f32>(depths > vec4<f32>(reference));
        blocker_sum += dot(depths, is_blocker);
        blocker_count += dot(is_blocker, vec4<f32>(1.0));
    }
    if blocker_count == 0.0 {
        return 1.0;
    }
    let total_taps = 4.0 * f32(#{PCSS_BLOCKER_SAMPLES});
    if (shadow.flags & SHADOW_FLAG_BLOCKER_EARLY_OUT) != 0u && blocker_count >= total_taps {
        return 0.0;
    }

    // Penumbra: full width = distance to the blockers times 2 tan(θ/2); the filter radius is
    // half of it.
    let blocker_depth = blocker_sum / blocker_count;
    let penumbra = 0.5 * max(blocker_depth - p.depth, 0.0) * pcss_scale;
    let radius = clamp(penumbra, min_radius, MAX_PENUMBRA_TEXELS * texel);

    var lit = 0.0;
    for (var i = 0u; i < u32(#{PCSS_FILTER_SAMPLES}); i++) {
        let offset = rotation * filter_tap(i) * radius * aspect;
        lit += textureSampleCompareLevel(
            shadow_map, shadow_compare, p.uv + offset, p.layer, pcss_tap_depth(p, offset)
        );
    }
    lit /= f32(#{PCSS_FILTER_SAMPLES});
    // Few blockers found means the search only grazed the penumbra's outer edge: fade
    // towards lit instead of cutting off.
    return mix(1.0, lit, smoothstep(0.0, 4.0, blocker_count));
}
#endif

// Shadow factor from one cascade with the configured filter.
fn sample_cascade(index: u32, world_pos: vec3<f32>, normal: vec3<f32>, frag_coord: vec2<f32>) -> f32 {
    let p = project_to_cascade(index, world_pos, normal);
    if any(p.uv < vec2<f32>(0.0)) || any(p.uv > vec2<f32>(1.0)) || p.depth > 1.0 {
        return 1.0;
    }
#ifdef SHADOW_FILTER_PCSS
    return sample_shadow_pcss(p, frag_coord);
#else
    return sample_shadow_pcf(p);
#endif
}

// The one entry point for materials: the fraction of the sun visible from `world_pos`
// (1 lit, 0 shadowed), with cascade blending and distance fade. `normal` is the unit
// world-space surface normal facing the viewer, `view_depth` the positive distance along the
// camera's forward axis, `frag_coord` the fragment's pixel position.
fn blend_cascade_shadow(
    world_pos: vec3<f32>,
    normal: vec3<f32>,
    view_depth: f32,
    frag_coord: vec2<f32>,
) -> f32 {
    if (shadow.flags & SHADOW_FLAG_ENABLED) == 0u || view_depth >= shadow.max_distance {
        return 1.0;
    }
    let selection = select_cascade(view_depth);
    var visibility = sample_cascade(selection.index, world_pos, normal, frag_coord);
    if selection.blend > 0.0 {
        let next = sample_cascade(selection.index + 1u, world_pos, normal, frag_coord);
        visibility = mix(visibility, next, selection.blend);
    }
    return mix(1.0, visibility, shadow_distance_fade(view_depth));
}

// The cascade a fragment at `view_depth` samples, or -1 when shadows are off or it lies past
// max_distance (for analysis outputs and debug views).
fn shadow_cascade_index(view_depth: f32) -> i32 {
    if (shadow.flags & SHADOW_FLAG_ENABLED) == 0u || view_depth >= shadow.max_distance {
        return -1;
    }
    return i32(select_cascade(view_depth).index);
}

// Debug colour of the cascade a fragment samples (red, green, blue, yellow), blended like
// the shadow itself; grey beyond max_distance.
fn cascade_debug_color(view_depth: f32) -> vec3<f32> {
    var colors = array<vec3<f32>, 4>(
        vec3<f32>(1.0, 0.25, 0.25),
        vec3<f32>(0.25, 1.0, 0.25),
        vec3<f32>(0.3, 0.45, 1.0),
        vec3<f32>(1.0, 1.0, 0.25),
    );
    if view_depth >= shadow.max_distance {
        return vec3<f32>(0.5);
    }
    let selection = select_cascade(view_depth);
    let next = min(selection.index + 1u, 3u);
    return mix(colors[selection.index], colors[next], selection.blend);
}
