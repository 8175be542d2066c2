// The shipped material's lighting, shared by the forward shader (forward.wgsl) and the
// lighting of the prepass's pixels (deferred.wgsl): Lambert diffuse from every light of the
// frame times its shadow, diffuse transmission, a flat ambient term, the debug views and the
// tone curve. Both shaders compose it with the same shader defs, so a pixel lit either way
// gets the same colour.
#define_import_path penumbra::shading

#import penumbra::contract::{LIGHT_DIRECTIONAL, LIGHT_POINT, MAX_LIGHTS, RESOLVE_NONE}
#import penumbra::frame::frame
#import penumbra::lights::{get_light, light_count, light_incidence, make_surface, shadow_visibility}
#import penumbra::shadows::bindings::{lights, resolved_visibility}
#ifdef MANY_LIGHTS
#import penumbra::shadows::bindings::more_lights
#endif
#import penumbra::shadows::cascades::cascade_debug_color
#ifdef SHADOW_POINT
#import penumbra::shadows::point::point_debug_color
#endif
#import penumbra::shadows::types::{Light, Surface}

// ACES filmic curve (Narkowicz 2015 fit): rolls highlights off instead of clipping them.
fn tonemap(color: vec3<f32>) -> vec3<f32> {
    let x = color * 0.6;
    return saturate((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14));
}

// What the lights give a surface: the direct light, and the focus light's visibility,
// shadow flag and n·l (analysis outputs).
struct Shading {
    direct: vec3<f32>,
    focus: vec4<f32>,
}

// Adds light `i` to `shading` at `surface` (`through_share`: the share of light the surface
// transmits from its other side).
fn shade_light(light: Light, i: u32, surface: Surface, receives: bool, through_share: f32, shading: ptr<function, Shading>) {
    let incidence = light_incidence(light, surface.position);
    let cosine = dot(surface.normal, incidence.to_light);
    let n_dot_l = max(cosine, 0.0);
    var visibility = 1.0;
    if receives && n_dot_l > 0.0 {
        visibility = shadow_visibility(light, surface);
    }
    (*shading).direct += incidence.radiance * n_dot_l * visibility;
#ifdef TRANSMISSION
    if through_share > 0.0 && cosine < 0.0 {
        // Diffuse transmission: the light on the other side, shadowed as that side is (what
        // the resolve wrote for this pixel, or the filters with the normal turned towards the
        // light).
        var through = 1.0;
        if receives {
            through = shadow_visibility(light, make_surface(surface.position, -surface.normal, surface.view_depth, surface.frag_coord));
        }
        (*shading).direct += incidence.radiance * (-cosine) * through_share * through;
    }
#endif
    if i == frame.focus_light {
        (*shading).focus = vec4<f32>(visibility, -1.0, select(0.0, 1.0, receives && n_dot_l > 0.0), n_dot_l);
    }
}

// Every light's contribution at `surface`: the uniform list's lights, then (in the
// MANY_LIGHTS variants) the storage list's.
fn shade(surface: Surface, receives: bool, through_share: f32) -> Shading {
    var shading = Shading(vec3<f32>(0.0), vec4<f32>(1.0, -1.0, 0.0, 0.0));
    let count = light_count();
    for (var i = 0u; i < min(count, MAX_LIGHTS); i++) {
        shade_light(lights.items[i], i, surface, receives, through_share, &shading);
    }
#ifdef MANY_LIGHTS
    for (var i = MAX_LIGHTS; i < count; i++) {
        shade_light(more_lights[i - MAX_LIGHTS], i, surface, receives, through_share, &shading);
    }
#endif
    return shading;
}

// The displayed colour of a surface of base colour `base` lit by `direct` light: ambient
// added, exposed, tinted by the debug views, tone-mapped.
fn display_color(base: vec3<f32>, direct: vec3<f32>, surface: Surface) -> vec3<f32> {
    var color = base * (frame.ambient + direct) * frame.exposure;
#ifdef SHADOW_DEBUG_CASCADES
    if frame.focus_light < light_count() {
        let light = get_light(frame.focus_light);
        var tint = vec3<f32>(1.0);
        if light.kind == LIGHT_DIRECTIONAL {
            tint = cascade_debug_color(light, surface);
        }
#ifdef SHADOW_POINT
        if light.kind == LIGHT_POINT {
            tint = point_debug_color(light, surface);
        }
#endif
        color = mix(color, color * tint * 1.6, 0.6);
    }
#endif
    if frame.debug_contact != 0u {
        // The focus light's layer holds its contact shadows alone (1 where none ran).
        let light = get_light(frame.focus_light);
        var contact = 1.0;
        if light.resolve_layer != RESOLVE_NONE {
            contact = textureLoad(resolved_visibility, vec2<i32>(surface.frag_coord), i32(light.resolve_layer), 0).r;
        }
        color = vec3<f32>(contact * 0.8);
    }
    return tonemap(color);
}
