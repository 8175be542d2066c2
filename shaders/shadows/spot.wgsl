// Spot-light shadows: a perspective reverse-Z view per light in the spot lights' depth array.
// The receiver moves along its normal by the light's normal offset in texels at its own
// distance, the receiver-plane gradient comes from projecting the surface's tangent plane
// (planes stay planes under a projective map, so it is exact), PCF is a rotated Poisson disc,
// PCSS uses the perspective penumbra of the blog seed,
// `w_penumbra = (d_receiver − d_blocker) · w_light / d_blocker`, in world units at the
// receiver, and VSM is Chebyshev's bound on the pre-filtered moments: one bilinear fetch, or
// with contact hardening (the default) PCSS's blocker search and moments averaged over the
// penumbra it gives.
// The entry point is `spot_visibility`.
//
// Shader defs: SHADOW_FILTER_PCSS compiles the PCSS path; without it a PCSS light is
// filtered with PCF.
#define_import_path penumbra::shadows::spot

#import penumbra::contract::{
    MAX_PENUMBRA_TEXELS, SHADOW_FILTER_PCSS, SHADOW_FILTER_VSM, SHADOW_FLAG_MOMENT_HARDENING,
    SHADOW_FLAG_RECEIVER_PLANE,
}
#import penumbra::shadows::bindings::{moments_sampler, shadow_views, spot_maps, spot_moments}
#import penumbra::shadows::common::{
    MAX_FILTER_STEP_METRES, MAX_RECEIVER_SLOPE, MAX_TRUE_SLOPE, blocker_samples, filter_samples,
    normal_offset_metres, poisson_rotation, sixteen_tap,
}
#import penumbra::shadows::filters::{
    MapSample, compare_tap, find_blockers, pcf_poisson, pcss_filter, search_settled,
}
#import penumbra::shadows::moments::vsm_covered_visibility
#import penumbra::shadows::types::{Light, ShadowView, Surface}

// A receiver projected into a spot light's view.
struct SpotSample {
    map: MapSample,
    // UV in the view (0..1 inside it) and whether the receiver is in front of the light.
    view_uv: vec2<f32>,
    in_front: bool,
    // Distance from the light along its axis, metres.
    distance: f32,
    // The same after the normal offset (what VSM compares), metres.
    offset_distance: f32,
}

// View UV and reverse-Z depth of a world point (w <= 0: behind the light).
fn spot_project(m: mat4x4<f32>, world: vec3<f32>) -> vec4<f32> {
    let clip = m * vec4<f32>(world, 1.0);
    let ndc = clip.xyz / clip.w;
    return vec4<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5, ndc.z, clip.w);
}

// Distance along the view axis of a reverse-Z depth (the inverse of
// `depth = a·(far − d) / d`, `a = near / (far − near)`); mirrors `math::spot::linear_distance`.
fn spot_linear_distance(depth: f32, near: f32, far: f32) -> f32 {
    let a = near / (far - near);
    return a * far / (clamp(depth, 0.0, 1.0) + a);
}

// World width that the view's whole UV range covers at `distance` along its axis.
fn spot_view_width(view: ShadowView, distance: f32) -> f32 {
    return view.params.x / view.texel_size * distance;
}

