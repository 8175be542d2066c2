// Point-light shadows: six 90° reverse-Z faces per light in the point lights' cube array,
// sampled along the light-to-receiver direction, so the hardware picks the face and filters
// across face edges. A face stores the depth of the distance along its own axis
// (`math::point::face_depth`); a tap recomputes it from its direction's major axis.
//
// Filtering works on the tangent basis of the light-to-receiver direction (blog seed): a tap
// is the receiver moved sideways by a rotated Poisson offset in metres, then re-aimed from the
// light. Its comparison depth is where that ray meets the receiver's tangent plane
// (receiver-plane bias, exact for planes: no self-shadowing of tilted surfaces under a wide
// kernel), or the receiver's own distance when the light's receiver-plane flag is off. PCSS
// searches blockers over the region through which the light's disc is seen and filters with
// `w_penumbra = (d_receiver − d_blocker) · w_light / d_blocker` in metres at the receiver.
// VSM reads the moments of the distance from the light, pre-filtered across face edges: one
// bilinear fetch, or with contact hardening (the default) moments averaged over the penumbra
// PCSS's blocker search gives. The entry point is `point_visibility`.
//
// Shader defs: SHADOW_FILTER_PCSS compiles the PCSS path; without it a PCSS light is
// filtered with PCF.
#define_import_path penumbra::shadows::point

#import penumbra::contract::{
    MAX_PENUMBRA_TEXELS, SHADOW_FILTER_PCSS, SHADOW_FILTER_VSM, SHADOW_FLAG_MOMENT_HARDENING,
    SHADOW_FLAG_RECEIVER_PLANE,
}
#import penumbra::shadows::bindings::{
    moments_sampler, point_maps, point_moments, shadow_compare, shadow_point, shadow_views,
}
#import penumbra::shadows::common::{
    MAX_FILTER_STEP_METRES, RECEIVER_PLANE_EPSILON_TEXELS, blocker_samples, blocker_tap, filter_samples,
    filter_tap, normal_offset_metres, poisson_rotation, sixteen_tap,
}
#import penumbra::shadows::filters::search_settled
#import penumbra::shadows::moments::vsm_covered_visibility
#import penumbra::shadows::types::{Light, Surface}

// A receiver seen from a point light.
struct PointSample {
    // From the light to the receiver (after the normal offset), metres.
    to_receiver: vec3<f32>,
    // Its length.
    distance: f32,
    // Unit tangent basis perpendicular to `to_receiver`.
    tangent: vec3<f32>,
    bitangent: vec3<f32>,
    // Receiver plane: unit normal and `dot(to_receiver, normal)`; `plane` is false when the
    // light's flags leave it off (taps then compare at the receiver's own distance).
    normal: vec3<f32>,
    plane_offset: f32,
    plane: bool,
    // Cube index in the array, face near plane and range.
    cube: i32,
    near: f32,
    range: f32,
    // World size of a face texel at the receiver, and the step between PCF taps (a texel, at
    // most MAX_FILTER_STEP_METRES).
    texel_metres: f32,
    filter_step: f32,
}

// Largest of a vector's absolute components: the distance along the face axis it falls in.
fn major_axis(v: vec3<f32>) -> f32 {
    let a = abs(v);
    return max(a.x, max(a.y, a.z));
}

// The reverse-Z depth a face stores for a point `axis` metres along the face's axis; mirrors
// `math::point::face_depth`.
fn point_face_depth(axis: f32, near: f32, range: f32) -> f32 {
    return near * (range - axis) / (axis * (range - near));
}

// The distance along a face's axis of a stored depth (the inverse of `point_face_depth`).
fn point_axis_distance(depth: f32, near: f32, range: f32) -> f32 {
    return near * range / (clamp(depth, 0.0, 1.0) * (range - near) + near);
}

// Projects a receiver into a point light's cube: offset along its normal by the light's
// normal offset in texels at its distance, with the tangent basis of the light direction.
fn project_to_point(light: Light, surface: Surface) -> PointSample {
    let view = shadow_views.items[light.first_view];
    var s: PointSample;
    s.near = view.params.y;
    s.range = view.params.z;
    s.cube = i32(view.layer / 6u);
    let raw = surface.position - light.position;
    s.texel_metres = view.params.x * max(major_axis(raw), s.near);
    let offset = normal_offset_metres(surface.normal, normalize(raw), light.shadow_params.x, s.texel_metres);
    s.to_receiver = raw + surface.normal * offset;
    s.distance = max(length(s.to_receiver), 1e-6);
    let dir = s.to_receiver / s.distance;
    let up = select(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0), abs(dir.y) > 0.999);
    s.tangent = normalize(cross(up, dir));
    s.bitangent = cross(dir, s.tangent);
    s.normal = surface.normal;
    s.plane_offset = dot(s.to_receiver, surface.normal);
    s.plane = (light.flags & SHADOW_FLAG_RECEIVER_PLANE) != 0u;
    s.filter_step = min(s.texel_metres, MAX_FILTER_STEP_METRES);
    return s;
}

