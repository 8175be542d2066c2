//! Culling systems: casters against each cascade's box (into [`ShadowDrawGroups`]) and all
//! instances against the camera frustum (into [`ViewDrawGroups`]).

use std::time::Instant;

use bevy_ecs::system::{Local, Res, ResMut};

use crate::ecs::draw_groups::{ShadowDrawGroups, ViewDrawGroups, push_instance};
use crate::ecs::instances::RenderInstances;
use crate::ecs::stats::ShadowStats;
use crate::ecs::view::ActiveView;
use crate::math::chunks::{cull_casters_chunked, cull_spheres_frustum_chunked};
use crate::math::frustum::Frustum;
use crate::settings::MAX_CASCADES;

/// Reused buffers of [`cull_shadow_casters`].
#[derive(Default)]
pub struct CullScratch {
    /// Cascade bit mask per caster.
    masks: Vec<u8>,
    /// Instance indices per cascade, in draw order.
    indices: [Vec<u32>; MAX_CASCADES],
}

/// Culls every caster against every active cascade and groups the survivors into instanced
/// draws per cascade, in one pass over the casters (they are sorted by draw key, so each
/// cascade's list comes out in draw order). Steady state allocates nothing: every buffer
/// keeps its capacity.
pub fn cull_shadow_casters(
    view: Res<ActiveView>,
    instances: Res<RenderInstances>,
    mut groups: ResMut<ShadowDrawGroups>,
    mut stats: ResMut<ShadowStats>,
    mut scratch: Local<CullScratch>,
) {
    let start = Instant::now();
    let groups = &mut *groups;
    groups.indices.clear();
    groups.cascades.iter_mut().for_each(|g| g.clear());
    groups.count = 0;
    stats.casters_per_cascade = [0; MAX_CASCADES];
    stats.draws_per_cascade = [0; MAX_CASCADES];
    let Some(sun) = view.sun.filter(|s| s.cascades.count > 0) else {
        stats.culling_cpu = start.elapsed();
        return;
    };
    let set = &sun.cascades;
    let CullScratch { masks, indices } = &mut *scratch;
    masks.resize(instances.casters.len(), 0);
    cull_casters_chunked(
        set,
        &instances.caster_centers,
        &instances.caster_radii,
        &instances.caster_chunks,
        masks,
    );
    indices.iter_mut().for_each(Vec::clear);
    for (&instance, &mask) in instances.casters.iter().zip(masks.iter()) {
        if mask == 0 {
            continue;
        }
        let key = instances.keys[instance as usize];
        let mut bits = mask;
        while bits != 0 {
            let c = bits.trailing_zeros() as usize;
            push_instance(&mut groups.cascades[c], &mut indices[c], key, instance);
            bits &= bits - 1;
        }
    }
    // Concatenate the per-cascade lists; batch starts move by the list's offset.
    groups.count = set.count;
    for (c, list) in indices.iter().enumerate().take(set.count) {
        let offset = groups.indices.len() as u32;
        groups.indices.extend_from_slice(list);
        let group = &mut groups.cascades[c];
        group
            .opaque
            .iter_mut()
            .chain(group.masked.iter_mut())
            .for_each(|b| b.first += offset);
        stats.casters_per_cascade[c] = list.len() as u32;
        stats.draws_per_cascade[c] = group.draw_count() as u32;
    }
    stats.culling_cpu = start.elapsed();
}

/// Culls every instance against the camera frustum into one draw group.
pub fn cull_view(
    view: Res<ActiveView>,
    instances: Res<RenderInstances>,
    mut groups: ResMut<ViewDrawGroups>,
    mut stats: ResMut<ShadowStats>,
    mut visible: Local<(Vec<u32>, Vec<u32>)>,
) {
    let start = Instant::now();
    let groups = &mut *groups;
    groups.group.clear();
    groups.indices.clear();
    if let Some((camera, _)) = &view.camera {
        let frustum = Frustum::from_clip_from_world(camera.clip_from_world());
        let (visible, scratch) = &mut *visible;
        cull_spheres_frustum_chunked(
            &frustum,
            &instances.centers,
            &instances.radii,
            &instances.chunks,
            visible,
            scratch,
        );
        for &i in visible.iter() {
            push_instance(&mut groups.group, &mut groups.indices, instances.keys[i as usize], i);
        }
    }
    stats.visible_instances = groups.indices.len() as u32;
    stats.view_culling_cpu = start.elapsed();
}
