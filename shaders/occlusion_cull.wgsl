// GPU culling of the camera view's instances: one workgroup per run of instances (at most one
// culling chunk's, each of one batch), one invocation per member. A member is culled when its
// bounding sphere is outside the frustum. Early (the default): a member in the frustum (with
// occlusion culling, only one seen last frame) is appended to its batch's early list, the
// batch's indirect instance count counting it. Late (`LATE`, with occlusion culling only):
// every member's bounding sphere is tested against the frustum and the depth pyramid the early
// draws left; the answer is the instance's "seen" flag for the next frame, and an instance seen
// now but not last frame is appended to the late list. A sphere is hidden when its nearest
// depth is farther than the farthest depth of every pyramid texel under its screen rectangle,
// read at the level where that rectangle spans at most 2 × 2 texels (reverse-Z: farther is
// smaller). The CPU mirror is `math::occlusion`.

#import penumbra::indirect::DrawArgs

struct Cull {
    clip_from_view: mat4x4<f32>,
    view_from_world: mat4x4<f32>,
    // The frustum's planes (unit normal inwards, offset), relative to the render origin.
    planes: array<vec4<f32>, 6>,
    // The camera's position, and (w) the error a level may have at unit view depth.
    eye: vec4<f32>,
    // The camera's unit forward direction.
    forward: vec4<f32>,
    // The pyramid's level 0 (the depth buffer's size), pixels.
    size: vec2<f32>,
    levels: u32,
    runs: u32,
    near: f32,
    // 1: occlusion culling (the early phase lists only instances seen last frame).
    occluding: u32,
    // Workgroups per row of the dispatch.
    row: u32,
    _pad: u32,
}

// Instances `first..first + count` (or, when `listed` is 1, the instances at those entries of
// the view's list), drawn by batch `batch`, or by batch `batch + l` at coarser level `l` of
// `levels` (of relative errors `errors[l - 1]`).
struct Run {
    first: u32,
    count: u32,
    batch: u32,
    listed: u32,
    levels: u32,
    errors: array<f32, 4>,
}

// The batch for sphere `b` of `run`: its coarsest level whose error, relative to the sphere's
// radius, stays within what its nearest view depth allows (the whole mesh for a sphere that
// reaches the camera's plane). The CPU mirror is `math::occlusion::level_for`.
fn level_batch(run: Run, b: vec4<f32>) -> u32 {
    let depth = dot(b.xyz - cull.eye.xyz, cull.forward.xyz) - b.w;
    var level = 0u;
    if depth > 0.0 {
        let budget = depth * cull.eye.w;
        for (var l = 1u; l <= run.levels; l++) {
            if run.errors[l - 1u] * b.w <= budget {
                level = l;
            }
        }
    }
    return run.batch + level;
}


@group(0) @binding(0) var<uniform> cull: Cull;
// Per instance: bounding-sphere centre (relative to the render origin) and radius.
@group(0) @binding(1) var<storage, read> bounds: array<vec4<f32>>;
// The view's draw list: an instance per entry (read by listed runs only).
@group(0) @binding(2) var<storage, read> entries: array<u32>;
// The runs to cull.
@group(0) @binding(3) var<storage, read> runs: array<Run>;
// Per instance: 1 when seen last frame (the late phase writes this frame's answer).
@group(0) @binding(4) var<storage, read_write> seen: array<u32>;
// Per batch: the phase's draw arguments (instance counts start at 0).
@group(0) @binding(5) var<storage, read_write> args: array<DrawArgs>;
// The phase's list: batch `b`'s instances from `args[b].first_instance`.
@group(0) @binding(6) var<storage, read_write> list: array<u32>;
// The depth pyramid, level after level (`occlusion_pyramid.wgsl`).
@group(0) @binding(7) var<storage, read> pyramid: array<f32>;

fn append(batch: u32, instance: u32) {
    let slot = atomicAdd(&args[batch].instance_count, 1u);
    list[args[batch].first_instance + slot] = instance;
}

