// GPU culling of shadow casters: one workgroup per run of casters (at most one culling chunk's,
// of one draw key, of one view), one invocation per member. A member whose bounding sphere
// reaches its view's volume is appended to the run's batch, the batch's indirect instance
// count counting it: a cascade's box (in the light's frame, open towards the light: casters
// between the light and the box cast into it), or a frustum (a spot light's; a cube face's,
// within its light's reach). Runs of views not drawn this frame do nothing. The CPU mirrors are
// `math::culling::sphere_reaches_light_box`, `Frustum::intersects_sphere` and
// `math::chunks::cull_spheres_sphere_chunked`'s member test.

#import penumbra::indirect::DrawArgs

// One view's volume. A box (`kind` 0): the light's rotation's rows in `a[0..3]`, the box's
// corner with the smallest coordinates in `a[3]` and its largest x, y in `a[4]`. A frustum
// (`kind` 1): its six planes (unit normal inwards, offset) in `a`, and a cube face's light
// position and reach in `reach` (w < 0: no reach).
struct CullView {
    a: array<vec4<f32>, 6>,
    reach: vec4<f32>,
    kind: u32,
    // 1 when the view is drawn this frame.
    drawn: u32,
    _pad0: u32,
    _pad1: u32,
}

// Casters `first..first + count` of view `view`, listed in batch `batch`.
struct Run {
    first: u32,
    count: u32,
    batch: u32,
    view: u32,
}

struct Dispatch {
    runs: u32,
    // Workgroups per row of the dispatch.
    row: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> dispatch: Dispatch;
@group(0) @binding(1) var<storage, read> views: array<CullView>;
// Per caster: bounding-sphere centre (relative to the render origin) and radius.
@group(0) @binding(2) var<storage, read> bounds: array<vec4<f32>>;
// Per caster: its instance.
@group(0) @binding(3) var<storage, read> casters: array<u32>;
@group(0) @binding(4) var<storage, read> runs: array<Run>;
// Per batch of every view: its draw arguments (instance counts start at 0).
@group(0) @binding(5) var<storage, read_write> args: array<DrawArgs>;
// Every view's list: batch `b`'s instances from `args[b].first_instance`.
@group(0) @binding(6) var<storage, read_write> list: array<u32>;

// Relative padding of a caster's radius per unit of its light-space L1 norm (the CPU's
// `CULL_PADDING`).
const CULL_PADDING: f32 = 1.0 / 1048576.0;

// True when every component of `v` is finite (NaN fails every comparison).
fn finite(v: vec4<f32>) -> bool {
    return all(abs(v) <= vec4<f32>(3.4028235e38));
}

// True when sphere `b` reaches the box of `view`.
fn reaches_box(view: CullView, b: vec4<f32>) -> bool {
    let c = vec4<f32>(b.xyz, 0.0);
    let p = vec3<f32>(dot(view.a[0], c), dot(view.a[1], c), dot(view.a[2], c));
    let r = max(b.w, 0.0) + CULL_PADDING * (abs(p.x) + abs(p.y) + abs(p.z));
    let lo = view.a[3];
    let hi = view.a[4];
    let dx = max(max(lo.x - p.x, p.x - hi.x), 0.0);
    let dy = max(max(lo.y - p.y, p.y - hi.y), 0.0);
    let dz = max(lo.z - p.z, 0.0);
    return finite(b) && finite(vec4<f32>(p, 0.0)) && dx * dx + dy * dy + dz * dz <= r * r;
}

// True when sphere `b` is finite, outside no plane of the frustum of `view`, and (with a
// reach) within the reach of its light.
fn reaches_frustum(view: CullView, b: vec4<f32>) -> bool {
    let r = max(b.w, 0.0);
    var inside = finite(b);
    for (var i = 0u; i < 6u; i++) {
        let p = view.a[i];
        inside = inside && dot(p.xyz, b.xyz) + p.w >= -r;
    }
    if view.reach.w >= 0.0 {
        inside = inside && distance(b.xyz, view.reach.xyz) <= view.reach.w + r;
    }
    return inside;
}

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let r = group.y * dispatch.row + group.x;
    if r >= dispatch.runs {
        return;
    }
    let run = runs[r];
    let view = views[run.view];
    if lane >= run.count || view.drawn == 0u {
        return;
    }
    let caster = run.first + lane;
    let b = bounds[caster];
    let kept = select(reaches_box(view, b), reaches_frustum(view, b), view.kind == 1u);
    if kept {
        let slot = atomicAdd(&args[run.batch].instance_count, 1u);
        list[args[run.batch].first_instance + slot] = casters[caster];
    }
}
