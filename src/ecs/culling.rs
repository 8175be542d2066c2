//! Camera culling: every instance against the camera frustum, into [`ViewDrawGroups`] in
//! draw-key order, front to back by culling chunk ([`crate::ecs::view_order`]), each run of
//! a chunk drawn with the coarsest mesh level its size on screen allows
//! ([`crate::ecs::view_lod`]); or, for a renderer that culls on the GPU, by chunk only
//! ([`crate::ecs::camera_runs`]). A frame whose camera matrix, viewport height, LOD setting,
//! culling and instance list are those of the last frame keeps its groups. Chunks culled for
//! the GPU are culled against the frustum grown by a margin ([`HELD_MARGIN`] of its depth),
//! and kept while the camera's frustum stays inside that (the GPU tests each instance against
//! the camera's own frustum every frame): a camera moving a little each frame lists its chunks
//! again only when it has moved about the margin.
//! (Shadow casters are culled per shadow view by
//! [`update_shadow_views`](crate::ecs::shadow_views::update_shadow_views).)

use std::time::Instant;

use bevy_ecs::system::{Local, Res, ResMut};
use glam::Mat4;

use crate::ecs::assets::MeshHandle;
use crate::ecs::camera_runs::cull_chunk_runs;
use crate::ecs::components::ViewportSize;
use crate::ecs::draw_groups::{DrawKey, ViewDrawGroups, push_run};
use crate::ecs::instances::RenderInstances;
use crate::ecs::receiver_culling::ShadowCulling;
use crate::ecs::shadow_lods::ShadowLods;
use crate::ecs::stats::ShadowStats;
use crate::ecs::view::ActiveView;
use crate::ecs::view_lod::{CameraLod, ViewLod};
use crate::ecs::view_order::{Run, front_to_back};
use crate::math::chunks::{CHUNK, cull_spheres_frustum_chunked};
use crate::math::frustum::{Frustum, slice_corners};

/// How far out, as a fraction of the camera's far distance, the frustum that chunks are
/// culled against for the GPU reaches past the camera's (they are kept while the camera's
/// frustum stays inside it). Larger keeps them longer and has the GPU test more instances.
pub const HELD_MARGIN: f32 = 0.005;

/// Reused buffers of [`cull_view`].
#[derive(Default)]
pub struct ViewScratch {
    visible: Vec<u32>,
    scratch: Vec<u32>,
    runs: Vec<Run>,
    /// The grown frustum the GPU's chunks were culled against, and what else they were made
    /// for (the instance list's generation, the viewport height, the LOD setting).
    held: Option<(Frustum, (u64, u32, CameraLod))>,
}

/// What the camera view's groups were made for: the camera matrix, the instance list's
/// generation, the viewport height, the LOD setting and whether the GPU culls instances.
type ViewKey = (Mat4, u64, u32, CameraLod, bool);

/// Culls every instance against the camera frustum into one draw group, each run with the
/// mesh level [`CameraLod`] allows (every mesh whole without [`ShadowLods`]).
#[allow(clippy::too_many_arguments)]
pub fn cull_view(
    view: Res<ActiveView>,
    instances: Res<RenderInstances>,
    lods: Option<Res<ShadowLods>>,
    lod: Option<Res<CameraLod>>,
    viewport: Res<ViewportSize>,
    culling: Option<Res<ShadowCulling>>,
    mut groups: ResMut<ViewDrawGroups>,
    (mut stats, mut visible): (ResMut<ShadowStats>, Local<ViewScratch>),
    mut last: Local<Option<ViewKey>>,
) {
    let start = Instant::now();
    let lod = lod.map_or_else(CameraLod::default, |l| *l);
    let gpu = culling.is_some_and(|c| c.gpu_camera);
    let key = view.camera.as_ref().map(|(camera, _)| {
        (
            camera.clip_from_world(),
            instances.generation,
            viewport.height,
            lod,
            gpu,
        )
    });
    if key.is_some() && *last == key {
        stats.view_culling_cpu = start.elapsed();
        return;
    }
    *last = key;
    let view_lod = view.camera.as_ref().and_then(|(camera, _)| {
        let eye = (camera.position(), camera.forward());
        (lods.as_deref()).and_then(|lods| ViewLod::new(lods, lod, eye, camera.fov_y, viewport.height))
    });
    let held_for = (instances.generation, viewport.height, lod);
    if let (true, Some((camera, _)), Some((grown, made_for))) = (gpu, &view.camera, &visible.held)
        && *made_for == held_for
        && grown.contains_points(&slice_corners(camera, camera.near, camera.far))
    {
        // NOTE: the runs stand; only the LOD's error scale follows the camera.
        groups.lod_error_per_depth = view_lod.as_ref().map_or(0.0, ViewLod::error_per_depth);
        stats.view_culling_cpu = start.elapsed();
        return;
    }
    visible.held = None;
    let groups = &mut *groups;
    groups.group.clear();
    groups.indices.clear();
    groups.runs.clear();
    groups.lod_error_per_depth = 0.0;
    groups.generation += 1;
    if let Some((camera, _)) = &view.camera {
        let frustum = Frustum::from_clip_from_world(camera.clip_from_world());
        let ViewScratch {
            visible,
            scratch,
            runs,
            held,
        } = &mut *visible;
        let eye = camera.position();
        let grown = frustum.dilated(HELD_MARGIN * camera.far);
        if gpu && cull_chunk_runs(&grown, view_lod.as_ref(), &instances, groups) {
            *held = Some((grown, held_for));
            stats.visible_instances = groups.candidate_count() as u32;
            stats.view_culling_cpu = start.elapsed();
            return;
        }
        cull_spheres_frustum_chunked(
            &frustum,
            &instances.centers,
            &instances.radii,
            &instances.chunks,
            visible,
            scratch,
        );
        front_to_back(visible, &instances.keys, &instances.chunks.centers, eye, runs);
        for run in runs.iter() {
            let members = run.of(visible);
            let key = match &view_lod {
                Some(v) => DrawKey {
                    mesh: chunk_mesh(v, run.key.mesh, &instances, members),
                    ..run.key
                },
                None => run.key,
            };
            push_run(&mut groups.group, &mut groups.indices, key, members);
        }
    }
    stats.visible_instances = groups.indices.len() as u32;
    stats.view_culling_cpu = start.elapsed();
}

/// The mesh [`ViewLod::mesh_for_chunk`] gives the culling chunk of `members` (one chunk's).
fn chunk_mesh(lod: &ViewLod, mesh: MeshHandle, instances: &RenderInstances, members: &[u32]) -> MeshHandle {
    let chunks = &instances.chunks;
    let k = members.first().map_or(0, |&i| i as usize / CHUNK);
    match (chunks.boxes.get(k), chunks.max_radii.get(k)) {
        (Some(bounds), Some(&radius)) => lod.mesh_for_chunk(mesh, bounds, radius),
        _ => mesh,
    }
}
