//! Culling systems: casters against each cascade's box (into [`ShadowDrawGroups`]) and all
//! instances against the camera frustum (into [`ViewDrawGroups`]).

use std::time::Instant;

use bevy_ecs::system::{Local, Res, ResMut};

use crate::ecs::draw_groups::{ShadowDrawGroups, ViewDrawGroups, push_instance};
use crate::ecs::instances::RenderInstances;
use crate::ecs::stats::ShadowStats;
use crate::ecs::view::ActiveView;
use crate::math::culling::{cull_casters, cull_spheres_frustum};
use crate::math::frustum::Frustum;

/// Culls every caster against every active cascade and groups the survivors into instanced
/// draws per cascade. Steady state allocates nothing: the mask buffer and the groups keep
/// their capacity.
pub fn cull_shadow_casters(
    view: Res<ActiveView>,
    instances: Res<RenderInstances>,
    mut groups: ResMut<ShadowDrawGroups>,
    mut stats: ResMut<ShadowStats>,
    mut masks: Local<Vec<u8>>,
) {
    let start = Instant::now();
    let groups = &mut *groups;
    groups.indices.clear();
    groups.cascades.iter_mut().for_each(|g| g.clear());
    groups.count = 0;
    stats.casters_per_cascade = [0; 4];
    stats.draws_per_cascade = [0; 4];
    let Some(sun) = view.sun.filter(|s| s.cascades.count > 0) else {
        stats.culling_cpu = start.elapsed();
        return;
    };
    let set = &sun.cascades;
    masks.resize(instances.casters.len(), 0);
    cull_casters(set, &instances.caster_centers, &instances.caster_radii, &mut masks);
    groups.count = set.count;
    for c in 0..set.count {
        let bit = 1u8 << c;
        let group = &mut groups.cascades[c];
        for (&instance, &mask) in instances.casters.iter().zip(masks.iter()) {
            if mask & bit != 0 {
                push_instance(group, &mut groups.indices, instances.keys[instance as usize], instance);
            }
        }
        stats.casters_per_cascade[c] = group.instance_count();
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
    mut visible: Local<Vec<u32>>,
) {
    let start = Instant::now();
    let groups = &mut *groups;
    groups.group.clear();
    groups.indices.clear();
    if let Some((camera, _)) = &view.camera {
        let frustum = Frustum::from_clip_from_world(camera.clip_from_world());
        cull_spheres_frustum(&frustum, &instances.centers, &instances.radii, &mut visible);
        for &i in visible.iter() {
            push_instance(&mut groups.group, &mut groups.indices, instances.keys[i as usize], i);
        }
    }
    stats.visible_instances = groups.indices.len() as u32;
    stats.view_culling_cpu = start.elapsed();
}
