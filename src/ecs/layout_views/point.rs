//! The point lights' views: six faces per shadowed point light, a cube of the points'
//! storage each, culled against the light's reach and then each face's frustum.

use glam::Vec4;

use crate::ecs::layout_views::ViewSink;
use crate::ecs::light_views::FrameLights;
use crate::ecs::view_list::{CullVolume, ShadowView, ShadowViewKind, ViewShading};
use crate::math::footprint::TileMask;
use crate::math::light_budget::LightKind;
use crate::math::point::FACES;

/// Appends every shadowed point light's six faces, layers numbered in order from 0. What
/// `point.wgsl` reads: `params` = (texel per metre of distance, near, reach, 0).
pub fn push_point_views(lights: &FrameLights, sink: &mut ViewSink<'_>) {
    let mut slot = 0;
    for (i, point) in lights.points.iter().enumerate() {
        let Some(shadow) = &point.shadow else { continue };
        let shading = ViewShading {
            near: shadow.near,
            far: shadow.range,
            params: Vec4::new(shadow.texel_per_metre, shadow.near, shadow.range, 0.0),
            ..ViewShading::default()
        };
        for face in 0..FACES {
            let view = ShadowView {
                entity: point.entity,
                light_kind: LightKind::Point,
                light: lights.light_index(LightKind::Point, i) as u32,
                kind: ShadowViewKind::point_face(face as u32),
                clip_from_world: shadow.faces[face],
                cull: CullVolume::CubeFace {
                    frustum: shadow.frusta[face],
                    center: point.position,
                    radius: point.light.range,
                },
                slot,
                resolution: point.resolution,
                shading,
                footprint: TileMask::EMPTY,
                version: 0,
                scroll: None,
            };
            sink.push(view, point.settings);
            slot += 1;
        }
    }
}
