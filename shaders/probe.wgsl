// Evaluates one light's shadow at fixed world points, exactly as a material would, so the
// same points can be compared across frames while the camera moves (temporal stability). The
// light is the frame's focus light.
#import penumbra::frame::frame
#import penumbra::lights::{filtered_visibility, get_light, light_count, make_surface}

struct Probe {
    // xyz: world position, w: pixel x the point was seen at (seeds the per-pixel noise).
    position: vec4<f32>,
    // xyz: unit normal, w: pixel y.
    normal: vec4<f32>,
}

@group(1) @binding(0) var<storage, read> probes: array<Probe>;
@group(1) @binding(1) var<storage, read_write> results: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&results) {
        return;
    }
    if frame.focus_light >= light_count() {
        results[i] = 1.0;
        return;
    }
    let p = probes[i];
    let view_depth = -(frame.view_from_world * vec4<f32>(p.position.xyz, 1.0)).z;
    let pixel = vec2<f32>(p.position.w, p.normal.w) + 0.5;
    let surface = make_surface(p.position.xyz, p.normal.xyz, view_depth, pixel);
    results[i] = filtered_visibility(get_light(frame.focus_light), surface);
}
