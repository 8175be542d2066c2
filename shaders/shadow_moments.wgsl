// Variance shadow maps: turns one light's depth layers into the covered moments
// `(o·z, o·z², o)` of its normalised distance `z` (`resolve`; `o` is 1 where a caster was
// drawn, 0 in an empty texel, so filtering keeps the occupied share), then pre-filters them with a separable Gaussian
// (`blur`, once along each axis: from the moments into a one-light scratch, and back). Spot lights store the distance along the light's axis over
// its range; point lights the distance from the light over its range, so the six faces of a
// cube agree along their shared edges, and their blur samples the cube along the face's axes:
// a tap past a face edge reads the neighbouring face (no seam).
//
// Shader defs: MOMENTS_POINT (the source is a cube array: faces in layer order +X, −X, +Y,
// −Y, +Z, −Z), MOMENTS_FP32 (the moments are `rgba32float`, else `rgba16float`).

struct MomentsJob {
    // First layer of the light in the source (depth, moments or scratch) and in the
    // destination (moments or scratch: the scratch holds one light, from layer 0); a point
    // light's layers start at its cube's first face.
    src_layer: u32,
    dst_layer: u32,
    // Texels per side of a layer.
    side: u32,
    // Blur radius in texels (the Gaussian's sigma is half of it).
    radius: u32,
    // 0: blur along x (the face's s axis), 1: along y (t).
    axis: u32,
    // Near plane and range of the light's views, metres.
    near: f32,
    range: f32,
    padding_a: f32,
}

@group(0) @binding(0) var depth_layers: texture_depth_2d_array;
#ifdef MOMENTS_FP32
@group(0) @binding(1) var moments_out: texture_storage_2d_array<rgba32float, write>;
#else
@group(0) @binding(1) var moments_out: texture_storage_2d_array<rgba16float, write>;
#endif
@group(0) @binding(2) var<uniform> job: MomentsJob;
@group(0) @binding(3) var moments_sampler: sampler;
#ifdef MOMENTS_POINT
@group(0) @binding(4) var moments_in: texture_cube_array<f32>;
#else
@group(0) @binding(4) var moments_in: texture_2d_array<f32>;
#endif

// The direction from the light through texel coordinates `st` (−1..1, y down) of `face`, by
// the cube-map face-selection table (inverse of `math::point::face_uv`).
fn face_direction(face: u32, st: vec2<f32>) -> vec3<f32> {
    let s = st.x;
    let t = st.y;
    switch face {
        case 0u: { return vec3<f32>(1.0, -t, -s); }
        case 1u: { return vec3<f32>(-1.0, -t, s); }
        case 2u: { return vec3<f32>(s, 1.0, t); }
        case 3u: { return vec3<f32>(s, -1.0, -t); }
        case 4u: { return vec3<f32>(s, -t, 1.0); }
        default: { return vec3<f32>(-s, -t, -1.0); }
    }
}

// The texel's centre in −1..1 coordinates of its layer.
fn texel_st(texel: vec2<u32>) -> vec2<f32> {
    return (vec2<f32>(texel) + 0.5) / f32(job.side) * 2.0 - 1.0;
}

fn store(texel: vec2<u32>, layer: u32, moments: vec3<f32>) {
    textureStore(moments_out, texel, layer, vec4<f32>(moments, 1.0));
}

// Depth to moments: one invocation per texel of the light's layers (z: layer of the light).
@compute @workgroup_size(8, 8, 1)
fn resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= job.side || id.y >= job.side {
        return;
    }
    let depth = clamp(textureLoad(depth_layers, id.xy, job.src_layer + id.z, 0), 0.0, 1.0);
    let near = job.near;
    let range = job.range;
#ifdef MOMENTS_POINT
    // Distance along the face's axis (inverse of `math::point::face_depth`), then along the
    // texel's ray.
    let axis = near * range / (depth * (range - near) + near);
    let st = texel_st(id.xy);
    let z = axis * sqrt(1.0 + dot(st, st)) / range;
#else
    // Distance along the spot light's axis (`math::spot::linear_distance`).
    let a = near / (range - near);
    let z = a * range / (depth + a) / range;
#endif
    // NOTE: reverse-Z clears to 0, the far plane: a texel no caster reached.
    let o = select(0.0, 1.0, depth > 0.0);
    store(id.xy, job.dst_layer + id.z, o * vec3<f32>(z, z * z, 1.0));
}

// Gaussian weight of a tap `k` texels away for a radius of `radius` texels (sigma = radius / 2).
fn gaussian(k: f32, radius: f32) -> f32 {
    let sigma = max(0.5 * radius, 0.5);
    return exp(-0.5 * k * k / (sigma * sigma));
}

// One axis of the separable Gaussian pre-blur.
@compute @workgroup_size(8, 8, 1)
fn blur(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= job.side || id.y >= job.side {
        return;
    }
    let r = i32(job.radius);
    let radius = f32(job.radius);
    let texel = 2.0 / f32(job.side);
    var sum = vec3<f32>(0.0);
    var weights = 0.0;
#ifdef MOMENTS_POINT
    let face = id.z;
    let cube = i32(job.src_layer / 6u);
    let st = texel_st(id.xy);
    let centre = face_direction(face, st);
    // The face's s or t axis in world space: a step of one texel along it.
    let step_st = select(vec2<f32>(texel, 0.0), vec2<f32>(0.0, texel), job.axis == 1u);
    let step = face_direction(face, st + step_st) - centre;
    for (var k = -r; k <= r; k++) {
        let w = gaussian(f32(k), radius);
        sum += w * textureSampleLevel(moments_in, moments_sampler, centre + step * f32(k), cube, 0.0).xyz;
        weights += w;
    }
#else
    let layer = job.src_layer + id.z;
    let uv = (vec2<f32>(id.xy) + 0.5) / f32(job.side);
    let step = select(vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0), job.axis == 1u) / f32(job.side);
    for (var k = -r; k <= r; k++) {
        let w = gaussian(f32(k), radius);
        sum += w * textureSampleLevel(moments_in, moments_sampler, uv + step * f32(k), layer, 0.0).xyz;
        weights += w;
    }
#endif
    store(id.xy, job.dst_layer + id.z, sum / weights);
}
