// Data the shadow library reads: the lights of the frame, the shadow views they render, and
// the Poisson tap patterns. The Rust mirrors are in `render::shadows::gpu` and
// `render::gpu_types`; a test compares both layouts field by field, and the constants come from
// the generated `penumbra::contract`, so neither side counts offsets or flag bits by hand.
#define_import_path penumbra::shadows::types

#import penumbra::contract::{MAX_LIGHTS, MAX_SHADOW_VIEWS}

// One light of the frame (128 bytes). Positions are relative to the render origin.
struct Light {
    // Linear RGB colour times intensity (illuminance for a sun).
    color: vec3<f32>,
    // LIGHT_DIRECTIONAL, LIGHT_SPOT or LIGHT_POINT.
    kind: u32,
    // Position of a spot or point light.
    position: vec3<f32>,
    // Distance past which a spot or point light has no effect, metres.
    range: f32,
    // Direction the light travels (sun, spot), unit length.
    direction: vec3<f32>,
    // Size of the emitter: angular diameter of a sun (radians), radius of a spot or point
    // light (metres).
    size: f32,
    // Spot cone: x = cos(outer angle), y = 1 / (cos(inner) - cos(outer)). VSM (spot, point):
    // z = minimum variance (a fraction of the range squared), w = light-bleed reduction.
    // Sun moments (EVSM, MSM): x = MSM moment bias, y = 1 where MSM moments are stored
    // quantised (16-bit), z = minimum variance (square metres), w = light-bleed reduction.
    cone: vec4<f32>,
    // x: normal offset (texels), y: where a sun's shadows end (view depth), z: cascade blend
    // fraction, w: distance fade fraction.
    shadow_params: vec4<f32>,
    // The light's shadow views are `first_view .. first_view + view_count` (none: 0).
    first_view: u32,
    view_count: u32,
    // SHADOW_FILTER_*.
    shadow_filter: u32,
    // SHADOW_FLAG_* bits.
    flags: u32,
    // PCF kernel radius, texels.
    pcf_radius: u32,
    // Layer of penumbra::shadows::bindings::resolved_visibility holding this light's
    // visibility per pixel, computed before the lighting pass; RESOLVE_NONE when the
    // lighting pass filters the shadow itself.
    resolve_layer: u32,
    // PCSS sample counts: blocker-search taps in bits 0–7, filter taps in bits 8–15.
    pcss_samples: u32,
    // Contact shadows (penumbra::contact): steps of the march, 0 when off.
    contact_steps: u32,
    // Contact shadows: x = length of the march (metres), y = thickness (metres), z = intensity.
    contact: vec3<f32>,
}

// One view a shadow map was rendered from: a cascade of a sun, or a spot light's view
// (128 bytes).
struct ShadowView {
    // Light clip space from world space (reverse-Z).
    clip_from_world: mat4x4<f32>,
    // Cascade: x = world size of one texel, y = light size in UV per metre of depth,
    // z = NDC depth difference -> penumbra width in UV, w = width_x / width_y.
    // Spot: x = world size of one texel per metre of distance, y = near, z = far, w = 0.
    params: vec4<f32>,
    // Cascade: x = view depth where it starts, y = where it ends, z = depth range in metres,
    // w = a moment sun's receiver start: its moments are of the depth d = 1 − z remapped
    // from [w, 1] to [0, 1] (`cascade_moment_depth`).
    range: vec4<f32>,
    // Where the view lies in its layer: xy = UV offset, zw = UV scale.
    rect: vec4<f32>,
    // Layer of the view's storage (the cascades' array or the spot lights' array).
    layer: u32,
    // 1 / side of the view's shadow map in texels.
    texel_size: f32,
    // A sun's moments (EVSM): this cascade's positive and negative warp exponents.
    exponents: vec2<f32>,
    // A paged clipmap level (penumbra::shadows::page_table): xy the grid page of its window's
    // first page, z its page side in texels (0: not paged); `layer` is then its level in the
    // page table. A clipmap level whose layer wraps (it fills its layer, which keeps each
    // texel where it is while the window moves): w = 1, z = 0, xy the UV in the layer of the
    // window's first texel.
    page: vec4<f32>,
}

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

// One entry of a paged clipmap's page table (16 bytes): the physical page of the pool
// holding the grid page (page_x, page_y) of its level, or 0xffffffff (none resident).
struct PageEntry {
    physical: u32,
    page_x: i32,
    page_y: i32,
    padding: u32,
}

// The first MAX_LIGHTS lights of the frame.
struct LightList {
    items: array<Light, MAX_LIGHTS>,
}

// The shadow-view list.
struct ShadowViewList {
    items: array<ShadowView, MAX_SHADOW_VIEWS>,
}

// A point being shaded, as every shadow technique needs it.
struct Surface {
    // World position (relative to the render origin).
    position: vec3<f32>,
    // Unit normal, facing the viewer.
    normal: vec3<f32>,
    // Positive distance along the camera's forward axis.
    view_depth: f32,
    // Pixel position (seeds the per-pixel rotation of the sampling patterns).
    frag_coord: vec2<f32>,
}
