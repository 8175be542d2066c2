//! This frame's lights as the renderer sees them: every [`DirectionalLight`], [`SpotLight`]
//! and [`PointLight`] with a valid transform, its parameters repaired where they were out of
//! range (with a warning), and — for the lights that ask for shadows and fit the
//! [`ShadowLightBudget`] — the shadow settings and views. Computed by [`update_frame_lights`];
//! the per-view caster lists are built from it by
//! [`update_shadow_views`](crate::ecs::shadow_views::update_shadow_views).
//!
//! Lights are listed per kind; the renderer numbers them suns first, then spots, then points
//! ([`FrameLights::light_index`]), which is the order of the GPU light list a material loops
//! over.

use std::time::Instant;

use bevy_ecs::entity::Entity;
use bevy_ecs::name::Name;
use bevy_ecs::system::{Local, Query, Res, ResMut, SystemParam};
use bevy_transform::components::GlobalTransform;
use glam::{I64Vec2, Vec3};

use crate::ecs::components::DirectionalLight;
use crate::ecs::instances::RenderInstances;
use crate::ecs::light_checks::{sanitize_point, sanitize_spot, sanitize_sun, sanitized_settings, warn_mode};
use crate::ecs::light_views::{FrameLights, PointLightView, SpotLightView, SunView};
use crate::ecs::lights::{PointLight, SpotLight};
use crate::ecs::origin::RenderOrigin;
use crate::ecs::placement::{world_forward, world_pose};
use crate::ecs::shadow_memory::{MemoryScratch, ShadowMemory, ShadowMemoryBudget, apply_memory_budget};
use crate::ecs::stats::{ShadowDiagnostics, ShadowStats};
use crate::ecs::view::{ActiveView, SeenByCamera};
use crate::ecs::view_list::{POINT_NEAR, ShadowLightBudget};
use crate::math::cascades::{CascadeInput, CascadeSet, compute_cascades};
use crate::math::clipmap::{ClipmapInput, ClipmapSet, clipmap_cascades, compute_clipmap, moved_level};
use crate::math::light_budget::{
    BudgetChoice, LightCandidate, LightKind, RankScratch, RankingView, choose_shadowed_lights_into,
};
use crate::math::pages::{PageLayout, snap_to_pages};
use crate::math::point::point_view;
use crate::math::spot::spot_view;
use crate::settings::{ShadowSettings, SunLayout};
use crate::text::echoed;

/// Reused buffers of [`update_frame_lights`]. Candidates are identified by their index in
/// the renderer's light list ([`FrameLights::light_index`]).
#[derive(Default)]
pub struct LightScratch {
    candidates: Vec<LightCandidate>,
    rank: RankScratch,
    choice: BudgetChoice,
}

/// The shadow-memory budget's inputs and output in [`update_frame_lights`].
#[derive(SystemParam)]
pub struct MemoryParams<'w, 's> {
    budget: Res<'w, ShadowMemoryBudget>,
    account: ResMut<'w, ShadowMemory>,
    names: Query<'w, 's, &'static Name>,
    scratch: Local<'s, MemoryScratch>,
}

impl MemoryParams<'_, '_> {
    /// Fits the shadowed lights to the memory budget ([`apply_memory_budget`]), keeps the
    /// account, and raises its warning and error.
    fn apply(
        &mut self,
        lights: &mut FrameLights,
        shadowed: &mut Vec<usize>,
        ranking: &RankingView,
        diagnostics: &mut ShadowDiagnostics,
    ) {
        let names = &self.names;
        let name_of = |e| names.get(e).ok().map(|n: &Name| echoed(n.as_str()).into_owned());
        let budget = &*self.budget;
        if let Some(account) = apply_memory_budget(lights, shadowed, ranking, budget, name_of, &mut self.scratch) {
            *self.account = account;
        }
        for message in [&self.account.warning, &self.account.error].into_iter().flatten() {
            diagnostics.warn(message.clone());
        }
    }
}

