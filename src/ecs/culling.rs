//! Camera culling: every instance against the camera frustum, into [`ViewDrawGroups`] in
//! draw-key order, front to back by culling chunk ([`crate::ecs::view_order`]). A
//! frame whose camera matrix and instance list are those of the last frame keeps its groups.
//! (Shadow casters are culled per shadow view by
//! [`update_shadow_views`](crate::ecs::shadow_views::update_shadow_views).)

use std::time::Instant;

use bevy_ecs::system::{Local, Res, ResMut};
use glam::Mat4;

use crate::ecs::draw_groups::{ViewDrawGroups, push_run};
use crate::ecs::instances::RenderInstances;
use crate::ecs::stats::ShadowStats;
use crate::ecs::view::ActiveView;
use crate::ecs::view_order::{Run, front_to_back};
use crate::math::chunks::cull_spheres_frustum_chunked;
use crate::math::frustum::Frustum;

/// Reused buffers of [`cull_view`].
#[derive(Default)]
pub struct ViewScratch {
    visible: Vec<u32>,
    scratch: Vec<u32>,
    runs: Vec<Run>,
}

/// Culls every instance against the camera frustum into one draw group.
pub fn cull_view(
    view: Res<ActiveView>,
    instances: Res<RenderInstances>,
    mut groups: ResMut<ViewDrawGroups>,
    mut stats: ResMut<ShadowStats>,
    mut visible: Local<ViewScratch>,
    mut last: Local<Option<(Mat4, u64)>>,
) {
    let start = Instant::now();
    let key = view
        .camera
        .as_ref()
        .map(|(camera, _)| (camera.clip_from_world(), instances.generation));
    if key.is_some() && *last == key {
        stats.view_culling_cpu = start.elapsed();
        return;
    }
    *last = key;
    let groups = &mut *groups;
    groups.group.clear();
    groups.indices.clear();
    groups.generation += 1;
    if let Some((camera, _)) = &view.camera {
        let frustum = Frustum::from_clip_from_world(camera.clip_from_world());
        let ViewScratch { visible, scratch, runs } = &mut *visible;
        cull_spheres_frustum_chunked(
            &frustum,
            &instances.centers,
            &instances.radii,
            &instances.chunks,
            visible,
            scratch,
        );
        let eye = camera.position();
        front_to_back(visible, &instances.keys, &instances.chunks.centers, eye, runs);
        for run in runs.iter() {
            push_run(&mut groups.group, &mut groups.indices, run.key, run.of(visible));
        }
    }
    stats.visible_instances = groups.indices.len() as u32;
    stats.view_culling_cpu = start.elapsed();
}
