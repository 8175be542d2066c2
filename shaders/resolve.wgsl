// Compute visibility resolve: for every pixel the depth prepass covered, rebuild the surface
// (world position from depth, normal and receiver flag from the prepass's normals) and write
// each resolved light's filtered shadow into its layer of the resolved visibility, which the
// lighting pass then reads through penumbra::lights::shadow_visibility. The filters are the
// same functions the lighting pass would run; only where they run changes.
#import penumbra::frame::frame
#import penumbra::lights::{filtered_visibility, get_light, light_count, light_incidence, make_surface}
#import penumbra::normal_packing::unpack_normal
#import penumbra::shadows::types::RESOLVE_NONE

@group(1) @binding(0) var camera_depth: texture_depth_2d;
@group(1) @binding(1) var camera_normals: texture_2d<u32>;
@group(1) @binding(2) var visibility: texture_storage_2d_array<r32float, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(camera_depth);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    let depth = textureLoad(camera_depth, pixel, 0);
    let normal_flag = unpack_normal(textureLoad(camera_normals, pixel, 0).r);
    // Reverse-Z: 0 is the far plane, where nothing was drawn.
    let covered = depth > 0.0;
    let frag_coord = vec2<f32>(id.xy) + 0.5;
    let ndc = vec2<f32>(frag_coord.x / f32(size.x) * 2.0 - 1.0, 1.0 - frag_coord.y / f32(size.y) * 2.0);
    let world_h = frame.world_from_clip * vec4<f32>(ndc, depth, 1.0);
    let world = world_h.xyz / world_h.w;
    let normal = normal_flag.xyz;
    let view_depth = -(frame.view_from_world * vec4<f32>(world, 1.0)).z;
    let surface = make_surface(world, normal, view_depth, frag_coord);
    for (var i = 0u; i < light_count(); i++) {
        let light = get_light(i);
        if light.resolve_layer == RESOLVE_NONE {
            continue;
        }
        var shadow = 1.0;
        if covered && normal_flag.w > 0.5 {
            let to_light = light_incidence(light, world).to_light;
            if dot(normal, to_light) > 0.0 {
                shadow = filtered_visibility(light, surface);
            }
        }
        textureStore(visibility, pixel, i32(light.resolve_layer), vec4<f32>(shadow, 0.0, 0.0, 0.0));
    }
}
