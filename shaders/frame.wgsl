// Per-frame view data shared by every forward material: camera, ambient light, and the
// number of lights (the lights themselves are in penumbra::lights).
#define_import_path penumbra::frame

struct FrameUniforms {
    clip_from_world: mat4x4<f32>,
    view_from_world: mat4x4<f32>,
    // World space from camera clip space (the inverse of clip_from_world), for passes that
    // reconstruct positions from depth.
    world_from_clip: mat4x4<f32>,
    camera_position: vec3<f32>,
    exposure: f32,
    ambient: vec3<f32>,
    frame_index: u32,
    // Lights in penumbra::lights.
    light_count: u32,
    // The light analysis outputs and debug views report (an index below light_count, or
    // light_count when there is none).
    focus_light: u32,
    // 1 when the focus light's debug view shows its contact shadows alone (its resolved
    // layer, which then holds them).
    debug_contact: u32,
    padding_b: u32,
}

@group(0) @binding(0) var<uniform> frame: FrameUniforms;

// The world point at `pixel` (in pixels, from the top left) and reverse-Z `depth` of a
// camera target `size` pixels wide and high.
fn world_at(pixel: vec2<f32>, depth: f32, size: vec2<u32>) -> vec3<f32> {
    let ndc = vec2<f32>(pixel.x / f32(size.x) * 2.0 - 1.0, 1.0 - pixel.y / f32(size.y) * 2.0);
    let h = frame.world_from_clip * vec4<f32>(ndc, depth, 1.0);
    return h.xyz / h.w;
}
