// The cascades of a directional light: cascade selection, projection with normal offset and
// receiver-plane depth gradient, PCF or PCSS from the cascades' depth array, cascade blend
// and distance fade; a paged clipmap's levels through the page table. The entry point is
// `directional_visibility`, called by
// penumbra::lights::shadow_visibility for a sun.
//
// Shader defs: SHADOW_FILTER_PCSS compiles the PCSS path (variants with a PCSS light);
// without it a PCSS light is filtered with PCF. SHADOW_SUN_MOMENTS compiles the moment
// techniques (EVSM2, EVSM4, MSM: one filtered fetch of the pre-blurred moments); without it
// such a light is filtered with PCF.
#define_import_path penumbra::shadows::cascades

#import penumbra::contract::{
    MAX_PENUMBRA_TEXELS, SHADOW_FILTER_EVSM2, SHADOW_FILTER_EVSM4, SHADOW_FILTER_MSM,
    SHADOW_FILTER_PCSS, SHADOW_FLAG_CLIPMAP, SHADOW_FLAG_MOMENT_HARDENING, SHADOW_FLAG_PAGED,
    SHADOW_FLAG_RECEIVER_PLANE,
}
#import penumbra::shadows::clipmap::{clipmap_fade, select_level}
#import penumbra::shadows::bindings::{
    cascade_maps, cascade_moments, moments_sampler, page_moments, shadow_views,
}
#import penumbra::shadows::common::{
    MAX_FILTER_STEP_METRES, MAX_RECEIVER_SLOPE, MAX_TRUE_SLOPE, blocker_samples, filter_samples,
    linear_row, normal_offset_metres, poisson_rotation,
}
#import penumbra::shadows::filters::{
    MapSample, compare_tap, find_blockers, pcf_grid, pcss_filter, search_settled,
}
#import penumbra::shadows::moments::{
    evsm2_covered_visibility, evsm4_visibility, reduce_light_bleeding,
}
#import penumbra::shadows::msm::{msm_dequantize, msm_visibility}
#import penumbra::shadows::page_table::{footprint_resident, page_uv_inset}
#import penumbra::shadows::types::{Light, ShadowView, Surface}

// Which cascade a fragment samples, and how far it is into the blend band towards the next.
struct CascadeSelection {
    index: u32,
    // 0 inside the cascade, rising to 1 at its far end when blending is on.
    blend: f32,
}

// Maps a view-space depth to one of the light's cascades and a blend factor towards the next.
fn select_cascade(light: Light, view_depth: f32) -> CascadeSelection {
    let count = max(light.view_count, 1u);
    var index = count - 1u;
    for (var i = 0u; i < count; i++) {
        if view_depth < shadow_views.items[light.first_view + i].range.y {
            index = i;
            break;
        }
    }
    var blend = 0.0;
    if index + 1u < count {
        let range = shadow_views.items[light.first_view + index].range;
        let width = light.shadow_params.z * (range.y - range.x);
        if width > 0.0 {
            blend = saturate((view_depth - (range.y - width)) / width);
        }
    }
    return CascadeSelection(index, blend);
}

// 1 where the light's shadows are at full strength, falling smoothly to 0 at its
// max_distance.
fn shadow_distance_fade(light: Light, view_depth: f32) -> f32 {
    let end = light.shadow_params.y;
    let width = light.shadow_params.w * end;
    if width <= 0.0 {
        return select(0.0, 1.0, view_depth < end);
    }
    return 1.0 - smoothstep(end - width, end, view_depth);
}

