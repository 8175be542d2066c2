// Compute skinning: linear blend skinning of bind-pose vertices into posed ones, once a frame,
// so every pass that draws the mesh (camera, prepass, each shadow view) reads vertices
// already skinned. Workgroup row `y` runs job `y`: its vertices `source_first ..
// source_first + vertex_count` of `bind_pose`, each blended from up to four joint matrices
// (`joint_first` + the vertex's joint index) by its weights, written to `posed` from
// `dest_first`. Positions take the blended matrix; normals its cofactor matrix (the inverse
// transpose up to scale), normalised. Vertices are 8 floats (position, normal, uv), as the
// vertex buffer lays them out; influences 6 words (joints 0-1 and 2-3 as 16-bit pairs, then
// the four weights' bits). The CPU mirror is `math::skinning`.

struct SkinJob {
    source_first: u32,
    vertex_count: u32,
    joint_first: u32,
    dest_first: u32,
}

@group(0) @binding(0) var<storage, read> bind_pose: array<f32>;
@group(0) @binding(1) var<storage, read> influences: array<u32>;
@group(0) @binding(2) var<storage, read> joints: array<mat4x4<f32>>;
@group(0) @binding(3) var<storage, read> jobs: array<SkinJob>;
@group(0) @binding(4) var<storage, read_write> posed: array<f32>;

const VERTEX_FLOATS: u32 = 8u;
const INFLUENCE_WORDS: u32 = 6u;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let job = jobs[id.y];
    if id.x >= job.vertex_count {
        return;
    }
    let vertex = job.source_first + id.x;
    let w = vertex * INFLUENCE_WORDS;
    let packed = vec2<u32>(influences[w], influences[w + 1u]);
    let index = vec4<u32>(packed.x & 0xffffu, packed.x >> 16u, packed.y & 0xffffu, packed.y >> 16u);
    let weight = vec4<f32>(
        bitcast<f32>(influences[w + 2u]),
        bitcast<f32>(influences[w + 3u]),
        bitcast<f32>(influences[w + 4u]),
        bitcast<f32>(influences[w + 5u]),
    );
    var m = mat4x4<f32>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    for (var k = 0u; k < 4u; k++) {
        if weight[k] > 0.0 {
            m += joints[job.joint_first + index[k]] * weight[k];
        }
    }
    let v = vertex * VERTEX_FLOATS;
    let position = vec3<f32>(bind_pose[v], bind_pose[v + 1u], bind_pose[v + 2u]);
    let normal = vec3<f32>(bind_pose[v + 3u], bind_pose[v + 4u], bind_pose[v + 5u]);
    let p = (m * vec4<f32>(position, 1.0)).xyz;
    // The cofactor matrix of the upper 3x3 (columns c0, c1, c2), signed by the determinant.
    let c0 = m[0].xyz;
    let c1 = m[1].xyz;
    let c2 = m[2].xyz;
    let cofactor = mat3x3<f32>(cross(c1, c2), cross(c2, c0), cross(c0, c1));
    let det = dot(c0, cross(c1, c2));
    var n = cofactor * normal * select(1.0, -1.0, det < 0.0);
    let length_n = length(n);
    if length_n > 1e-20 {
        n = n / length_n;
    } else {
        n = normal;
    }
    let o = (job.dest_first + id.x) * VERTEX_FLOATS;
    posed[o] = p.x;
    posed[o + 1u] = p.y;
    posed[o + 2u] = p.z;
    posed[o + 3u] = n.x;
    posed[o + 4u] = n.y;
    posed[o + 5u] = n.z;
    posed[o + 6u] = bind_pose[v + 6u];
    posed[o + 7u] = bind_pose[v + 7u];
}