// Projects a receiver into the spot light's view, offset along its normal, with the depth
// gradient of its tangent plane in layer UV.
fn project_to_spot(light: Light, view: ShadowView, world_pos: vec3<f32>, normal: vec3<f32>) -> SpotSample {
    let near = view.params.y;
    let far = view.params.z;
    let to_surface = world_pos - light.position;
    let distance = max(dot(to_surface, light.direction), near);
    let texel_metres = view.params.x * distance;
    let travel = normalize(to_surface);
    let offset = normal_offset_metres(normal, travel, light.shadow_params.x, texel_metres);
    let p = world_pos + normal * offset;
    let q = spot_project(view.clip_from_world, p);
    var out: SpotSample;
    out.view_uv = q.xy;
    out.in_front = q.w > 0.0;
    out.distance = distance;
    out.offset_distance = q.w;
    out.map.uv = view.rect.xy + q.xy * view.rect.zw;
    out.map.depth = max(q.z, 0.0);
    out.map.layer = view.layer;
    out.map.texel = view.texel_size * view.rect.z;
    out.map.filter_step = vec2<f32>(out.map.texel * min(1.0, MAX_FILTER_STEP_METRES / max(texel_metres, 1e-30)));
    out.map.dz_duv = vec2<f32>(0.0);
    out.map.dz_duv_true = vec2<f32>(0.0);
    if (light.flags & SHADOW_FLAG_RECEIVER_PLANE) != 0u {
        // Two points of the tangent plane, a twentieth of the distance away.
        let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(normal.x) > 0.9);
        let t1 = normalize(cross(normal, helper));
        let t2 = cross(normal, t1);
        let step = 0.05 * distance;
        let q1 = spot_project(view.clip_from_world, p + t1 * step);
        let q2 = spot_project(view.clip_from_world, p + t2 * step);
        let du1 = q1.xy - q.xy;
        let du2 = q2.xy - q.xy;
        let dz = vec2<f32>(q1.z - q.z, q2.z - q.z);
        let det = du1.x * du2.y - du1.y * du2.x;
        // Steepest gradients allowed: a world slope converted to NDC depth per view UV at this
        // distance (d depth / d distance = a·far / d², world width per UV = width(d)).
        let a = near / (far - near);
        let per_slope = a * far / (distance * distance) * spot_view_width(view, distance);
        let max_true = MAX_TRUE_SLOPE * per_slope;
        let max_gradient = MAX_RECEIVER_SLOPE * per_slope;
        var gradient = vec2<f32>(max_true);
        if abs(det) > 1e-20 {
            gradient = vec2<f32>(dz.x * du2.y - dz.y * du1.y, du1.x * dz.y - du2.x * dz.x) / det;
        }
        let g_true = clamp(gradient, vec2<f32>(-max_true), vec2<f32>(max_true));
        out.map.dz_duv_true = g_true / view.rect.zw;
        out.map.dz_duv = clamp(g_true, vec2<f32>(-max_gradient), vec2<f32>(max_gradient)) / view.rect.zw;
    }
    return out;
}

// What a spot light's blocker search settled: `settled` is 1 (no blocker), 0 (every tap
// blocked, with the light's early-out) or -1 (a penumbra to filter: `radius` in layer UV,
// `count` blocking texels).
struct SpotSearch {
    settled: f32,
    radius: f32,
    count: f32,
}

// Perspective blocker search (PCSS's first step): search the region of the map through which
// the light's disc is seen from the receiver (at most MAX_PENUMBRA_TEXELS), turn the mean
// blocker depth into a distance and give half the penumbra that blocker throws at the
// receiver, in layer UV, at least one filter step.
fn spot_search(light: Light, view: ShadowView, s: SpotSample, rotation: mat2x2<f32>) -> SpotSearch {
    let p = s.map;
    let near = view.params.y;
    let far = view.params.z;
    let light_size = 2.0 * light.size;
    let min_radius = p.filter_step.x;
    let max_radius = MAX_PENUMBRA_TEXELS * p.texel;
    // NOTE: a blocker at distance b hides the disc over `light_size · (d − b) / d` metres at
    // b; in UV that is largest at the near plane.
    let search = 0.5 * light_size * (s.distance - near) / s.distance / spot_view_width(view, near);
    let search_radius = clamp(search * view.rect.z, min_radius, max_radius);
    let blockers = find_blockers(spot_maps, p, search_radius, vec2<f32>(1.0), rotation, blocker_samples(light));
    var out = SpotSearch(search_settled(blockers.count, light), 0.0, blockers.count);
    let blocker = spot_linear_distance(blockers.depth, near, far);
    let penumbra = max(s.distance - blocker, 0.0) * light_size / max(blocker, 1e-6);
    out.radius = clamp(0.5 * penumbra / spot_view_width(view, s.distance) * view.rect.z, min_radius, max_radius);
    return out;
}

