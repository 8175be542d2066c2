// Per-frame view data shared by every forward material: camera, sun and ambient light.
#define_import_path penumbra::frame

struct FrameUniforms {
    clip_from_world: mat4x4<f32>,
    view_from_world: mat4x4<f32>,
    camera_position: vec3<f32>,
    exposure: f32,
    // Direction the sun's light travels, unit length.
    sun_direction: vec3<f32>,
    sun_illuminance: f32,
    sun_color: vec3<f32>,
    frame_index: u32,
    ambient: vec3<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
