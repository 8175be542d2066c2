// Deferred lighting of the prepass's pixels: every pixel whose nearest surface is an opaque,
// untextured material (its shading id, written by the prepass, names its instance) is lit
// with the shipped material's lighting (penumbra::shading) from the prepass's depth and
// normal, so the lighting pass draws only the other materials again. The world position is
// rebuilt from the depth, as the compute resolve rebuilds it; the normal is the prepass's
// (penumbra::normal_packing). Composed with the forward shader's defs (one variant per
// forward variant).
//
// Two entry points: a full-screen triangle (`vs_main`, `fs_main`) that discards the other
// pixels over the colour the pass cleared, and, with DEFERRED_COMPUTE, a compute pass
// (`main`) that writes every pixel of the target's storage view: the lit colour, sRGB-
// encoded, or the clear colour where the lighting pass draws (or nothing was drawn). On GPUs
// whose fragment stage is slow next to their compute (the H200), the compute pass is the
// cheaper of the two.
#import penumbra::contract::{INSTANCE_FLAG_RECEIVE_SHADOWS, SHADING_ID_NONE}
#import penumbra::forward_io::transmission_byte
#import penumbra::frame::{frame, world_at}
#import penumbra::lights::make_surface
#import penumbra::mesh::Instance
#import penumbra::normal_packing::unpack_normal
#import penumbra::shading::{display_color, shade}

@group(2) @binding(0) var camera_depth: texture_depth_2d;
@group(2) @binding(1) var camera_normals: texture_2d<u32>;
@group(2) @binding(2) var shading_ids: texture_2d<u32>;
// The instance array (the one the mesh passes bind in group 1).
@group(2) @binding(3) var<storage, read> shaded_instances: array<Instance>;

// The colour of the surface seen at `pixel` (whose centre is `frag_coord`), alpha 1; alpha 0
// where the pixel is not lit here (another material's, or nothing drawn).
fn lit_pixel(pixel: vec2<i32>, frag_coord: vec2<f32>) -> vec4<f32> {
    let depth = textureLoad(camera_depth, pixel, 0);
    let id = textureLoad(shading_ids, pixel, 0).r;
    // Reverse-Z: 0 is the far plane, where the prepass drew nothing (the ids there are stale).
    if depth <= 0.0 || id == SHADING_ID_NONE {
        return vec4<f32>(0.0);
    }
    let instance = shaded_instances[id];
    let normal = unpack_normal(textureLoad(camera_normals, pixel, 0).r).xyz;
    let world = world_at(frag_coord, depth, textureDimensions(camera_depth));
    let view_depth = -(frame.view_from_world * vec4<f32>(world, 1.0)).z;
    let surface = make_surface(world, normal, view_depth, frag_coord);
    let receives = (instance.flags & INSTANCE_FLAG_RECEIVE_SHADOWS) != 0u;
#ifdef TRANSMISSION
    // NOTE: quantised as the forward pass's vertex stage passes it on.
    let through_share = f32(transmission_byte(instance.transmission)) / 255.0;
#else
    let through_share = 0.0;
#endif
    let shading = shade(surface, receives, through_share);
    return vec4<f32>(display_color(instance.base_color.rgb, shading.direct, surface), 1.0);
}

// One triangle that covers the whole target (vertices 0, 1, 2).
@vertex
fn vs_main(@builtin(vertex_index) vertex: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((vertex << 1u) & 2u), f32(vertex & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let color = lit_pixel(vec2<i32>(position.xy), position.xy);
    if color.a == 0.0 {
        discard;
    }
    return color;
}

#ifdef DEFERRED_COMPUTE
@group(2) @binding(4) var target_storage: texture_storage_2d<rgba8unorm, write>;
// rgb: the clear colour (linear), a: 1 to encode the written colours as sRGB.
@group(2) @binding(5) var<uniform> clear: vec4<f32>;

// The sRGB encoding of linear `c` (what an sRGB render target does on write).
fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    let low = c * 12.92;
    let high = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(high, low, c <= vec3<f32>(0.0031308));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(camera_depth);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    let lit = lit_pixel(pixel, vec2<f32>(id.xy) + 0.5);
    var color = select(clear.rgb, lit.rgb, lit.a > 0.0);
    if clear.a > 0.0 {
        color = srgb_encode(saturate(color));
    }
    textureStore(target_storage, pixel, vec4<f32>(color, 1.0));
}
#endif