// Projects a receiver into cascade `index` of `light`, offset along its normal, and derives
// the depth gradient of the receiver's plane in shadow UV space. Returns the sample and
// whether the receiver lies inside the cascade.
//
// NOTE: the gradient comes from the surface normal, not from screen-space derivatives: it
// needs no uniform control flow, is defined at cascade and silhouette edges (where
// derivatives mix unrelated pixels), and costs a few dot products. For the plane n·p = c, the
// map world -> (u, v, z) has rows a_i; the plane's covector in (u, v, z) is
// m_i = (a_i · n) / |a_i|², so dz = -(m.x du + m.y dv) / m.z.
fn project_to_cascade(light: Light, index: u32, world_pos: vec3<f32>, normal: vec3<f32>) -> MapSample {
    let view = shadow_views.items[light.first_view + index];
    let m = view.clip_from_world;
    let texel_world = view.params.x;
    let offset = normal_offset_metres(normal, light.direction, light.shadow_params.x, texel_world);
    let clip = m * vec4<f32>(world_pos + normal * offset, 1.0);
    let uv = vec2<f32>(clip.x * 0.5 + 0.5, 0.5 - clip.y * 0.5);
    var out: MapSample;
    out.uv = view.rect.xy + uv * view.rect.zw;
    if view.page.w > 0.0 {
        // NOTE: a wrapping layer holds its window's first texel at `page.xy` (UV); the taps
        // around `uv` wrap round the layer's edges with it.
        out.uv = fract(out.uv + view.page.xy);
        out.page = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    // NOTE: a receiver past the box's far plane (depth < 0) is compared as if on it: a
    // stored caster (depth > 0) still shadows it, an empty texel (cleared to 0) does not.
    out.depth = max(clip.z, 0.0);
    out.layer = view.layer;
    out.texel = view.texel_size * view.rect.z;
    // World size of a texel along u and along v (params.w is width_x / width_y).
    let texel_metres = vec2<f32>(texel_world, texel_world / max(view.params.w, 1e-30));
    out.filter_step = out.texel * min(vec2<f32>(1.0), MAX_FILTER_STEP_METRES / max(texel_metres, vec2<f32>(1e-30)));
    out.dz_duv = vec2<f32>(0.0);
    out.dz_duv_true = vec2<f32>(0.0);
    if (light.flags & SHADOW_FLAG_RECEIVER_PLANE) != 0u {
        let a0 = linear_row(m, 0u) * 0.5;
        let a1 = linear_row(m, 1u) * -0.5;
        let a2 = linear_row(m, 2u);
        let cov = vec3<f32>(
            dot(a0, normal) / max(dot(a0, a0), 1e-30),
            dot(a1, normal) / max(dot(a1, a1), 1e-30),
            dot(a2, normal) / max(dot(a2, a2), 1e-30),
        );
        // Largest gradient allowed: MAX_RECEIVER_SLOPE in world units, converted to NDC depth
        // per UV (width_x / depth_range).
        let width_x = texel_world / view.texel_size;
        let max_gradient = MAX_RECEIVER_SLOPE * width_x / max(view.range.z, 1e-6);
        let denom = select(cov.z, 1e-30, abs(cov.z) < 1e-30);
        let max_true = MAX_TRUE_SLOPE * width_x / max(view.range.z, 1e-6);
        // Per unit of view UV, then per unit of layer UV.
        let dz_true = clamp(-cov.xy / denom, vec2<f32>(-max_true), vec2<f32>(max_true));
        out.dz_duv_true = dz_true / view.rect.zw;
        out.dz_duv = clamp(dz_true, vec2<f32>(-max_gradient), vec2<f32>(max_gradient)) / view.rect.zw;
    }
    return out;
}

// What PCSS's blocker search over a cascade's depth map found around a receiver.
struct CascadeSearch {
    // 1: no blocker (lit); 0: every tap blocked and the light early-outs (umbra); -1: filter.
    settled: f32,
    // The penumbra's half width from the blockers' mean depth (layer UV, along u): the
    // distance to them times tan(θ/2), at most the reach of the search.
    radius: f32,
    // Blocker texels found, of 4 · blocker_samples(light).
    count: f32,
    // The smallest kernel radius (one filter step along u).
    min_radius: f32,
    // Scale from a u-extent to the v-extent of the same world size.
    aspect: vec2<f32>,
    // The per-pixel rotation of the sampling patterns.
    rotation: mat2x2<f32>,
}

// PCSS's blocker search in a cascade: over the widest penumbra any caster between the
// light-side plane and the receiver could throw (at most MAX_PENUMBRA_TEXELS), the blockers'
// mean depth, and the penumbra it gives: full width = distance to the blockers times
// 2 tan(θ/2), the radius half of it. Shared by PCSS and the moment techniques' contact
// hardening.
fn cascade_search(light: Light, index: u32, p: MapSample, frag_coord: vec2<f32>) -> CascadeSearch {
    let view = shadow_views.items[light.first_view + index];
    let pcss_scale = view.params.z * view.rect.z;
    var out: CascadeSearch;
    out.aspect = vec2<f32>(1.0, view.params.w);
    // Smallest kernel radius in u units (the kernel's v extent is the radius times aspect.y).
    out.min_radius = min(p.filter_step.x, p.filter_step.y / out.aspect.y);
    let max_radius = MAX_PENUMBRA_TEXELS * p.texel;
    out.rotation = poisson_rotation(frag_coord, light.flags);
    let search_radius = clamp(0.5 * (1.0 - p.depth) * pcss_scale, out.min_radius, max_radius);
    let blockers = find_blockers(cascade_maps, p, search_radius, out.aspect, out.rotation, blocker_samples(light));
    out.count = blockers.count;
    out.radius = min(0.5 * max(blockers.depth - p.depth, 0.0) * pcss_scale, max_radius);
    out.settled = search_settled(blockers.count, light);
    return out;
}

#ifdef SHADOW_FILTER_PCSS
// Percentage-closer soft shadows in a cascade: the blocker search, then PCSS's filter over
// the penumbra it gives.
fn cascade_pcss(light: Light, index: u32, p: MapSample, frag_coord: vec2<f32>) -> f32 {
    let search = cascade_search(light, index, p, frag_coord);
    if search.settled >= 0.0 {
        return search.settled;
    }
    let radius = max(search.radius, search.min_radius);
    return pcss_filter(cascade_maps, p, radius, search.aspect, search.rotation, search.count, filter_samples(light));
}
#endif

#ifdef SHADOW_SUN_MOMENTS
// The depth a sun's moments hold for a receiver at reverse-Z depth `z` of a cascade: d = 1 − z
// remapped from the cascade's receiver span [range.w, 1] to [0, 1], as the bake stores it.
fn cascade_moment_depth(view: ShadowView, z: f32) -> f32 {
    let start = view.range.w;
    return saturate((1.0 - z - start) / max(1.0 - start, 1e-6));
}

// The visibility a sun's moment technique gives `power` (moments filtered around the
// receiver) for a receiver at moment depth `depth`: MSM's Hamburger bound, or EVSM's
// Chebyshev bound in warped space with a variance floor of `min_variance` (moment depth units
// squared), with light-bleed reduction (EVSM2's moments carry their coverage: the empty
// share of the footprint is lit).
fn moments_bound(light: Light, view: ShadowView, moments: vec4<f32>, depth: f32, min_variance: f32) -> f32 {
    let bleed = light.cone.w;
    if light.shadow_filter == SHADOW_FILTER_MSM {
        let power = select(moments, msm_dequantize(moments), light.cone.y > 0.5);
        return reduce_light_bleeding(msm_visibility(power, depth, light.cone.x), bleed);
    }
    if light.shadow_filter == SHADOW_FILTER_EVSM4 {
        return evsm4_visibility(moments, depth, view.exponents.x, view.exponents.y, min_variance, bleed);
    }
    return evsm2_covered_visibility(moments, depth, view.exponents.x, min_variance, bleed);
}

// The variance floor of EVSM's bound in cascade `view` at `p` (moment depth units squared):
// the light's minimum (square metres) plus the receiver plane's depth change across a texel
// (zero without the receiver-plane gradient), so sloped receivers do not shadow themselves.
fn moments_min_variance(light: Light, view: ShadowView, p: MapSample) -> f32 {
    let span = max(1.0 - view.range.w, 1e-6);
    // Metres of the moment depth's [0, 1].
    let range = max(view.range.z * span, 1e-6);
    let slope = p.dz_duv_true * p.texel / span;
    return light.cone.z / (range * range) + 0.25 * dot(slope, slope);
}

// A sun's moments at `uv` (layer UV) of the receiver's cascade, filtered at mip `lod`: of the
// cascades' array, or of a paged level's atlas through the page table, clamped inside the
// page by half a texel of the coarser mip read (empty moments, which read as lit, where the
// page is missing).
fn sun_moments_at(p: MapSample, uv: vec2<f32>, lod: f32) -> vec4<f32> {
    if p.page.z > 0.0 {
        let at = page_uv_inset(p.page, p.layer, p.texel, uv, 0.5 * exp2(ceil(lod)));
        if at.x < 0.0 {
            return vec4<f32>(0.0);
        }
        return textureSampleLevel(page_moments, moments_sampler, at, 0, lod);
    }
    return textureSampleLevel(cascade_moments, moments_sampler, uv, p.layer, lod);
}

// Contact hardening for a sun's moments, sized by the sun as PCSS is: PCSS's blocker search
// over the cascade's depth map gives the blockers' mean depth and so the penumbra's radius;
// the moments are then filtered over that radius in one fetch per quarter of it (four
// fetches at 0.4 of the radius around the receiver, rotated per pixel, from the mip level
// whose texel is the radius wide). A receiver whose search finds no blocker is lit, one whose
// every tap is blocked is in the umbra (with the light's early-out), and one whose penumbra
// is under a texel (a caster's foot) compares the depth itself: no moment filter resolves a
// gap that small.
fn cascade_moments_hardened(light: Light, index: u32, p: MapSample, frag_coord: vec2<f32>) -> f32 {
    let view = shadow_views.items[light.first_view + index];
    let search = cascade_search(light, index, p, frag_coord);
    if search.settled >= 0.0 {
        return search.settled;
    }
    let radius = search.radius;
    let texels = radius / p.texel;
    if texels < 1.0 {
        return compare_tap(cascade_maps, p, vec2<f32>(0.0));
    }
    let lod = log2(texels);
    var sum = vec4<f32>(0.0);
    for (var i = 0u; i < 4u; i++) {
        let corner = vec2<f32>(select(-0.4, 0.4, (i & 1u) == 1u), select(-0.4, 0.4, i >= 2u));
        let offset = search.rotation * corner * radius * search.aspect;
        sum += sun_moments_at(p, p.uv + offset, lod);
    }
    let depth = cascade_moment_depth(view, p.depth);
    return moments_bound(light, view, 0.25 * sum, depth, moments_min_variance(light, view, p));
}

// EVSM2, EVSM4 or MSM in a cascade with a fixed softness: one bilinear fetch of the
// moments pre-blurred by `moment_blur` and the technique's bound at the receiver's moment
// depth (`cascade_moment_depth`).
fn cascade_moments_visibility(light: Light, index: u32, p: MapSample) -> f32 {
    let view = shadow_views.items[light.first_view + index];
    let moments = sun_moments_at(p, p.uv, 0.0);
    let depth = cascade_moment_depth(view, p.depth);
    return moments_bound(light, view, moments, depth, moments_min_variance(light, view, p));
}
#endif

// A receiver projected into a paged sun's level `index`, or past the last level.
struct PagedPick {
    index: u32,
    sample: MapSample,
}

// A receiver projected into a paged sun's level `index`, if every page under its filter's
// footprint (the PCF kernel, PCSS's widest search, which contact hardening makes too, or a
// fixed-blur moment filter's bilinear tap: its moments are blurred within their page) is
// resident there; `view_count` as the index when
// one is not.
fn paged_try(light: Light, index: u32, surface: Surface) -> PagedPick {
    let pcss = light.shadow_filter == SHADOW_FILTER_PCSS;
    var texels = select(f32(min(light.pcf_radius, 5u)) + 2.0, MAX_PENUMBRA_TEXELS + 2.0, pcss);
    if light.shadow_filter >= SHADOW_FILTER_EVSM2 {
        // NOTE: contact hardening searches as PCSS does; a fixed blur reads one bilinear tap.
        let hardening = (light.flags & SHADOW_FLAG_MOMENT_HARDENING) != 0u;
        texels = select(2.0, MAX_PENUMBRA_TEXELS + 2.0, hardening);
    }
    let view = shadow_views.items[light.first_view + index];
    var p = project_to_cascade(light, index, surface.position, surface.normal);
    p.page = view.page;
    let resident = footprint_resident(p.page, p.layer, p.texel, p.uv, texels * p.texel);
    return PagedPick(select(light.view_count, index, resident), p);
}

// The level a paged sun's receiver reads: level `index` where its pages are resident, else
// (the pool overflowed) the next coarser one, else the coarsest (every receiver marks it and
// the pool serves it first); `view_count` when none is, and the receiver is lit.
//
// NOTE: three tries, not a loop over the levels (as `footprint_resident`).
fn paged_level(light: Light, index: u32, surface: Surface) -> PagedPick {
    let coarsest = light.view_count - 1u;
    let next = min(index + 1u, coarsest);
    var pick = paged_try(light, index, surface);
    if pick.index > coarsest && next != index {
        pick = paged_try(light, next, surface);
    }
    if pick.index > coarsest && coarsest != next {
        pick = paged_try(light, coarsest, surface);
    }
    return pick;
}

// Shadow factor from one cascade (or clipmap level) with the light's filter; a paged sun's
// from the first resident level from `first` on.
fn sample_cascade(light: Light, first: u32, surface: Surface) -> f32 {
    var index = first;
    var p = project_to_cascade(light, index, surface.position, surface.normal);
    if (light.flags & SHADOW_FLAG_PAGED) != 0u {
        let pick = paged_level(light, first, surface);
        if pick.index >= light.view_count {
            return 1.0;
        }
        index = pick.index;
        p = pick.sample;
    }
    let rect = shadow_views.items[light.first_view + index].rect;
    let uv = (p.uv - rect.xy) / rect.zw;
    if any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) || p.depth > 1.0 {
        return 1.0;
    }
#ifdef SHADOW_FILTER_PCSS
    if light.shadow_filter == SHADOW_FILTER_PCSS {
        return cascade_pcss(light, index, p, surface.frag_coord);
    }
#endif
#ifdef SHADOW_SUN_MOMENTS
    if light.shadow_filter >= SHADOW_FILTER_EVSM2 {
        if (light.flags & SHADOW_FLAG_MOMENT_HARDENING) != 0u {
            return cascade_moments_hardened(light, index, p, surface.frag_coord);
        }
        return cascade_moments_visibility(light, index, p);
    }
#endif
    return pcf_grid(cascade_maps, p, light.pcf_radius);
}

