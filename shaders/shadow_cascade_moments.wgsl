// A sun's moment shadows (EVSM2, EVSM4, MSM): turns each redrawn cascade's depth into the
// moments its technique filters (`resolve`), then pre-filters them with a separable Gaussian
// (`blur`, once along each axis: from the moments into a one-layer scratch, and back), and
// with contact hardening averages them down a mip chain (`downsample`, one level at a time).
// Reverse-Z orthographic depth is linear in the distance from the light, so d = 1 − z grows
// away from the light from 0 (the box's light side) to 1 (its far side).
//
// Shader defs: MOMENTS_RG32 (the moments are `rg32float`: EVSM2 in 32 bits), MOMENTS_RGBA32
// (`rgba32float`), MOMENTS_RGBA16_UNORM (`rgba16unorm`: MSM only), else `rgba16float`.

#import penumbra::shadows::moments::{negative_warp, positive_warp}
#import penumbra::shadows::msm::{msm_moments, msm_quantize}

// `CascadeMomentsJob::technique` (the `SHADOW_FILTER_*` codes of the light).
const TECHNIQUE_EVSM2: u32 = 3u;
const TECHNIQUE_EVSM4: u32 = 4u;

struct CascadeMomentsJob {
    // The cascade's layer in the source (depth, moments or scratch) and the destination.
    src_layer: u32,
    dst_layer: u32,
    // Texels per side of the cascade's view (its corner of the layer).
    size: u32,
    // 3: EVSM2, 4: EVSM4, 5: MSM.
    technique: u32,
    // The warp exponents of this cascade (EVSM).
    c_positive: f32,
    c_negative: f32,
    // Blur radius in texels (the Gaussian's sigma is half of it); 0: no blur.
    radius: f32,
    // Blur: 0 along x, 1 along y. Downsample: the side of the level read, in texels.
    axis: u32,
}

@group(0) @binding(0) var depth_layers: texture_depth_2d_array;
#ifdef MOMENTS_RG32
@group(0) @binding(1) var moments_out: texture_storage_2d_array<rg32float, write>;
#else ifdef MOMENTS_RGBA32
@group(0) @binding(1) var moments_out: texture_storage_2d_array<rgba32float, write>;
#else ifdef MOMENTS_RGBA16_UNORM
@group(0) @binding(1) var moments_out: texture_storage_2d_array<rgba16unorm, write>;
#else
@group(0) @binding(1) var moments_out: texture_storage_2d_array<rgba16float, write>;
#endif
@group(0) @binding(2) var<uniform> job: CascadeMomentsJob;
@group(0) @binding(3) var moments_in: texture_2d_array<f32>;

// The moments of one texel at depth `d` (0 at the light's side).
fn texel_moments(d: f32) -> vec4<f32> {
    if job.technique == TECHNIQUE_EVSM2 {
        let w = positive_warp(d, job.c_positive);
        return vec4<f32>(w, w * w, 0.0, 0.0);
    }
    if job.technique == TECHNIQUE_EVSM4 {
        let p = positive_warp(d, job.c_positive);
        let n = negative_warp(d, job.c_negative);
        return vec4<f32>(p, p * p, n, n * n);
    }
#ifdef MOMENTS_RG32
    return msm_moments(d);
#else ifdef MOMENTS_RGBA32
    // 32-bit channels hold the raw power moments.
    return msm_moments(d);
#else
    // 16-bit channels need the optimised quantisation.
    return msm_quantize(msm_moments(d));
#endif
}

// Depth to moments: one invocation per texel of the cascade's view.
@compute @workgroup_size(8, 8, 1)
fn resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= job.size || id.y >= job.size {
        return;
    }
    let z = clamp(textureLoad(depth_layers, id.xy, job.src_layer, 0), 0.0, 1.0);
    textureStore(moments_out, id.xy, job.dst_layer, texel_moments(1.0 - z));
}

// One axis of the separable Gaussian pre-blur; taps past the view's edge repeat its edge
// texel (the view may not fill its layer, and the next view's texels are not its own).
@compute @workgroup_size(8, 8, 1)
fn blur(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= job.size || id.y >= job.size {
        return;
    }
    let r = i32(ceil(job.radius));
    let sigma = max(0.5 * job.radius, 0.5);
    let step = select(vec2<i32>(1, 0), vec2<i32>(0, 1), job.axis == 1u);
    let last = i32(job.size) - 1;
    var sum = vec4<f32>(0.0);
    var weights = 0.0;
    for (var k = -r; k <= r; k++) {
        let w = exp(-0.5 * f32(k * k) / (sigma * sigma));
        let texel = clamp(vec2<i32>(id.xy) + step * k, vec2<i32>(0), vec2<i32>(last));
        sum += w * textureLoad(moments_in, texel, job.src_layer, 0);
        weights += w;
    }
    textureStore(moments_out, id.xy, job.dst_layer, sum / weights);
}

// One mip level of the cascade's view from the level before: the mean of the 2×2 texels each
// texel covers (an odd side repeats its last texel).
@compute @workgroup_size(8, 8, 1)
fn downsample(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= job.size || id.y >= job.size {
        return;
    }
    let last = vec2<i32>(i32(job.axis) - 1);
    let base = vec2<i32>(id.xy) * 2;
    var sum = vec4<f32>(0.0);
    for (var k = 0; k < 4; k++) {
        let texel = min(base + vec2<i32>(k & 1, k >> 1u), last);
        sum += textureLoad(moments_in, texel, job.src_layer, 0);
    }
    textureStore(moments_out, id.xy, job.dst_layer, 0.25 * sum);
}
