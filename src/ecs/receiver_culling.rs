//! Receiver-bounded caster culling for cascades ([`crate::math::receivers`]): each sun's
//! cascade boxes, as culling sees them, shrink to the light-space bounds of the visible
//! shadow receivers of their slice (grown by the filter's reach), so casters whose shadow
//! cannot land on anything the camera sees are not drawn. Recomputed only when the camera,
//! the instance list or the sun's cascades change.

use bevy_ecs::resource::Resource;
use glam::Mat4;

use crate::ecs::assets::Meshes;
use crate::ecs::draw_groups::ViewDrawGroups;
use crate::ecs::frame_lights::FrameLights;
use crate::ecs::instances::RenderInstances;
use crate::ecs::view::ActiveView;
use crate::math::aabb::Aabb;
use crate::math::cascades::CascadeSet;
use crate::math::frustum::slice_corners;
use crate::math::receivers::{Slice, receiver_bounds, shrink_to_receivers};
use crate::render::gpu_types::INSTANCE_FLAG_RECEIVE_SHADOWS;
use crate::settings::MAX_CASCADES;

/// How far, in shadow texels, a receiver's filter reads around it: the widest PCSS kernel
/// (32 texels) plus the largest PCF radius and normal offset, rounded up.
pub const FILTER_REACH_TEXELS: f32 = 48.0;

/// Switches of shadow-caster culling.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowCulling {
    /// Shrink cascade cull boxes to the visible receivers (default on).
    pub receivers: bool,
}

impl Default for ShadowCulling {
    fn default() -> Self {
        Self { receivers: true }
    }
}

/// What a sun's shrunk set was computed from.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Key {
    camera: Option<Mat4>,
    generation: u64,
    cascades: CascadeSet,
    enabled: bool,
}

/// Each sun's cascade set as culling uses it, kept between frames.
#[derive(Debug, Default)]
pub struct ReceiverCache {
    keys: Vec<Key>,
    sets: Vec<CascadeSet>,
    slices: Vec<Slice>,
    bounds: Vec<Aabb>,
}

impl ReceiverCache {
    /// Brings every sun's culling set up to date.
    pub fn update(
        &mut self,
        lights: &FrameLights,
        view: &ActiveView,
        groups: &ViewDrawGroups,
        instances: &RenderInstances,
        meshes: &Meshes,
        culling: ShadowCulling,
    ) {
        let camera = view.camera.as_ref().map(|(c, _)| c);
        self.keys.truncate(lights.suns.len());
        self.sets.truncate(lights.suns.len());
        for (i, sun) in lights.suns.iter().enumerate() {
            let key = Key {
                camera: camera.map(|c| c.clip_from_world()),
                generation: instances.generation,
                cascades: sun.cascades,
                enabled: culling.receivers,
            };
            if self.keys.get(i) == Some(&key) {
                continue;
            }
            let mut set = sun.cascades;
            if let (true, Some(camera)) = (culling.receivers, camera) {
                let count = set.count.min(MAX_CASCADES);
                self.slices.clear();
                for c in 0..count {
                    // NOTE: from the previous cascade's start, so the blend band that also
                    // samples this cascade is served.
                    let near = set.splits[c.saturating_sub(1)].max(camera.near);
                    let far = set.splits[c + 1].max(near);
                    self.slices.push(Slice {
                        near,
                        far,
                        world: Aabb::from_points(&slice_corners(camera, near, far)),
                    });
                }
                self.bounds.resize(count, Aabb::EMPTY);
                let receivers = groups.indices.iter().filter_map(|&k| {
                    let k = k as usize;
                    (instances.gpu.get(k)?.flags & INSTANCE_FLAG_RECEIVE_SHADOWS != 0)
                        .then(|| (instances.centers[k], instances.radii[k], k))
                });
                // NOTE: only receivers large against a slice ask for their box.
                let world_box = |k: usize| {
                    let mesh = meshes.get(instances.keys[k].mesh);
                    mesh.map_or(Aabb::EMPTY, |m| {
                        m.bounds().transformed(&instances.gpu[k].world_from_local)
                    })
                };
                receiver_bounds(
                    &set.light_rotation,
                    &camera.view_from_world(),
                    &self.slices,
                    receivers,
                    world_box,
                    &mut self.bounds,
                );
                for (cascade, bound) in set.cascades.iter_mut().zip(&self.bounds) {
                    let reach = FILTER_REACH_TEXELS * cascade.texel_world_size;
                    (cascade.light_min, cascade.light_max) =
                        shrink_to_receivers(cascade.light_min, cascade.light_max, bound, reach);
                }
            }
            if i < self.keys.len() {
                self.keys[i] = key;
                self.sets[i] = set;
            } else {
                self.keys.push(key);
                self.sets.push(set);
            }
        }
    }

    /// Sun `i`'s cascade set as culling uses it (after [`update`](Self::update)).
    pub fn set(&self, i: usize) -> &CascadeSet {
        &self.sets[i]
    }
}
