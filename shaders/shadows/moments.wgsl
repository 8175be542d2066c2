// Moment shadow tests shared by every filterable-moments technique (variance shadow maps of
// point and spot lights; EVSM for the sun): Chebyshev's upper bound on the lit fraction from
// the first two moments of the occluders' depth, a variance floor, and light-bleed reduction.
// Depth here grows away from the light (linear distance over range, or a warped depth).
// `src/math/moments.rs` and `src/math/evsm.rs` mirror these functions on the CPU.
#define_import_path penumbra::shadows::moments

// Chebyshev's one-sided bound on the fraction of the filter footprint farther from the light
// than `depth`: 1 when the receiver is no farther than the mean occluder; else
// σ² / (σ² + (depth − μ)²), with σ² floored at `min_variance`.
fn chebyshev_upper_bound(moments: vec2<f32>, depth: f32, min_variance: f32) -> f32 {
    let mean = moments.x;
    if depth <= mean {
        return 1.0;
    }
    let variance = max(moments.y - mean * mean, min_variance);
    let d = depth - mean;
    return variance / (variance + d * d);
}

// Light-bleed reduction: the bound's low tail (where bleeding lives) clips to 0 and the rest
// is stretched back over [0, 1].
fn reduce_light_bleeding(p_max: f32, amount: f32) -> f32 {
    let a = clamp(amount, 0.0, 0.999);
    return clamp((p_max - a) / (1.0 - a), 0.0, 1.0);
}

// The visibility of a receiver at `depth` from filtered moments.
fn moments_visibility(moments: vec2<f32>, depth: f32, min_variance: f32, bleed: f32) -> f32 {
    return reduce_light_bleeding(chebyshev_upper_bound(moments, depth, min_variance), bleed);
}

// Exponential warps (EVSM; `src/math/evsm.rs` mirrors them) of a depth growing away from the
// light (0..1): the positive warp exp(c·d) and the negative warp −exp(−c·d). The exponent is
// bounded by the moment format (the second moment reaches exp(2c)).
fn positive_warp(depth: f32, c: f32) -> f32 {
    return exp(c * depth);
}

fn negative_warp(depth: f32, c: f32) -> f32 {
    return -exp(-c * depth);
}

// Chebyshev's bound in one warped space, the variance floor (depth units squared) scaled by
// the warp's derivative `slope` at the receiver.
fn warped_bound(moments: vec2<f32>, warped: f32, slope: f32, min_variance: f32) -> f32 {
    return chebyshev_upper_bound(moments, warped, min_variance * slope * slope);
}

// EVSM2: visibility from filtered positive-warp moments (w, w²).
fn evsm2_visibility(moments: vec2<f32>, depth: f32, c: f32, min_variance: f32, bleed: f32) -> f32 {
    let w = positive_warp(depth, c);
    return reduce_light_bleeding(warped_bound(moments, w, c * w, min_variance), bleed);
}

// EVSM4: the smaller of the positive and negative warps' bounds, from (w+, w+², w−, w−²).
fn evsm4_visibility(moments: vec4<f32>, depth: f32, c_positive: f32, c_negative: f32, min_variance: f32, bleed: f32) -> f32 {
    let p = positive_warp(depth, c_positive);
    let n = negative_warp(depth, c_negative);
    let positive = warped_bound(moments.xy, p, c_positive * p, min_variance);
    let negative = warped_bound(moments.zw, n, -c_negative * n, min_variance);
    return reduce_light_bleeding(min(positive, negative), bleed);
}

// Smallest coverage `evsm2_covered_visibility` divides by (`math::evsm::MIN_COVERAGE`).
const MIN_COVERAGE: f32 = 1.0e-4;

// EVSM2 from filtered covered moments (o·w, o·w², o; o is 1 where a caster was drawn, 0 in an
// empty texel): the footprint's empty share is lit, its occupied share gets the bound of the
// occupied texels' own moments. Without coverage an empty texel stands for the farthest
// depth, whose warp outweighs any occluder's.
fn evsm2_covered_visibility(moments: vec4<f32>, depth: f32, c: f32, min_variance: f32, bleed: f32) -> f32 {
    let coverage = saturate(moments.z);
    if coverage < MIN_COVERAGE {
        return 1.0;
    }
    let lit = evsm2_visibility(moments.xy / coverage, depth, c, min_variance, bleed);
    return 1.0 - coverage + coverage * lit;
}

// VSM (spot and point lights) from filtered covered moments (o·z, o·z², o; o as above): the
// empty share is lit, the occupied share gets Chebyshev's bound of the occupied texels' own
// moments. Without coverage an empty texel stands for the farthest distance, and a footprint
// reaching past a caster's edge over a receiver that casts nothing reads as lit.
fn vsm_covered_visibility(moments: vec3<f32>, depth: f32, min_variance: f32, bleed: f32) -> f32 {
    let coverage = saturate(moments.z);
    if coverage < MIN_COVERAGE {
        return 1.0;
    }
    let lit = moments_visibility(moments.xy / coverage, depth, min_variance, bleed);
    return 1.0 - coverage + coverage * lit;
}