#ifdef SHADOW_FILTER_PCSS
// Perspective PCSS: the blocker search, then comparison taps over the penumbra it gives.
fn spot_pcss(light: Light, view: ShadowView, s: SpotSample, rotation: mat2x2<f32>) -> f32 {
    let search = spot_search(light, view, s, rotation);
    if search.settled >= 0.0 {
        return search.settled;
    }
    return pcss_filter(spot_maps, s.map, search.radius, vec2<f32>(1.0), rotation, search.count, filter_samples(light));
}
#endif

// VSM with contact hardening, sized by the emitter as PCSS is: the blocker search gives the
// penumbra's radius, and the moments (pre-blurred by `vsm_blur`) are averaged over 16 rotated
// Poisson fetches of that radius before Chebyshev's bound. A penumbra under a texel (a
// caster's foot) compares the depth itself: no moment filter resolves a gap that small.
fn spot_vsm_hardened(light: Light, view: ShadowView, s: SpotSample, rotation: mat2x2<f32>) -> f32 {
    let search = spot_search(light, view, s, rotation);
    if search.settled >= 0.0 {
        return search.settled;
    }
    if search.radius < s.map.texel {
        return compare_tap(spot_maps, s.map, vec2<f32>(0.0));
    }
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < 16u; i++) {
        let uv = s.map.uv + rotation * sixteen_tap(i) * search.radius;
        sum += textureSampleLevel(spot_moments, moments_sampler, uv, s.map.layer, 0.0).xyz;
    }
    return vsm_covered_visibility(sum / 16.0, s.offset_distance / view.params.z, light.cone.z, light.cone.w);
}

// The fraction of a spot light visible from `surface` (1 lit, 0 shadowed); 1 outside the
// light's view or for a spot light without a shadow.
fn spot_visibility(light: Light, surface: Surface) -> f32 {
    if light.view_count == 0u {
        return 1.0;
    }
    let view = shadow_views.items[light.first_view];
    let s = project_to_spot(light, view, surface.position, surface.normal);
    if !s.in_front || any(s.view_uv < vec2<f32>(0.0)) || any(s.view_uv > vec2<f32>(1.0)) || s.map.depth > 1.0 {
        return 1.0;
    }
    let rotation = poisson_rotation(surface.frag_coord, light.flags);
    if light.shadow_filter == SHADOW_FILTER_VSM {
        if (light.flags & SHADOW_FLAG_MOMENT_HARDENING) != 0u && light.size > 0.0 {
            return spot_vsm_hardened(light, view, s, rotation);
        }
        // Moments of the distance along the axis over the range, pre-filtered.
        let moments = textureSampleLevel(spot_moments, moments_sampler, s.map.uv, s.map.layer, 0.0).xyz;
        return vsm_covered_visibility(moments, s.offset_distance / view.params.z, light.cone.z, light.cone.w);
    }
#ifdef SHADOW_FILTER_PCSS
    if light.shadow_filter == SHADOW_FILTER_PCSS && light.size > 0.0 {
        return spot_pcss(light, view, s, rotation);
    }
#endif
    // PCF: a disc of (radius + 0.5) texels (one tap at radius 0).
    let radius = select(0.0, (f32(light.pcf_radius) + 0.5) * s.map.filter_step.x, light.pcf_radius > 0u);
    return pcf_poisson(spot_maps, s.map, radius, rotation);
}

// 1 where a spot light's shadow is evaluated at `surface` (inside its view), else 0.
fn spot_covers(light: Light, surface: Surface) -> bool {
    if light.view_count == 0u {
        return false;
    }
    let q = spot_project(shadow_views.items[light.first_view].clip_from_world, surface.position);
    return q.w > 0.0 && all(q.xy >= vec2<f32>(0.0)) && all(q.xy <= vec2<f32>(1.0)) && q.z <= 1.0;
}
