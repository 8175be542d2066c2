// The public light and shadow contract for materials. A material loops over the frame's
// lights and asks each for its light and its shadow:
//
//     let surface = make_surface(world_position, normal, view_depth, frag_coord);
//     for (var i = 0u; i < light_count(); i++) {
//         let light = get_light(i);
//         let incidence = light_incidence(light, surface.position);
//         let n_dot_l = max(dot(surface.normal, incidence.to_light), 0.0);
//         if n_dot_l > 0.0 {
//             radiance += incidence.radiance * n_dot_l * shadow_visibility(light, surface);
//         }
//     }
//
// `shadow_visibility` works for every kind of light and every shadow technique: a material
// written against these functions keeps compiling, and keeps its shadows, when new lights,
// filters or shadow layouts are added. It reads group 3 (the shadow bind group) and the
// frame uniforms of group 0; a material uses groups 1 and 2 as `forward.wgsl` does. The
// renderer composes it with the defs of the frame's variant (SHADOW_SPOT when a spot light
// casts, SHADOW_POINT when a point light does, the PCSS defs when a light filters with PCSS); a material only forwards them.
#define_import_path penumbra::lights

#import penumbra::contract::{LIGHT_DIRECTIONAL, LIGHT_POINT, LIGHT_SPOT, MAX_LIGHTS, RESOLVE_NONE, SHADOW_FLAG_CONTACT_ONLY}
#import penumbra::frame::frame
#import penumbra::shadows::bindings::{lights, resolved_visibility}
#ifdef MANY_LIGHTS
#import penumbra::shadows::bindings::more_lights
#endif
#import penumbra::shadows::cascades::directional_visibility
#ifdef SHADOW_POINT
#import penumbra::shadows::point::point_visibility
#endif
#ifdef SHADOW_SPOT
#import penumbra::shadows::spot::spot_visibility
#endif
#import penumbra::shadows::types::{Light, Surface}

// Light arriving at a surface point from one light.
struct Incidence {
    // Unit direction from the point towards the light.
    to_light: vec3<f32>,
    // Colour times intensity, after distance falloff and the spot cone (no shadow, no n·l).
    radiance: vec3<f32>,
}

// Number of lights this frame.
fn light_count() -> u32 {
    return frame.light_count;
}

// Light `i` (0 <= i < light_count()): from the uniform list, or past its MAX_LIGHTS from the
// storage one (in the MANY_LIGHTS variants, which the frames with more lights use).
fn get_light(i: u32) -> Light {
#ifdef MANY_LIGHTS
    if i >= MAX_LIGHTS {
        return more_lights[i - MAX_LIGHTS];
    }
#endif
    return lights.items[min(i, MAX_LIGHTS - 1u)];
}

// A point being shaded: world position, unit normal facing the viewer, positive view depth,
// pixel position.
fn make_surface(position: vec3<f32>, normal: vec3<f32>, view_depth: f32, frag_coord: vec2<f32>) -> Surface {
    return Surface(position, normal, view_depth, frag_coord);
}

// Smooth window that takes a positional light to zero at its range (as Karis 2013):
// (1 − (d/range)⁴)², times inverse-square falloff from 1 at 1 m.
fn distance_falloff(distance_squared: f32, range: f32) -> f32 {
    let ratio = distance_squared / (range * range);
    let window = saturate(1.0 - ratio * ratio);
    return window * window / max(distance_squared, 1e-4);
}

// Direction to `light` and the light arriving at `position`, before shadowing.
fn light_incidence(light: Light, position: vec3<f32>) -> Incidence {
    if light.kind == LIGHT_DIRECTIONAL {
        return Incidence(-light.direction, light.color);
    }
    let to_light = light.position - position;
    let distance_squared = max(dot(to_light, to_light), 1e-8);
    let direction = to_light * inverseSqrt(distance_squared);
    var radiance = light.color * distance_falloff(distance_squared, light.range);
    if light.kind == LIGHT_SPOT {
        let cos_angle = dot(-direction, light.direction);
        let cone = saturate((cos_angle - light.cone.x) * light.cone.y);
        radiance *= cone * cone;
    }
    return Incidence(direction, radiance);
}

// The fraction of `light` visible from `surface` (1 lit, 0 shadowed), with whatever shadow
// technique the light uses; 1 for a light without a shadow. When the frame resolved the
// light's visibility before the lighting pass, this reads it at the surface's pixel (unless
// the variant is UNRESOLVED_SHADOWS: alpha-to-coverage materials, which the prepass does not
// draw, filter their own, without contact shadows); where the resolve wrote the light's
// contact shadows alone (SHADOW_FLAG_CONTACT_ONLY), they multiply the filtered shadow.
fn shadow_visibility(light: Light, surface: Surface) -> f32 {
#ifndef UNRESOLVED_SHADOWS
    if light.resolve_layer != RESOLVE_NONE {
        let pixel = vec2<i32>(surface.frag_coord);
        let resolved = textureLoad(resolved_visibility, pixel, i32(light.resolve_layer), 0).r;
        if (light.flags & SHADOW_FLAG_CONTACT_ONLY) != 0u {
            return resolved * filtered_visibility(light, surface);
        }
        return resolved;
    }
#endif
    return filtered_visibility(light, surface);
}

// The light's shadow filtered at `surface` itself (what the compute resolve writes, and what
// the lighting pass computes when nothing was resolved).
fn filtered_visibility(light: Light, surface: Surface) -> f32 {
    if light.kind == LIGHT_DIRECTIONAL {
        return directional_visibility(light, surface);
    }
#ifdef SHADOW_SPOT
    if light.kind == LIGHT_SPOT {
        return spot_visibility(light, surface);
    }
#endif
#ifdef SHADOW_POINT
    if light.kind == LIGHT_POINT {
        return point_visibility(light, surface);
    }
#endif
    return 1.0;
}