// The direction of a tap `offset` metres sideways (tangent basis) from the receiver.
fn tap_direction(s: PointSample, offset: vec2<f32>) -> vec3<f32> {
    return s.to_receiver + s.tangent * offset.x + s.bitangent * offset.y;
}

// Comparison depth along `direction`: where it meets the receiver plane (within half to twice
// the receiver's distance), moved half a texel towards the light; or the receiver's own
// distance without the plane.
fn tap_reference(s: PointSample, direction: vec3<f32>) -> f32 {
    let length_d = length(direction);
    var distance = s.distance;
    let facing = dot(direction, s.normal);
    if s.plane && abs(facing) > 1e-6 {
        distance = clamp(s.plane_offset / facing * length_d, 0.5 * s.distance, 2.0 * s.distance);
    }
    distance -= RECEIVER_PLANE_EPSILON_TEXELS * s.texel_metres;
    let axis = max(major_axis(direction) / length_d * distance, s.near);
    return point_face_depth(axis, s.near, s.range);
}

// One hardware comparison tap `offset` metres sideways: 1 lit, 0 shadowed.
fn point_tap(s: PointSample, offset: vec2<f32>) -> f32 {
    let d = tap_direction(s, offset);
    return textureSampleCompareLevel(point_maps, shadow_compare, d, s.cube, tap_reference(s, d));
}

// 16 comparison taps of a rotated Poisson disc of `radius` metres; one tap at radius 0.
fn point_pcf(s: PointSample, radius: f32, rotation: mat2x2<f32>) -> f32 {
    if radius <= 0.0 {
        return point_tap(s, vec2<f32>(0.0));
    }
    var sum = 0.0;
    for (var i = 0u; i < 16u; i++) {
        sum += point_tap(s, rotation * sixteen_tap(i) * radius);
    }
    return sum / 16.0;
}

// What a point light's blocker search settled: `settled` is 1 (no blocker), 0 (every tap
// blocked, with the light's early-out) or -1 (a penumbra to filter: `radius` in metres at
// the receiver, `count` blocking texels).
struct PointSearch {
    settled: f32,
    radius: f32,
    count: f32,
}

// Point-light blocker search (PCSS's first step): the region through which the light's disc
// is seen (at most MAX_PENUMBRA_TEXELS texels), the mean blocker distance along each tap's
// ray, and half the penumbra that blocker throws at the receiver, at least one filter step.
fn point_search(light: Light, s: PointSample, rotation: mat2x2<f32>) -> PointSearch {
    let light_size = 2.0 * light.size;
    let max_radius = MAX_PENUMBRA_TEXELS * s.texel_metres;
    // NOTE: a blocker at distance b hides the disc over `light_size · (d − b) / b` metres at
    // the receiver; largest for a blocker at the near plane.
    let search = 0.5 * light_size * (s.distance - s.near) / s.near;
    let search_radius = clamp(search, s.filter_step, max_radius);
    var sum = 0.0;
    var count = 0.0;
    let samples = blocker_samples(light);
    for (var i = 0u; i < samples; i++) {
        let d = tap_direction(s, rotation * blocker_tap(i, samples) * search_radius);
        let depths = textureGather(point_maps, shadow_point, d, s.cube);
        let is_blocker = vec4<f32>(depths > vec4<f32>(tap_reference(s, d)));
        // NOTE: the four texels share the tap's face; a blocker's distance along the tap's
        // ray is its axis distance over the ray's share of that axis.
        let stretch = length(d) / major_axis(d);
        let axis = vec4<f32>(
            point_axis_distance(depths.x, s.near, s.range),
            point_axis_distance(depths.y, s.near, s.range),
            point_axis_distance(depths.z, s.near, s.range),
            point_axis_distance(depths.w, s.near, s.range),
        );
        sum += dot(axis * stretch, is_blocker);
        count += dot(is_blocker, vec4<f32>(1.0));
    }
    var out = PointSearch(search_settled(count, light), 0.0, count);
    let blocker = sum / max(count, 1.0);
    let penumbra = max(s.distance - blocker, 0.0) * light_size / max(blocker, 1e-6);
    out.radius = clamp(0.5 * penumbra, s.filter_step, max_radius);
    return out;
}

