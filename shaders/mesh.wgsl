// Instance data and the vertex fetch shared by the caster and forward pipelines. Each draw
// covers a range of `draw_indices`, which point into the instance array, so one instanced
// draw renders every culled instance of one mesh.
#define_import_path penumbra::mesh

struct Instance {
    world_from_local: mat4x4<f32>,
    // Inverse transpose of the upper 3x3 of world_from_local, in the first three columns.
    normal_from_local: mat4x4<f32>,
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
