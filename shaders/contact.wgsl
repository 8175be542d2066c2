// Contact shadows: from a pixel's surface, a short march towards a light over the depth the
// camera's prepass saw (`Light::contact_steps` samples along `contact.x` metres). A sample the
// camera cannot see, because the surface it saw there lies in front of it by less than
// `contact.y` metres along the camera's ray, is inside an occluder: the light is darkened by
// `contact.z`. The surface seen at a sample is taken as its plane (the prepass's depth and
// normal at that pixel), not as the depth at the pixel's centre, so flat ground at grazing
// angles does not shadow itself between pixel centres; a march that leaves the screen, goes
// behind the camera or reaches the sky finds nothing, so geometry off screen never invents a
// shadow. A sample is compared with the plane only when it lies behind the depth seen at its
// pixel's centre (the cheap test that rejects most samples). The start is jittered by interleaved-gradient noise (per frame with temporal
// rotation), which turns the steps' banding into noise. The CPU mirror is `math::contact`.
//
// The inputs are group 1 of the compute visibility resolve (single-sample, or each pixel's
// sample 0 with MULTISAMPLED).
#define_import_path penumbra::contact

#import penumbra::contract::{LIGHT_DIRECTIONAL, SHADOW_FLAG_TEMPORAL}
#import penumbra::frame::{frame, world_at}
#import penumbra::normal_packing::unpack_normal
#import penumbra::shadows::common::interleaved_gradient_noise
#import penumbra::shadows::types::Light

#ifdef MULTISAMPLED
@group(1) @binding(0) var camera_depth: texture_depth_multisampled_2d;
@group(1) @binding(1) var camera_normals: texture_multisampled_2d<u32>;
#ifdef MSAA_X2
const SAMPLE_POSITION: vec2<f32> = vec2<f32>(0.75, 0.75);
#else
const SAMPLE_POSITION: vec2<f32> = vec2<f32>(0.375, 0.125);
#endif
#else
@group(1) @binding(0) var camera_depth: texture_depth_2d;
@group(1) @binding(1) var camera_normals: texture_2d<u32>;
const SAMPLE_POSITION: vec2<f32> = vec2<f32>(0.5, 0.5);
#endif

// Below this cosine between the camera's ray and the plane seen at a sample, the plane is
// edge-on and its depth along the ray meaningless: the sample is compared by distance to the
// camera instead.
const EDGE_ON_COSINE: f32 = 0.05;
// A sample must lie this many pixel footprints behind the surface seen there to count as
// occluded: the prepass's depth and normal are rounded.
const DEPTH_TOLERANCE_PIXELS: f32 = 0.5;
const GOLDEN_RATIO_FRACT: f32 = 0.618033988749;

// How far `point` lies behind the surface the camera saw at `pixel` (depth `depth`, unit
// normal `normal`), metres along the camera's ray through `point`; negative in front of it.
fn hidden_by(point: vec3<f32>, pixel: vec2<i32>, depth: f32, normal: vec3<f32>, size: vec2<u32>) -> f32 {
    let seen = world_at(vec2<f32>(pixel) + SAMPLE_POSITION, depth, size);
    let ray = point - frame.camera_position;
    let ray_length = length(ray);
    let across = dot(ray, normal);
    if abs(across) > EDGE_ON_COSINE * ray_length {
        // Where the ray crosses the seen surface's plane, as a fraction of the way to `point`.
        let crossing = dot(seen - frame.camera_position, normal) / across;
        return ray_length * (1.0 - crossing);
    }
    return ray_length - distance(seen, frame.camera_position);
}

// The light's contact shadows at a surface point `position` (unit normal `normal`, seen at
// `pixel` of a `size` target with reverse-Z `depth`), towards the light along unit
// `to_light`: 1 - intensity where the march finds an occluder, 1 where it does not.
fn contact_visibility(light: Light, position: vec3<f32>, normal: vec3<f32>, to_light: vec3<f32>, pixel: vec2<f32>, depth: f32, size: vec2<u32>) -> f32 {
    let steps = light.contact_steps;
    var reach = light.contact.x;
    if light.kind != LIGHT_DIRECTIONAL {
        // A positional light's casters end at its emitter.
        reach = min(reach, distance(light.position, position) - light.size);
    }
    if steps == 0u || reach <= 0.0 {
        return 1.0;
    }
    // One pixel's width at the point, metres: the start leaves the surface by half of it.
    let footprint = distance(world_at(pixel + vec2<f32>(1.0, 0.0), depth, size), world_at(pixel, depth, size));
    let eye_distance = max(distance(position, frame.camera_position), 1e-6);
    let origin = position + normal * (DEPTH_TOLERANCE_PIXELS * footprint);
    var jitter = interleaved_gradient_noise(floor(pixel));
    if (light.flags & SHADOW_FLAG_TEMPORAL) != 0u {
        jitter = fract(jitter + f32(frame.frame_index % 4096u) * GOLDEN_RATIO_FRACT);
    }
    let step = reach / f32(steps);
    // Clip coordinates are linear in the world point: the march steps through them.
    let origin_clip = frame.clip_from_world * vec4<f32>(origin, 1.0);
    let step_clip = frame.clip_from_world * vec4<f32>(to_light * step, 0.0);
    let last = vec2<i32>(size) - 1;
    for (var i = 0u; i < steps; i++) {
        let along = f32(i) + jitter;
        let clip = origin_clip + step_clip * along;
        if clip.w <= 0.0 {
            break;
        }
        let ndc = clip.xy / clip.w;
        if any(abs(ndc) > vec2<f32>(1.0)) {
            break;
        }
        let at = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * vec2<f32>(size);
        let sample_pixel = clamp(vec2<i32>(floor(at)), vec2<i32>(0), last);
        let seen_depth = textureLoad(camera_depth, sample_pixel, 0);
        // Reverse-Z: a sample not behind the depth seen at its pixel's centre is not hidden
        // (nor is one over the sky, depth 0); only the others are compared with the plane.
        if clip.z / clip.w >= seen_depth {
            continue;
        }
        let point = origin + to_light * (along * step);
        let seen_normal = unpack_normal(textureLoad(camera_normals, sample_pixel, 0).r).xyz;
        let hidden = hidden_by(point, sample_pixel, seen_depth, seen_normal, size);
        let tolerance = DEPTH_TOLERANCE_PIXELS * footprint * distance(point, frame.camera_position) / eye_distance;
        if hidden > tolerance && hidden < light.contact.y {
            return 1.0 - light.contact.z;
        }
    }
    return 1.0;
}