/// Collects the lights, chooses which cast shadows under the budget (reporting the others),
/// and computes the cascades of shadowed suns and the views of shadowed spot and point lights.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn update_frame_lights(
    suns: Query<(Entity, &DirectionalLight, &GlobalTransform, Option<&ShadowSettings>)>,
    spots: Query<(Entity, &SpotLight, &GlobalTransform, Option<&ShadowSettings>)>,
    points: Query<(Entity, &PointLight, &GlobalTransform, Option<&ShadowSettings>)>,
    view: Res<ActiveView>,
    seen: Res<SeenByCamera>,
    origin: Res<RenderOrigin>,
    budget: Res<ShadowLightBudget>,
    instances: Res<RenderInstances>,
    mut lights: ResMut<FrameLights>,
    mut stats: ResMut<ShadowStats>,
    mut diagnostics: ResMut<ShadowDiagnostics>,
    mut scratch: Local<LightScratch>,
    mut memory: MemoryParams,
) {
    let start = Instant::now();
    let lights = &mut *lights;
    let scratch = &mut *scratch;
    lights.suns.clear();
    lights.spots.clear();
    lights.points.clear();
    scratch.candidates.clear();
    let diagnostics = &mut *diagnostics;
    for (entity, light, transform, settings) in &suns {
        let Some(direction) = world_forward(transform) else {
            diagnostics.warn_about(
                &entity.to_string(),
                format!(
                    "directional light {entity} has a non-finite or degenerate transform {:?}; it is ignored",
                    transform.affine()
                ),
            );
            continue;
        };
        let light = sanitize_sun(entity, light, diagnostics);
        let mut settings = sanitized_settings(settings, diagnostics);
        if light.shadows_enabled {
            warn_mode(diagnostics, "directional light", entity, &settings, true);
        }
        // NOTE: every pass reads the technique the light is filtered with, not the one asked.
        settings.filter.mode = settings.filter.mode.effective(true);
        if light.shadows_enabled {
            scratch.candidates.push(LightCandidate {
                id: lights.suns.len(),
                kind: LightKind::Directional,
                bounds: None,
            });
        }
        lights.suns.push(SunView {
            entity,
            direction,
            light,
            settings,
            resolution: settings.map.resolution,
            cascades: CascadeSet::default(),
            clipmap: ClipmapSet::default(),
            paged: None,
        });
    }
    for (entity, light, transform, settings) in &spots {
        let Some((rotation, position)) = world_pose(transform) else {
            diagnostics.warn_about(
                &entity.to_string(),
                format!("spot light {entity} has a non-finite or degenerate transform; it is ignored"),
            );
            continue;
        };
        let light = sanitize_spot(entity, light, diagnostics);
        let position = position - origin.0;
        if light.shadows_enabled {
            scratch.candidates.push(LightCandidate {
                id: lights.suns.len() + lights.spots.len(),
                kind: LightKind::Spot,
                bounds: Some((position, light.range)),
            });
        }
        // NOTE: a spot without its own settings uses the budget's resolution, so adding many
        // spot lights does not multiply the sun's 2048² maps.
        let resolution = settings.map_or(budget.spot_resolution, |s| s.map.resolution);
        let mut settings = sanitized_settings(settings, diagnostics);
        warn_mode(diagnostics, "spot light", entity, &settings, false);
        // NOTE: EVSM or MSM asked for a spot light is VSM for every pass (its moments are
        // baked only for VSM): read as asked, they were never baked and the light was dark.
        settings.filter.mode = settings.filter.mode.effective(false);
        lights.spots.push(SpotLightView {
            entity,
            position,
            direction: rotation * Vec3::NEG_Z,
            light,
            settings,
            resolution: resolution.max(1),
            shadow: None,
        });
    }
    for (entity, light, transform, settings) in &points {
        let Some((_, position)) = world_pose(transform) else {
            diagnostics.warn_about(
                &entity.to_string(),
                format!("point light {entity} has a non-finite or degenerate transform; it is ignored"),
            );
            continue;
        };
        let light = sanitize_point(entity, light, diagnostics);
        let position = position - origin.0;
        if light.shadows_enabled {
            scratch.candidates.push(LightCandidate {
                id: lights.suns.len() + lights.spots.len() + lights.points.len(),
                kind: LightKind::Point,
                bounds: Some((position, light.range)),
            });
        }
        let resolution = settings.map_or(budget.point_resolution, |s| s.map.resolution);
        let mut settings = sanitized_settings(settings, diagnostics);
        warn_mode(diagnostics, "point light", entity, &settings, false);
        settings.filter.mode = settings.filter.mode.effective(false);
        lights.points.push(PointLightView {
            entity,
            position,
            light,
            settings,
            resolution: resolution.max(1),
            shadow: None,
        });
    }
    let ranking = match &view.camera {
        Some((camera, _)) => RankingView {
            position: camera.position(),
            tan_half_fov_y: (camera.fov_y * 0.5).tan(),
        },
        None => RankingView {
            position: Vec3::ZERO,
            tan_half_fov_y: 1.0,
        },
    };
    choose_shadowed_lights_into(
        &scratch.candidates,
        &budget.lights,
        &ranking,
        &mut scratch.rank,
        &mut scratch.choice,
    );
    report_over_budget(lights, &scratch.choice, &budget, diagnostics);
    memory.apply(lights, &mut scratch.choice.shadowed, &ranking, diagnostics);
    // NOTE: point lights are sampled as one cube array, so they share a face size: the
    // largest any shadowed one asks for.
    let spots_end = lights.suns.len() + lights.spots.len();
    let point_side = scratch
        .choice
        .shadowed
        .iter()
        .filter_map(|&id| id.checked_sub(spots_end))
        .map(|p| lights.points[p].resolution)
        .max()
        .unwrap_or(0);
    let mut paged_taken = false;
    for &id in &scratch.choice.shadowed {
        if let Some(sun) = lights.suns.get_mut(id) {
            let Some((camera, _)) = &view.camera else {
                continue;
            };
            if let Some((levels, level0_extent)) = sun.settings.map.layout.clipmap_levels() {
                // NOTE: one sun is paged (the pool serves one); another is a plain clipmap.
                let pages = paged_layout(&sun.settings.map.layout).filter(|_| !paged_taken);
                paged_taken |= pages.is_some();
                sun.paged = pages;
                if let Some(pages) = pages {
                    sun.resolution = pages.virtual_resolution;
                }
                let mut clipmap = compute_clipmap(&ClipmapInput {
                    camera_position: camera.position(),
                    light_direction: sun.direction,
                    levels,
                    level0_extent,
                    resolution: sun.resolution,
                    casters: instances.caster_bounds,
                });
                if let Some(pages) = pages {
                    snap_levels_to_pages(&mut clipmap, &pages);
                }
                sun.cascades = clipmap_cascades(&clipmap, sun.light.angular_diameter);
                sun.clipmap = clipmap;
            } else {
                sun.cascades = compute_cascades(&CascadeInput {
                    camera: *camera,
                    light_direction: sun.direction,
                    scene_bounds: instances.caster_bounds,
                    receiver_bounds: instances.receiver_bounds,
                    count: sun.settings.map.cascades.count as usize,
                    split_lambda: sun.settings.map.cascades.split_lambda,
                    max_distance: sun.settings.map.max_distance,
                    resolution: sun.resolution,
                    fit: sun.settings.map.cascades.fit,
                    angular_diameter: sun.light.angular_diameter,
                    blend_width: sun.settings.map.cascades.blend_width,
                    snap_cells: sun.settings.map.cascades.snap_cells,
                    // NOTE: moments are blurred up to a layer's edges: a moments sun's
                    // cascades are drawn whole.
                    scroll: sun.settings.map.cascades.scroll
                        && !sun.settings.filter.mode.effective(true).is_sun_moments(),
                    seen: seen.relative_to(origin.0),
                });
            }
            continue;
        }
        if id >= spots_end {
            let point = &mut lights.points[id - spots_end];
            point.resolution = point_side;
            point.shadow = point_view(point.position, POINT_NEAR, point.light.range, point_side);
            if point.shadow.is_none() {
                diagnostics.warn_about(
                    &point.entity.to_string(),
                    format!(
                        "point light {} has range {:?}: no shadow view can be made",
                        point.entity, point.light.range
                    ),
                );
            }
            continue;
        }
        let spot = &mut lights.spots[id - lights.suns.len()];
        spot.shadow = spot_view(&spot.shadow_input());
        if spot.shadow.is_none() {
            diagnostics.warn_about(
                &spot.entity.to_string(),
                format!(
                    "spot light {} has range {:?}, outer angle {:?} rad: no shadow view can be made",
                    spot.entity, spot.light.range, spot.light.outer_angle
                ),
            );
        }
    }
    stats.cascades_cpu = start.elapsed();
}

