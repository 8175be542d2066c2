//! The spot lights' views: one perspective view per shadowed spot light, a layer each of the
//! spots' storage, culled against its frustum.

use glam::Vec4;

use crate::ecs::layout_views::ViewSink;
use crate::ecs::light_views::FrameLights;
use crate::ecs::view_list::{CullVolume, ShadowView, ShadowViewKind, ViewShading};
use crate::math::footprint::TileMask;
use crate::math::light_budget::LightKind;

/// Appends every shadowed spot light's view, layers numbered in order from 0. What
/// `spot.wgsl` reads: `params` = (texel per metre of distance, near, far, 0).
pub fn push_spot_views(lights: &FrameLights, sink: &mut ViewSink<'_>) {
    let mut slot = 0;
    for (i, spot) in lights.spots.iter().enumerate() {
        let Some(shadow) = &spot.shadow else { continue };
        let view = ShadowView {
            entity: spot.entity,
            light_kind: LightKind::Spot,
            light: lights.light_index(LightKind::Spot, i) as u32,
            kind: ShadowViewKind::SPOT,
            clip_from_world: shadow.clip_from_world,
            cull: CullVolume::Frustum(shadow.frustum),
            slot,
            resolution: spot.resolution,
            shading: ViewShading {
                near: shadow.near,
                far: shadow.far,
                params: Vec4::new(shadow.texel_per_metre, shadow.near, shadow.far, 0.0),
                ..ViewShading::default()
            },
            footprint: TileMask::EMPTY,
            version: 0,
            scroll: None,
        };
        sink.push(view, spot.settings);
        slot += 1;
    }
}
