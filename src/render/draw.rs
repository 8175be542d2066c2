//! What every mesh pass shares: the vertex stage over the mesh buffers, the camera view's
//! rasterisation, and the instanced draws of a list of batches (multi-draws where nothing is
//! bound between them).

use crate::ecs::draw_groups::{DrawBatch, DrawGroup};
use crate::mesh::Vertex;
use crate::render::draw_args::{DrawArgs, IndexedArgs};
use crate::render::scene_gpu::{IndexList, SceneGpu};

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
/// the camera's instances (group 1: the view's list, or `instances` over a culling phase's).
/// False (nothing bound) while the scene has no mesh.
pub fn bind_camera_view(
    pass: &mut wgpu::RenderPass<'_>,
    scene: &SceneGpu,
    instances: Option<&wgpu::BindGroup>,
) -> bool {
    let Some((vertices, indices)) = scene.mesh_buffers() else {
        return false;
    };
    pass.set_vertex_buffer(0, vertices.slice(..));
    pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
    pass.set_bind_group(0, &scene.view_group, &[]);
    pass.set_bind_group(1, instances.unwrap_or(&scene.view_instances_group), &[]);
    true
}

/// The camera view's batches, opaque then masked, each split into single- and double-sided
/// parts (the draw key sorts single-sided first): `(masked, double_sided, part, its first
/// batch in opaque-then-masked order)`. With `masked` false the masked batches are left out.
pub fn camera_parts(group: &DrawGroup, masked: bool) -> [(bool, bool, &[DrawBatch], u32); 4] {
    let masked_batches: &[DrawBatch] = if masked { &group.masked } else { &[] };
    let base = group.opaque.len() as u32;
    let split = |b: &[DrawBatch]| b.partition_point(|b| !b.double_sided);
    let (o, m) = (split(&group.opaque), split(masked_batches));
    [
        (false, false, &group.opaque[..o], 0),
        (false, true, &group.opaque[o..], o as u32),
        (true, false, &masked_batches[..m], base),
        (true, true, &masked_batches[m..], base + m as u32),
    ]
}

/// Whether the batch's material is one of those `skipped` marks (indexed by material
/// handle; an empty slice skips none).
pub fn skipped(skipped: &[bool], batch: &DrawBatch) -> bool {
    skipped.get(batch.material.0 as usize).copied().unwrap_or(false)
}

/// Draws `batches` (instanced, indexed, from each mesh's index list `list`), binding each
/// batch's material (group 2) when `bind_material`: the batches between two material changes
/// are one multi-draw where `args` allows it ([`DrawArgs`]). Batches of the materials `skip`
/// marks are left out. Returns the draw commands recorded.
pub fn draw_batches(
    pass: &mut wgpu::RenderPass<'_>,
    (scene, list): (&SceneGpu, IndexList),
    batches: &[DrawBatch],
    (bind_material, skip): (bool, &[bool]),
    args: &mut DrawArgs,
) -> u32 {
    let mut last_material = None;
    let mut calls = 0;
    for batch in batches {
        let Some(range) = scene.mesh_ranges.get(batch.mesh.0 as usize) else {
            continue;
        };
        if skipped(skip, batch) {
            continue;
        }
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
            first_index: range.first_of(list),
            base_vertex: range.base_vertex,
            first_instance: batch.first,
        });
    }
    calls + args.flush(pass)
}

/// Draws `batches` from a culling phase's indirect arguments, batch `i` of the slice at
/// argument `first + i` ([`crate::render::occlusion`]): one multi-draw per run of batches
/// between material changes (materials bound and skipped as [`draw_batches`] binds and skips
/// them). Returns the draw commands recorded.
pub fn draw_culled(
    pass: &mut wgpu::RenderPass<'_>,
    scene: &SceneGpu,
    batches: &[DrawBatch],
    (bind_material, skip): (bool, &[bool]),
    (args, first): (&wgpu::Buffer, u32),
    counted: &mut DrawArgs,
) -> u32 {
    counted.count_gpu_written(batches.len());
    let stride = size_of::<IndexedArgs>() as u64;
    let mut calls = 0;
    let mut flush = |pass: &mut wgpu::RenderPass<'_>, run: std::ops::Range<usize>| {
        if !run.is_empty() {
            let offset = (u64::from(first) + run.start as u64) * stride;
            pass.multi_draw_indexed_indirect(args, offset, run.len() as u32);
            calls += 1;
        }
    };
    let (mut start, mut last_material, mut bound) = (0, None, true);
    for (i, batch) in batches.iter().enumerate() {
        if bind_material && last_material != Some(batch.material) {
            flush(pass, start..i);
            start = i;
            last_material = Some(batch.material);
            let group = scene.material_groups.get(batch.material.0 as usize);
            if let Some(group) = group {
                pass.set_bind_group(2, group, &[]);
            }
            bound = group.is_some();
        }
        // NOTE: a batch whose material has no group is not drawn, nor a skipped one.
        if skipped(skip, batch) {
            flush(pass, start..i);
            start = i + 1;
        } else if !bound {
            start = i + 1;
        }
    }
    flush(pass, start..batches.len());
    calls
}
