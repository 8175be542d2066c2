// Moment shadow tests shared by every filterable-moments technique (variance shadow maps of
// point and spot lights; EVSM for the sun): Chebyshev's upper bound on the lit fraction from
// the first two moments of the occluders' depth, a variance floor, and light-bleed reduction.
// Depth here grows away from the light (linear distance over range, or a warped depth).
// `src/math/moments.rs` mirrors these functions on the CPU.
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