// The view a receiver samples among a sun's cascades (by view depth) or clipmap levels (by
// its light-frame position), and its blend towards the next; `index` is `view_count` for a
// receiver outside every clipmap level.
fn select_view(light: Light, surface: Surface) -> CascadeSelection {
    if (light.flags & SHADOW_FLAG_CLIPMAP) != 0u {
        let level = select_level(light, surface.position, surface.view_depth);
        return CascadeSelection(level.index, level.blend);
    }
    return select_cascade(light, surface.view_depth);
}

// 1 where a sun's shadows are at full strength, falling to 0 where they end: its
// max_distance (cascades) or the last clipmap level's edge.
fn sun_fade(light: Light, surface: Surface) -> f32 {
    if (light.flags & SHADOW_FLAG_CLIPMAP) != 0u {
        return clipmap_fade(light, surface.position);
    }
    return shadow_distance_fade(light, surface.view_depth);
}

// The fraction of a sun visible from `surface` (1 lit, 0 shadowed), with cascade (or level)
// blending and distance fade; 1 for a sun without shadow views.
fn directional_visibility(light: Light, surface: Surface) -> f32 {
    if light.view_count == 0u || surface.view_depth >= light.shadow_params.y {
        return 1.0;
    }
    let selection = select_view(light, surface);
    if selection.index >= light.view_count {
        return 1.0;
    }
    var visibility = sample_cascade(light, selection.index, surface);
    if selection.blend > 0.0 {
        let next = sample_cascade(light, selection.index + 1u, surface);
        visibility = mix(visibility, next, selection.blend);
    }
    return mix(1.0, visibility, sun_fade(light, surface));
}

