// Compute visibility resolve: for every pixel the depth prepass covered, rebuild the surface
// (world position from depth, normal and receiver flag from the prepass's normals) and write
// each resolved light's filtered shadow, times its contact shadows (penumbra::contact, marched
// over the prepass's depth), into its layer of the resolved visibility, which the lighting
// pass then reads through penumbra::lights::shadow_visibility. The filters are the same
// functions the lighting pass would run; only where they run changes. When the frame does
// not resolve its filters (RenderOptions::visibility_resolve off), a light with contact
// shadows still gets a layer, holding them alone (SHADOW_FLAG_CONTACT_ONLY), which the
// lighting pass multiplies into the shadow it filters.
//
// With MSAA (MULTISAMPLED: 4 samples, or 2 with MSAA_X2) the prepass's depth and normals are
// multisampled: each pixel is resolved from its sample 0. Its depth is rebuilt at that
// sample's standard position (Vulkan, D3D and Metal share it), then carried along the
// surface's plane to the pixel centre, where the lighting pass shades: a pixel covered by one
// surface resolves what the lighting pass would filter. A lighting-pass fragment on an edge
// pixel whose sample 0 saw another surface reads that surface's shadow.
#import penumbra::contact::{SAMPLE_POSITION, camera_depth, camera_normals, contact_visibility}
#import penumbra::contract::{MAX_LIGHTS, RESOLVE_NONE, SHADOW_FLAG_CONTACT_ONLY}
#import penumbra::frame::{frame, world_at}
#import penumbra::lights::{filtered_visibility, light_count, light_incidence, make_surface}
#import penumbra::normal_packing::{packed_transmits, unpack_normal}
#import penumbra::shadows::bindings::lights
#ifdef MANY_LIGHTS
#import penumbra::shadows::bindings::more_lights
#endif
#import penumbra::shadows::types::{Light, Surface}

@group(1) @binding(2) var visibility: texture_storage_2d_array<r32float, write>;

// Writes `light`'s filtered shadow at `surface`, times its contact shadows, into its layer of
// the resolved visibility at `pixel` (1 where the pixel holds no shadow receiver); its contact
// shadows alone for a light with SHADOW_FLAG_CONTACT_ONLY (the lighting pass filters its
// maps); nothing for a light that is not resolved. `depth`: the prepass's at the pixel;
// `march`: whether contact shadows are marched (for the uniform list's lights only: the
// storage list's loop stays free of the march's loop, which nested there stopped lavapipe's
// loop limiter on scenes of thousands of lights; the CPU packs no contact shadows past it).
fn resolve_light(light: Light, surface: Surface, receiver: bool, transmits: bool, pixel: vec2<i32>, depth: f32, march: bool) {
    if light.resolve_layer == RESOLVE_NONE {
        return;
    }
    var shadow = 1.0;
    if receiver {
        let contact_only = (light.flags & SHADOW_FLAG_CONTACT_ONLY) != 0u;
        let to_light = light_incidence(light, surface.position).to_light;
        if dot(surface.normal, to_light) > 0.0 {
            if !contact_only {
                shadow = filtered_visibility(light, surface);
            }
            if march && shadow > 0.0 && light.contact_steps > 0u {
                let size = textureDimensions(camera_depth);
                shadow *= contact_visibility(light, surface.position, surface.normal, to_light, surface.frag_coord, depth, size);
            }
        } else if transmits && !contact_only {
            shadow = filtered_visibility(light, make_surface(surface.position, -surface.normal, surface.view_depth, surface.frag_coord));
        }
    }
    textureStore(visibility, pixel, i32(light.resolve_layer), vec4<f32>(shadow, 0.0, 0.0, 0.0));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(camera_depth);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    // NOTE: the last argument is the mip level, or with MSAA the sample index: sample 0.
    let depth = textureLoad(camera_depth, pixel, 0);
    let packed = textureLoad(camera_normals, pixel, 0).r;
    let normal_flag = unpack_normal(packed);
    // A surface with diffuse transmission facing away from a light shows the light its other
    // side receives: that side's shadow (the normal turned towards the light).
    let transmits = packed_transmits(packed);
    // Reverse-Z: 0 is the far plane, where nothing was drawn.
    let covered = depth > 0.0;
    let frag_coord = vec2<f32>(id.xy) + 0.5;
    let normal = normal_flag.xyz;
    var world = world_at(vec2<f32>(id.xy) + SAMPLE_POSITION, depth, size);
#ifdef MULTISAMPLED
    // Where the pixel centre's ray meets the plane of the surface sample 0 saw (the normal is
    // the prepass's, shaded at the centre): the point the lighting pass interpolates there.
    let a = world_at(frag_coord, depth, size);
    let ray = world_at(frag_coord, depth * 0.5, size) - a;
    let across = dot(normal, ray);
    if covered && abs(across) > 1e-4 * length(ray) {
        world = a + ray * (dot(normal, world - a) / across);
    }
#endif
    let view_depth = -(frame.view_from_world * vec4<f32>(world, 1.0)).z;
    let surface = make_surface(world, normal, view_depth, frag_coord);
    // The uniform list's lights, then (in the MANY_LIGHTS variants) the storage list's.
    let receiver = covered && normal_flag.w > 0.5;
    let count = light_count();
    for (var i = 0u; i < min(count, MAX_LIGHTS); i++) {
        resolve_light(lights.items[i], surface, receiver, transmits, pixel, depth, true);
    }
#ifdef MANY_LIGHTS
    for (var i = MAX_LIGHTS; i < count; i++) {
        resolve_light(more_lights[i - MAX_LIGHTS], surface, receiver, transmits, pixel, depth, false);
    }
#endif
}
