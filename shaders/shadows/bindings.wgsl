// The shadow bind group (group 3): the frame's lights (the first MAX_LIGHTS in a uniform
// array, the rest in a storage array) and shadow views (a uniform array), one depth array
// per kind of shadow storage (a cube array for point lights), the samplers
// and the Poisson taps. A material does not name these; it calls `penumbra::lights`.
#define_import_path penumbra::shadows::bindings

#import penumbra::shadows::types::{Light, LightList, PoissonTaps, ShadowViewList}

// The frame's first MAX_LIGHTS lights (read through the constant cache: faster per pixel
// than a storage buffer on the GPUs measured).
@group(3) @binding(0) var<uniform> lights: LightList;
@group(3) @binding(1) var<uniform> shadow_views: ShadowViewList;
// Every cascade of every shadowed sun, one layer each.
@group(3) @binding(2) var cascade_maps: texture_depth_2d_array;
// Every shadowed spot light, one layer each.
@group(3) @binding(3) var spot_maps: texture_depth_2d_array;
// Comparison sampler: returns 1 where the reference depth is >= the stored depth (reverse-Z:
// the receiver is at least as close to the light as the nearest caster, so it is lit).
@group(3) @binding(4) var shadow_compare: sampler_comparison;
// Nearest-neighbour sampler for raw depth reads (PCSS blocker search).
@group(3) @binding(5) var shadow_point: sampler;
@group(3) @binding(6) var<uniform> poisson_taps: PoissonTaps;
// Each resolved light's visibility per pixel (layer `Light::resolve_layer`), written by the
// compute resolve before the lighting pass; a 1×1 stand-in when nothing is resolved.
@group(3) @binding(7) var resolved_visibility: texture_2d_array<f32>;
// Every shadowed point light's six faces, sampled as a cube (index: first layer / 6).
@group(3) @binding(8) var point_maps: texture_depth_cube_array;
// Variance shadow maps: the pre-filtered moments (z, z²) of the normalised distance of every
// spot light's layer and point light's cube (1×1 stand-ins while no light uses VSM), and the
// bilinear sampler that filters them.
@group(3) @binding(9) var spot_moments: texture_2d_array<f32>;
@group(3) @binding(10) var point_moments: texture_cube_array<f32>;
@group(3) @binding(11) var moments_sampler: sampler;
// The suns' cascades as EVSM or MSM moments, a layer per cascade (a 1×1 stand-in while no
// sun filters moments): (w, w²) for EVSM2, (w+, w+², w−, w−²) for EVSM4, the quantised
// power moments for MSM.
@group(3) @binding(12) var cascade_moments: texture_2d_array<f32>;
#ifdef MANY_LIGHTS
// The lights past the first MAX_LIGHTS (`frame.light_count` in all; the buffer grows with the
// scene). Declared only in the variants of frames with more lights than that.
@group(3) @binding(13) var<storage, read> more_lights: array<Light>;
#endif