#ifdef SHADOW_FILTER_PCSS
// Point-light PCSS: the blocker search, then comparison taps over the penumbra it gives,
// faded towards lit where the search found few blockers.
fn point_pcss(light: Light, s: PointSample, rotation: mat2x2<f32>) -> f32 {
    let search = point_search(light, s, rotation);
    if search.settled >= 0.0 {
        return search.settled;
    }
    var lit = 0.0;
    let samples = filter_samples(light);
    for (var i = 0u; i < samples; i++) {
        lit += point_tap(s, rotation * filter_tap(i, samples) * search.radius);
    }
    lit /= f32(samples);
    return mix(1.0, lit, smoothstep(0.0, 4.0, search.count));
}
#endif

// VSM with contact hardening, sized by the emitter as PCSS is: the blocker search gives the
// penumbra's radius, and the moments (pre-blurred by `vsm_blur`) are averaged over 16 rotated
// Poisson fetches of that radius before Chebyshev's bound. A penumbra under a texel (a
// caster's foot) compares the depth itself.
fn point_vsm_hardened(light: Light, s: PointSample, rotation: mat2x2<f32>) -> f32 {
    let search = point_search(light, s, rotation);
    if search.settled >= 0.0 {
        return search.settled;
    }
    if search.radius < s.texel_metres {
        return point_tap(s, vec2<f32>(0.0));
    }
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < 16u; i++) {
        let d = tap_direction(s, rotation * sixteen_tap(i) * search.radius);
        sum += textureSampleLevel(point_moments, moments_sampler, d, s.cube, 0.0).xyz;
    }
    return vsm_covered_visibility(sum / 16.0, s.distance / s.range, light.cone.z, light.cone.w);
}

// The fraction of a point light visible from `surface` (1 lit, 0 shadowed); 1 past the
// light's range or for a point light without a shadow.
fn point_visibility(light: Light, surface: Surface) -> f32 {
    if light.view_count == 0u {
        return 1.0;
    }
    let s = project_to_point(light, surface);
    if major_axis(s.to_receiver) >= s.range {
        return 1.0;
    }
    let rotation = poisson_rotation(surface.frag_coord, light.flags);
    if light.shadow_filter == SHADOW_FILTER_VSM {
        if (light.flags & SHADOW_FLAG_MOMENT_HARDENING) != 0u && light.size > 0.0 {
            return point_vsm_hardened(light, s, rotation);
        }
        // Moments of the distance from the light over the range, pre-filtered across faces.
        let moments = textureSampleLevel(point_moments, moments_sampler, s.to_receiver, s.cube, 0.0).xyz;
        return vsm_covered_visibility(moments, s.distance / s.range, light.cone.z, light.cone.w);
    }
#ifdef SHADOW_FILTER_PCSS
    if light.shadow_filter == SHADOW_FILTER_PCSS && light.size > 0.0 {
        return point_pcss(light, s, rotation);
    }
#endif
    // PCF: a disc of (radius + 0.5) filter steps (one tap at radius 0).
    let radius = select(0.0, (f32(light.pcf_radius) + 0.5) * s.filter_step, light.pcf_radius > 0u);
    return point_pcf(s, radius, rotation);
}

// The cube face `surface` samples from a point light (0..5 in layer order: +X, −X, +Y, −Y,
// +Z, −Z; ties go to x, then y, as `math::point::face_of`), or -1 past its range or without a
// shadow.
fn point_face(light: Light, surface: Surface) -> i32 {
    let d = surface.position - light.position;
    let a = abs(d);
    if light.view_count == 0u || max(a.x, max(a.y, a.z)) >= light.range {
        return -1;
    }
    if a.x >= a.y && a.x >= a.z {
        return select(0, 1, d.x < 0.0);
    }
    if a.y >= a.z {
        return select(2, 3, d.y < 0.0);
    }
    return select(4, 5, d.z < 0.0);
}

// Debug tint of the cube face `surface` samples (grey outside the shadow).
fn point_debug_color(light: Light, surface: Surface) -> vec3<f32> {
    var colors = array<vec3<f32>, 6>(
        vec3<f32>(1.0, 0.25, 0.25),
        vec3<f32>(0.25, 1.0, 1.0),
        vec3<f32>(0.25, 1.0, 0.25),
        vec3<f32>(1.0, 0.25, 1.0),
        vec3<f32>(0.3, 0.45, 1.0),
        vec3<f32>(1.0, 1.0, 0.25),
    );
    let face = point_face(light, surface);
    if face < 0 {
        return vec3<f32>(0.5);
    }
    return colors[face];
}