// True when the sphere `b` is finite and meets every plane of the frustum (its radius padded by
// a relative 1e-5, as the CPU's chunk test pads, so rounding never culls a touching sphere).
fn in_frustum(b: vec4<f32>) -> bool {
    let r = max(b.w, 0.0);
    let pad = r + 1e-5 * (abs(b.x) + abs(b.y) + abs(b.z) + r);
    var inside = true;
    for (var i = 0u; i < 6u; i++) {
        let p = cull.planes[i];
        inside = inside && dot(p.xyz, b.xyz) + p.w >= -pad;
    }
    // NOTE: a comparison with NaN is false: a sphere that is not finite is outside.
    return inside;
}

// True when the sphere `b` lies behind the pyramid's depths everywhere it covers.
fn hidden(b: vec4<f32>) -> bool {
    let centre = cull.view_from_world * vec4<f32>(b.xyz, 1.0);
    let r = b.w;
    // NOTE: the view looks down -z; a sphere whose box reaches the near plane is kept.
    if -centre.z - r <= cull.near {
        return false;
    }
    var lo = vec2<f32>(1e30);
    var hi = vec2<f32>(-1e30);
    for (var i = 0u; i < 8u; i++) {
        let corner = centre.xyz + r * vec3<f32>(
            select(-1.0, 1.0, (i & 1u) != 0u),
            select(-1.0, 1.0, (i & 2u) != 0u),
            select(-1.0, 1.0, (i & 4u) != 0u),
        );
        let clip = cull.clip_from_view * vec4<f32>(corner, 1.0);
        let ndc = clip.xy / clip.w;
        lo = min(lo, ndc);
        hi = max(hi, ndc);
    }
    let nearest_clip = cull.clip_from_view * vec4<f32>(centre.xy, centre.z + r, 1.0);
    let nearest = nearest_clip.z / nearest_clip.w;
    // Pixels, y down, clamped to the screen.
    let p0 = clamp(vec2<f32>(lo.x * 0.5 + 0.5, 0.5 - hi.y * 0.5) * cull.size, vec2<f32>(0.0), cull.size);
    let p1 = clamp(vec2<f32>(hi.x * 0.5 + 0.5, 0.5 - lo.y * 0.5) * cull.size, vec2<f32>(0.0), cull.size);
    let extent = max(p1.x - p0.x, p1.y - p0.y);
    let level = u32(ceil(log2(max(extent, 1.0))));
    if level >= cull.levels {
        return false;
    }
    // The level's size and first texel: each level halves the one above (rounding down).
    var dims = vec2<u32>(cull.size);
    var offset = 0u;
    for (var k = 0u; k < level; k++) {
        offset += dims.x * dims.y;
        dims = max(dims / 2u, vec2<u32>(1u));
    }
    let scale = 1.0 / f32(1u << level);
    let t0 = min(vec2<u32>(floor(p0 * scale)), dims - 1u);
    let t1 = min(vec2<u32>(floor(p1 * scale)), dims - 1u);
    var farthest = 1.0;
    for (var y = t0.y; y <= t1.y; y++) {
        for (var x = t0.x; x <= t1.x; x++) {
            farthest = min(farthest, pyramid[offset + y * dims.x + x]);
        }
    }
    return nearest < farthest;
}

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let r = group.y * cull.row + group.x;
    if r >= cull.runs {
        return;
    }
    let run = runs[r];
    if lane >= run.count {
        return;
    }
    var instance = run.first + lane;
    if run.listed != 0u {
        instance = entries[instance];
    }
    let b = bounds[instance];
#ifdef LATE
    let now = in_frustum(b) && !hidden(b);
    let before = seen[instance] != 0u;
    seen[instance] = select(0u, 1u, now);
    if now && !before {
        append(level_batch(run, b), instance);
    }
#else
    if in_frustum(b) && (cull.occluding == 0u || seen[instance] != 0u) {
        append(level_batch(run, b), instance);
    }
#endif
}
