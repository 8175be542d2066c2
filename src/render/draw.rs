//! What every mesh pass shares: the vertex stage over the mesh buffers, the camera view's
//! rasterisation, and the instanced draws of a list of batches (multi-draws where nothing is
//! bound between them).

use crate::ecs::draw_groups::DrawBatch;
use crate::mesh::Vertex;
use crate::render::draw_args::{DrawArgs, IndexedArgs};
use crate::render::scene_gpu::SceneGpu;

/// Vertex layout of the mesh buffers: position (0), normal (1), uv (2).
pub const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2];

/// The vertex buffers of every mesh pipeline: the mesh vertices.
static MESH_BUFFERS: [Option<wgpu::VertexBufferLayout<'static>>; 1] = [Some(wgpu::VertexBufferLayout {
    array_stride: size_of::<Vertex>() as u64,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &VERTEX_ATTRIBUTES,
})];

/// The vertex buffers of a mesh pipeline (for a vertex stage of another entry point).
pub fn mesh_buffers() -> &'static [Option<wgpu::VertexBufferLayout<'static>>] {
    &MESH_BUFFERS
}

/// The vertex stage of a mesh pipeline: `vs_main` of `module` over the mesh buffers.
pub fn mesh_vertex_state(module: &wgpu::ShaderModule) -> wgpu::VertexState<'_> {
    wgpu::VertexState {
        module,
        entry_point: Some("vs_main"),
        compilation_options: Default::default(),
        buffers: &MESH_BUFFERS,
    }
}

/// Rasterisation of a camera-view mesh pipeline: back faces culled unless `double_sided`.
pub fn mesh_primitive(double_sided: bool) -> wgpu::PrimitiveState {
    wgpu::PrimitiveState {
        cull_mode: if double_sided { None } else { Some(wgpu::Face::Back) },
        ..Default::default()
    }
}

/// Binds what every camera-view mesh pass shares: the mesh buffers, the frame (group 0) and
/// the camera's instances (group 1). False (nothing bound) while the scene has no mesh.
pub fn bind_camera_view(pass: &mut wgpu::RenderPass<'_>, scene: &SceneGpu) -> bool {
    let Some((vertices, indices)) = scene.mesh_buffers() else {
        return false;
    };
    pass.set_vertex_buffer(0, vertices.slice(..));
    pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
    pass.set_bind_group(0, &scene.view_group, &[]);
    pass.set_bind_group(1, &scene.view_instances_group, &[]);
    true
}

/// Draws `batches` (instanced, indexed), binding each batch's material (group 2) when
/// `bind_material`: the batches between two material changes are one multi-draw where `args`
/// allows it ([`DrawArgs`]). Returns the draw commands recorded.
pub fn draw_batches(
    pass: &mut wgpu::RenderPass<'_>,
    scene: &SceneGpu,
    batches: &[DrawBatch],
    bind_material: bool,
    args: &mut DrawArgs,
) -> u32 {
    let mut last_material = None;
    let mut calls = 0;
    for batch in batches {
        let Some(range) = scene.mesh_ranges.get(batch.mesh.0 as usize) else {
            continue;
        };
        if bind_material && last_material != Some(batch.material) {
            let Some(group) = scene.material_groups.get(batch.material.0 as usize) else {
                continue;
            };
            calls += args.flush(pass);
            pass.set_bind_group(2, group, &[]);
            last_material = Some(batch.material);
        }
        args.push(IndexedArgs {
            index_count: range.index_count,
            instance_count: batch.count,
            first_index: range.first_index,
            base_vertex: range.base_vertex,
            first_instance: batch.first,
        });
    }
    calls + args.flush(pass)
}
