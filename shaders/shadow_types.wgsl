// Data the directional shadow library reads. The Rust mirror is `render::gpu_types`; a test
// compares both layouts field by field, so neither side counts offsets by hand.
#define_import_path penumbra::shadow_types

// One cascade of the directional shadow map.
struct ShadowCascade {
    // Light clip space from world space (reverse-Z orthographic, texel-snapped).
    clip_from_world: mat4x4<f32>,
    // x: world size of one texel, y: light size in UV per metre of depth,
    // z: NDC depth difference -> penumbra width in UV, w: width_x / width_y.
    params: vec4<f32>,
    // x: view depth where the cascade starts, y: where it ends, z: depth range in metres.
    range: vec4<f32>,
}

// Flag bits of `ShadowUniforms::flags`.
const SHADOW_FLAG_ENABLED: u32 = 1u;
const SHADOW_FLAG_BLOCKER_EARLY_OUT: u32 = 2u;
const SHADOW_FLAG_RECEIVER_PLANE: u32 = 4u;
const SHADOW_FLAG_TEMPORAL: u32 = 8u;

// The Poisson-disk tap patterns (unit disc), two taps per vec4 (xy, then zw). Filled from
// `math::poisson::STANDARD_SETS`; uniform memory keeps the dynamically indexed taps cheap on
// every GPU (a function-local copy of a constant array may spill to scratch memory).
struct PoissonTaps {
    blocker_sixteen: array<vec4<f32>, 8>,
    blocker_thirty_two: array<vec4<f32>, 16>,
    filter_sixteen: array<vec4<f32>, 8>,
    filter_twenty_five: array<vec4<f32>, 13>,
    filter_forty_nine: array<vec4<f32>, 25>,
}

struct ShadowUniforms {
    cascades: array<ShadowCascade, 4>,
    // Direction the light travels, world space, unit length.
    light_direction: vec3<f32>,
    cascade_count: u32,
    // 1 / shadow-map resolution.
    texel_size: f32,
    // Normal offset in texels.
    normal_offset: f32,
    max_distance: f32,
    // Fraction of a cascade's depth range blended into the next.
    blend_width: f32,
    // Fraction of max_distance over which shadows fade out.
    fade_width: f32,
    pcf_radius: u32,
    flags: u32,
    frame_index: u32,
}