// The cascade (or clipmap level) `surface` samples, or -1 when the light has no shadow or the
// fragment lies past where its shadows end (for analysis outputs and debug views).
fn cascade_index(light: Light, surface: Surface) -> i32 {
    if light.view_count == 0u || surface.view_depth >= light.shadow_params.y {
        return -1;
    }
    let index = select_view(light, surface).index;
    return select(i32(index), -1, index >= light.view_count);
}

// Debug colour of the cascade a fragment samples (red, green, blue, yellow, repeating),
// blended like the shadow itself; grey beyond max_distance or without shadows.
fn cascade_debug_color(light: Light, surface: Surface) -> vec3<f32> {
    var colors = array<vec3<f32>, 4>(
        vec3<f32>(1.0, 0.25, 0.25),
        vec3<f32>(0.25, 1.0, 0.25),
        vec3<f32>(0.3, 0.45, 1.0),
        vec3<f32>(1.0, 1.0, 0.25),
    );
    if cascade_index(light, surface) < 0 {
        return vec3<f32>(0.5);
    }
    let selection = select_view(light, surface);
    if (light.flags & SHADOW_FLAG_PAGED) != 0u {
        // A paged sun: the level read; half magenta where its pages overflowed the pool and a
        // coarser level was read, magenta where no level was resident.
        let pick = paged_level(light, selection.index, surface);
        if pick.index >= light.view_count {
            return vec3<f32>(1.0, 0.0, 1.0);
        }
        let fell_back = select(0.0, 0.5, pick.index != selection.index);
        return mix(colors[pick.index % 4u], vec3<f32>(1.0, 0.0, 1.0), fell_back);
    }
    let next = min(selection.index + 1u, light.view_count - 1u);
    return mix(colors[selection.index % 4u], colors[next % 4u], selection.blend);
}
