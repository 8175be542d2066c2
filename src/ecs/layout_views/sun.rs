//! The sun's views: a layer of the cascades' storage per cascade or clipmap level of each
//! shadowed sun, culled against the light-space box the receivers bound; a clipmap level, or
//! a cascade of a sun whose cascades scroll, scrolls ([`Scroll`]) rather than being drawn
//! again when its box moves; a paged sun's levels are virtual views of the page pool.

use glam::Vec4;

use crate::ecs::layout_views::ViewSink;
use crate::ecs::light_views::FrameLights;
use crate::ecs::receiver_culling::ReceiverCache;
use crate::ecs::view_list::{CullVolume, Scroll, ShadowView, ShadowViewKind, ViewPaging, ViewShading};
use crate::layout::ShadowStorage;
use crate::math::cascades::Cascade;
use crate::math::footprint::TileMask;
use crate::math::light_budget::LightKind;

/// What `cascades.wgsl` reads of a cascade or clipmap level: `params` = (texel world size,
/// light size in UV, PCSS scale, UV y scale), `range` = (near, far, depth range, 0; the
/// renderer writes the moments' depth start into `w`).
pub fn cascade_shading(cascade: &Cascade) -> ViewShading {
    let k = cascade;
    ViewShading {
        near: k.near,
        far: k.far,
        texel_world_size: k.texel_world_size,
        params: Vec4::new(k.texel_world_size, k.light_size_uv, k.pcss_scale, k.uv_scale_y),
        range: Vec4::new(k.near, k.far, k.depth_range, 0.0),
        page: None,
    }
}

/// Appends every shadowed sun's views: cascades and plain clipmap levels in the cascades'
/// storage, layers numbered in order from 0; a paged sun's levels in the page pool, level `c`
/// at slot `c` (its page table's level).
pub fn push_sun_views(lights: &FrameLights, receivers: &ReceiverCache, sink: &mut ViewSink<'_>) {
    let mut slot = 0;
    for (i, sun) in lights.suns.iter().enumerate() {
        let set = &sun.cascades;
        let culled = receivers.set(i);
        for (c, (cascade, cull)) in set.active().iter().zip(culled.active()).enumerate() {
            let window = cascade.grid.first_texel;
            let mut shading = cascade_shading(cascade);
            let (kind, view_slot, scroll) = match sun.paged {
                Some(pages) => {
                    shading.page = Some(ViewPaging {
                        first_page: pages.page_of(window),
                        page_size: pages.page_size,
                    });
                    let kind = ShadowViewKind {
                        storage: ShadowStorage::Pages,
                        index: c as u32,
                    };
                    (kind, c as u32, None)
                }
                None => {
                    let scroll = set.scrolls.then_some(Scroll {
                        from: window,
                        to: window,
                        ..Scroll::default()
                    });
                    slot += 1;
                    (ShadowViewKind::cascade(c as u32), slot - 1, scroll)
                }
            };
            let view = ShadowView {
                entity: sun.entity,
                light_kind: LightKind::Directional,
                light: lights.light_index(LightKind::Directional, i) as u32,
                kind,
                clip_from_world: cascade.clip_from_world,
                cull: CullVolume::LightBox {
                    light_rotation: set.light_rotation,
                    min: cull.light_min,
                    max: cull.light_max,
                },
                slot: view_slot,
                resolution: sun.resolution,
                shading,
                footprint: TileMask::EMPTY,
                version: 0,
                scroll,
            };
            sink.push(view, sun.settings);
        }
    }
}
