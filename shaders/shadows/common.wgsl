// Pieces every shadow layout and filter shares: the per-pixel rotation of the sampling
// patterns, the Poisson taps, and the limits that keep biases and kernels finite.
//
#define_import_path penumbra::shadows::common

#import penumbra::contract::SHADOW_FLAG_TEMPORAL
#import penumbra::frame::frame
#import penumbra::shadows::bindings::poisson_taps
#import penumbra::shadows::types::Light

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
// Largest step between filter taps, and smallest filter radius, in metres: in a view whose
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

// Row `i` of the upper 3x3 of a column-major matrix.
fn linear_row(m: mat4x4<f32>, i: u32) -> vec3<f32> {
    return vec3<f32>(m[0][i], m[1][i], m[2][i]);
}

// How far along its normal a receiver moves before it is projected: `texel_metres` times the
// light's normal offset (in texels), growing as the surface turns away from the light
// (MIN_NORMAL_OFFSET_SHARE of it facing the light, all of it at grazing angles), where depth
// changes fastest across a texel; never more than MAX_NORMAL_OFFSET_METRES.
fn normal_offset_metres(normal: vec3<f32>, to_light_travel: vec3<f32>, normal_offset_texels: f32, texel_metres: f32) -> f32 {
    let slope = max(saturate(1.0 - abs(dot(normal, to_light_travel))), MIN_NORMAL_OFFSET_SHARE);
    return min(normal_offset_texels * texel_metres, MAX_NORMAL_OFFSET_METRES) * slope;
}

// Interleaved gradient noise (Jimenez 2014): a per-pixel value in [0, 1) with little
// low-frequency content.
fn interleaved_gradient_noise(pixel: vec2<f32>) -> f32 {
    return fract(52.9829189 * fract(dot(pixel, vec2<f32>(0.06711056, 0.00583715))));
}

// Rotation applied to the Poisson patterns at this pixel (and frame, when the light's flags
// ask for temporal rotation).
fn poisson_rotation(frag_coord: vec2<f32>, flags: u32) -> mat2x2<f32> {
    var n = interleaved_gradient_noise(floor(frag_coord));
    if (flags & SHADOW_FLAG_TEMPORAL) != 0u {
        n = fract(n + f32(frame.frame_index % 4096u) * GOLDEN_RATIO_FRACT);
    }
    let angle = n * TAU;
    let s = sin(angle);
    let c = cos(angle);
    return mat2x2<f32>(vec2<f32>(c, s), vec2<f32>(-s, c));
}

// Tap `i` of a pattern stored two per vec4.
fn unpack_tap(pair: vec4<f32>, i: u32) -> vec2<f32> {
    return select(pair.xy, pair.zw, (i & 1u) == 1u);
}

// The light's PCSS blocker-search taps (16 or 32; `Light::pcss_samples`, bits 0–7).
fn blocker_samples(light: Light) -> u32 {
    return light.pcss_samples & 0xffu;
}

// The light's PCSS filter taps (16, 25 or 49; `Light::pcss_samples`, bits 8–15).
fn filter_samples(light: Light) -> u32 {
    return (light.pcss_samples >> 8u) & 0xffu;
}

// Poisson tap `i` of the blocker search pattern of `samples` taps (unit disc).
fn blocker_tap(i: u32, samples: u32) -> vec2<f32> {
    if samples == 32u {
        return unpack_tap(poisson_taps.blocker_thirty_two[i / 2u], i);
    }
    return unpack_tap(poisson_taps.blocker_sixteen[i / 2u], i);
}

// Poisson tap `i` of the PCSS filter pattern of `samples` taps (unit disc).
fn filter_tap(i: u32, samples: u32) -> vec2<f32> {
    if samples == 49u {
        return unpack_tap(poisson_taps.filter_forty_nine[i / 2u], i);
    }
    if samples == 25u {
        return unpack_tap(poisson_taps.filter_twenty_five[i / 2u], i);
    }
    return unpack_tap(poisson_taps.filter_sixteen[i / 2u], i);
}

// Tap `i` of the 16-tap pattern (spot-light PCF).
fn sixteen_tap(i: u32) -> vec2<f32> {
    return unpack_tap(poisson_taps.filter_sixteen[i / 2u], i);
}
