// Moment shadow mapping (Peters & Klein 2015, "Moment Shadow Mapping"): the four moments
// (z, z², z³, z⁴) of a depth, the paper's optimised quantisation that lets them be stored in
// 16-bit channels, and the Hamburger 4MSM bound (the paper's Algorithm 2) on the lit fraction
// of a receiver from filtered moments. Depth grows away from the light in [0, 1].
// `src/math/msm.rs` mirrors these functions on the CPU, line for line.
#define_import_path penumbra::shadows::msm

// Moment biases: for moments stored in 16-bit channels with `msm_quantize` (the paper's
// value, made for 16-bit unorm), and for raw moments stored and filtered as 32-bit floats
// (moments quantised in f32 want about 1e-5; `src/math/msm.rs` has the measurements).
const MSM_BIAS_16: f32 = 3e-5;
const MSM_BIAS_32: f32 = 3e-6;

// Below this the variance b₂ − b₁² is taken as a single depth at the mean.
const MSM_MIN_VARIANCE: f32 = 1e-10;
// Floor on the third Cholesky pivot (the same as raising the fourth moment): covers depths
// only at 0 and 1, whose biased moments have a singular Hankel matrix, and 16-bit rounding.
const MSM_MIN_PIVOT: f32 = 3e-8;
// Floor on the quadratic's leading coefficient, relative to the others.
const MSM_MIN_LEADING: f32 = 1e-6;

// The quantisation: stored = Q·moments + (MSM_QUANTIZE_OFFSET, 0, 0, 0). The constructor
// takes columns: column i weighs moment i.
const MSM_QUANTIZE: mat4x4<f32> = mat4x4<f32>(
    vec4<f32>(-2.0722466, 13.794886, 0.105877705, 9.792406),
    vec4<f32>(32.237038, -59.4684, -1.9077467, -33.76521),
    vec4<f32>(-68.571075, 82.03597, 9.349655, 47.94561),
    vec4<f32>(39.370327, -35.364902, -6.654349, -23.972805),
);
// Its inverse; column i weighs stored channel i.
const MSM_DEQUANTIZE: mat4x4<f32> = mat4x4<f32>(
    vec4<f32>(0.22277442, 0.15496792, 0.1451989, 0.16312744),
    vec4<f32>(0.07719728, 0.13946295, 0.21202022, 0.25914323),
    vec4<f32>(0.7926987, 0.7963416, 0.7258694, 0.65390927),
    vec4<f32>(0.031941757, -0.17228232, -0.27580148, -0.33761317),
);
// Added to the first quantised channel so every stored value lies in [0, 1].
const MSM_QUANTIZE_OFFSET: f32 = 0.035955884;

// The four moments (z, z², z³, z⁴) of a depth z in [0, 1].
fn msm_moments(depth: f32) -> vec4<f32> {
    let square = depth * depth;
    return vec4<f32>(depth, square, square * depth, square * square);
}

// The paper's optimised quantisation: spreads the nearly collinear moments of depths in
// [0, 1] over the whole of [0, 1] in every channel, so 16-bit storage keeps them apart.
fn msm_quantize(moments: vec4<f32>) -> vec4<f32> {
    return MSM_QUANTIZE * moments + vec4<f32>(MSM_QUANTIZE_OFFSET, 0.0, 0.0, 0.0);
}

// The inverse of `msm_quantize`: the moments back from the stored (filtered) values.
fn msm_dequantize(stored: vec4<f32>) -> vec4<f32> {
    return MSM_DEQUANTIZE * (stored - vec4<f32>(MSM_QUANTIZE_OFFSET, 0.0, 0.0, 0.0));
}

// The lit fraction (1 lit, 0 shadowed) of a receiver at `depth` from filtered, dequantised
// moments: the Hamburger 4MSM bound. The moments are first mixed with (0.5, 0.5, 0.5, 0.5)
// (half the footprint at 0, half at 1) by `moment_bias`, which keeps the Hankel matrix
// invertible; degenerate moments give a step at their depth, never NaN.
fn msm_visibility(stored_moments_dequantized: vec4<f32>, depth: f32, moment_bias: f32) -> f32 {
    let b = mix(stored_moments_dequantized, vec4<f32>(0.5), moment_bias);
    let z0 = depth;
    if b.y - b.x * b.x <= MSM_MIN_VARIANCE {
        return select(0.0, 1.0, z0 <= b.x);
    }
    let nodes = msm_nodes(b, z0);
    let z2 = nodes.x;
    let z3 = nodes.y;
    // The shadow intensity: the bound's weight on the nodes in front of the receiver.
    var shadow = 0.0;
    if z0 <= z2 {
        shadow = 0.0;
    } else if z0 <= z3 {
        shadow = (z0 * z3 - b.x * (z0 + z3) + b.y) / max((z3 - z2) * (z0 - z2), 1e-30);
    } else {
        shadow = 1.0 - (z2 * z3 - b.x * (z2 + z3) + b.y) / max((z0 - z2) * (z0 - z3), 1e-30);
    }
    return clamp(1.0 - shadow, 0.0, 1.0);
}

// The two nodes z₂ ≤ z₃ that, with the receiver's depth z₀, carry the Hamburger bound's
// distribution for biased moments `b` (whose variance is above MSM_MIN_VARIANCE).
fn msm_nodes(b: vec4<f32>, z0: f32) -> vec2<f32> {
    // Cholesky decomposition B = L·D·Lᵀ of the Hankel matrix B = [[1, b₁, b₂], [b₁, b₂, b₃],
    // [b₂, b₃, b₄]]: L's lower entries b₁, b₂, l32 and D's pivots 1, d22, d33.
    let d22 = b.y - b.x * b.x;
    let l32_d22 = b.z - b.x * b.y;
    let l32 = l32_d22 / d22;
    let d33 = max(b.w - b.y * b.y - l32 * l32_d22, MSM_MIN_PIVOT);
    // Solve B·c = (1, z₀, z₀²): forward substitution, the pivots, backward substitution.
    let y1 = z0 - b.x;
    let y2 = z0 * z0 - b.y - l32 * y1;
    let c3_raw = y2 / d33;
    let c2 = y1 / d22 - l32 * c3_raw;
    let c1 = 1.0 - b.x * c2 - b.y * c3_raw;
    // The other two nodes z₂ ≤ z₃: the roots of c₃·z² + c₂·z + c₁.
    let lead = max(max(abs(c3_raw), MSM_MIN_LEADING * max(abs(c1), abs(c2))), 1e-30);
    let c3 = select(lead, -lead, c3_raw < 0.0);
    let p = c2 / c3;
    let q = c1 / c3;
    let r = sqrt(max(0.25 * p * p - q, 0.0));
    let z2 = -0.5 * p - r;
    let z3 = -0.5 * p + r;
    return vec2<f32>(z2, z3);
}