/// Names every light over budget, per kind.
fn report_over_budget(
    lights: &FrameLights,
    choice: &BudgetChoice,
    budget: &ShadowLightBudget,
    diagnostics: &mut ShadowDiagnostics,
) {
    for &(kind, id) in &choice.dropped {
        let what = kind.word();
        let entity = match kind {
            LightKind::Directional => lights.suns[id].entity,
            LightKind::Spot => lights.spots[id - lights.suns.len()].entity,
            LightKind::Point => lights.points[id - lights.suns.len() - lights.spots.len()].entity,
        };
        let order = match kind {
            LightKind::Directional => "it comes later in the scene",
            _ => "it is smaller on screen",
        };
        diagnostics.warn_about(
            &entity.to_string(),
            format!(
                "{what} light {entity} gets no shadow: only {} shadowed {what} lights fit the budget, and {order}",
                budget.lights.of(kind)
            ),
        );
    }
}

/// The page layout of a paged clipmap (None for other layouts, or settings the checks have
/// not made valid).
pub fn paged_layout(layout: &SunLayout) -> Option<PageLayout> {
    match *layout {
        SunLayout::VirtualClipmap {
            virtual_resolution,
            page_size,
            ..
        } => PageLayout::new(virtual_resolution, page_size).ok(),
        _ => None,
    }
}

/// Moves each level of `clipmap` to the window of whole pages of `pages` nearest its own.
fn snap_levels_to_pages(clipmap: &mut ClipmapSet, pages: &PageLayout) {
    let half = i64::from(pages.virtual_resolution / 2);
    let rotation = clipmap.light_rotation;
    let count = clipmap.count;
    for level in clipmap.levels.iter_mut().take(count) {
        let centre = (level.first_texel + I64Vec2::splat(half)).as_dvec2();
        let first = snap_to_pages(centre, pages);
        *level = moved_level(rotation, level, first, pages.virtual_resolution);
    }
}
