// Instance data and the vertex fetch shared by the caster and forward pipelines. Each draw
// covers a range of `draw_indices`, which point into the instance array, so one instanced
// draw renders every culled instance of one mesh.
#define_import_path penumbra::mesh

struct Instance {
    // World from local: its first three rows (the fourth is 0 0 0 1).
    world_rows: array<vec4<f32>, 3>,
    base_color: vec4<f32>,
    // Alpha below this is discarded (masked materials only).
    alpha_cutoff: f32,
    // Bit 0: receives shadows.
    flags: u32,
    // Diffuse transmission of a double-sided material (0 for solids): the share of the light
    // on its lit side that its other side shows.
    transmission: f32,
    padding: u32,
}

@group(1) @binding(0) var<storage, read> instances: array<Instance>;
@group(1) @binding(1) var<storage, read> draw_indices: array<u32>;

// The instance drawn by `instance_index` of the current draw.
fn fetch_instance(instance_index: u32) -> Instance {
    return instances[draw_indices[instance_index]];
}

// The world position of local point `p` of `instance`.
fn instance_position(instance: Instance, p: vec3<f32>) -> vec3<f32> {
    let q = vec4<f32>(p, 1.0);
    return vec3<f32>(dot(instance.world_rows[0], q), dot(instance.world_rows[1], q), dot(instance.world_rows[2], q));
}

// The world direction of local normal `n` of `instance`, not normalised: the cofactor matrix of
// the transform's linear part (its inverse transpose times its determinant) times the
// determinant's sign, so a mirroring transform keeps normals outwards.
fn instance_normal(instance: Instance, n: vec3<f32>) -> vec3<f32> {
    let r = instance.world_rows;
    let c0 = vec3<f32>(r[0].x, r[1].x, r[2].x);
    let c1 = vec3<f32>(r[0].y, r[1].y, r[2].y);
    let c2 = vec3<f32>(r[0].z, r[1].z, r[2].z);
    let x = cross(c1, c2);
    let sign = select(1.0, -1.0, dot(c0, x) < 0.0);
    return (x * n.x + cross(c2, c0) * n.y + cross(c0, c1) * n.z) * sign;
}
