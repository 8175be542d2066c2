//! Shadow views: every view a shadow map is rendered from this frame — each cascade of each
//! shadowed sun, each shadowed spot light, each cube face of each shadowed point light, as
//! their layouts make them ([`crate::ecs::layout_views`]) — in one list ([`ShadowViews`]),
//! with the casters of
//! each culled into its own draw group. Nothing here has a fixed count: the lists grow with
//! the lights, keep their capacity between frames, and allocate nothing once the scene has
//! been seen.
//!
//! Each view has a `slot` in the storage of its kind (a layer of the cascades' depth array,
//! a layer of the spot lights' array, a face of the point lights' cube array); the renderer
//! allocates storage from these slots.

use std::time::Instant;

use bevy_ecs::system::{Local, Res, ResMut};

use crate::ecs::assets::Meshes;
use crate::ecs::caster_changes::CasterChanges;
use crate::ecs::clipmap_scroll::{ScrollResync, plan_scrolls};
use crate::ecs::draw_groups::{DrawGroup, ShadowRun};
use crate::ecs::instances::RenderInstances;
use crate::ecs::layout_views::{ViewSink, push_views};
use crate::ecs::light_views::FrameLights;
use crate::ecs::receiver_culling::ShadowCulling;
use crate::ecs::shadow_lods::ShadowLods;
use crate::ecs::single_pass::single_pass_cascades;
use crate::ecs::stats::ShadowStats;
use crate::ecs::view::ActiveView;
use crate::ecs::view_cache::ViewInput;
use crate::ecs::view_culling::{ViewScratch, collect_single_pass, cull_views};
use crate::ecs::view_list::ShadowViews;
pub use crate::layout::ShadowStorage;
use crate::math::cascades::TexelGrid;

/// Lists the shadow views of the shadowed lights, gives each its content version
/// ([`ViewCache`](crate::ecs::view_cache::ViewCache)), and culls every caster into the draw group of each view it touches — only
/// for views that moved or whose instance list was rebuilt; the others keep last frame's
/// group. A sun's cascades are culled in one pass over the casters (sorted by draw key, so
/// each list comes out in draw order), a spot light or a point light's face against its
/// frustum; where the renderer culls casters on the GPU
/// ([`ShadowCulling::gpu_shadows`](crate::ecs::receiver_culling::ShadowCulling::gpu_shadows)),
/// a large scene's views are culled by chunk only and listed as runs
/// ([`crate::ecs::shadow_runs`]).
#[allow(clippy::too_many_arguments)]
pub fn update_shadow_views(
    lights: Res<FrameLights>,
    instances: Res<RenderInstances>,
    changes: Res<CasterChanges>,
    view: Res<ActiveView>,
    meshes: Res<Meshes>,
    culling: Option<Res<ShadowCulling>>,
    lods: Option<Res<ShadowLods>>,
    resync: Option<ResMut<ScrollResync>>,
    mut out: ResMut<ShadowViews>,
    mut stats: ResMut<ShadowStats>,
    mut scratch: Local<ViewScratch>,
) {
    let start = Instant::now();
    let out = &mut *out;
    let scratch = &mut *scratch;
    let culling = culling.map_or_else(ShadowCulling::default, |c| *c);
    // NOTE: the views the renderer asked for again are taken out, the list kept for its
    // allocation.
    let mut resync = resync;
    let asked = resync.as_deref_mut().map(|r| std::mem::take(&mut r.views));
    let resync = ScrollResync {
        views: asked.unwrap_or_default(),
    };
    scratch.receivers.update(&lights, &view, &instances, &meshes, culling);
    out.views.clear();
    scratch.settings.clear();
    let mut sink = ViewSink {
        views: &mut out.views,
        settings: &mut scratch.settings,
    };
    push_views(&lights, &scratch.receivers, &mut sink);
    let inputs = out.views.iter().zip(&scratch.settings).map(|(v, settings)| ViewInput {
        entity: v.entity,
        kind: v.kind,
        clip_from_world: match v.scroll {
            Some(_) => TexelGrid::at_origin(v.clip_from_world),
            None => v.clip_from_world,
        },
        resolution: v.resolution,
        key: settings.map_key(),
        cull: &v.cull,
        scrolls: v.scroll.is_some(),
        // NOTE: a clipmap level's casters are culled again only for a new version (its strips
        // are culled on their own); a scrolling cascade's whenever its box moves, so the
        // list a whole draw takes (on the GPU, by chunk) always serves the current box.
        lazy: v.scroll.is_some()
            && culling.cached
            && !resync.wants(v.entity, v.kind.index)
            && lights.sun_at(v.light).is_some_and(|s| s.cascades.clipmap),
    });
    scratch
        .cache
        .plan(inputs, instances.generation, &changes, &mut scratch.versions);
    for (view, &version) in out.views.iter_mut().zip(&scratch.versions) {
        view.version = version;
    }
    // NOTE: views listed for the other culling (GPU or CPU) are culled again.
    if culling.gpu_shadows != scratch.gpu_shadows {
        scratch.gpu_shadows = culling.gpu_shadows;
        scratch.cache.entries.iter_mut().for_each(|e| e.cull = true);
    }
    let single_pass = single_pass_cascades(culling.single_pass, culling.multiview_views, instances.keys.len());
    let toggled = single_pass != scratch.single_pass;
    scratch.single_pass = single_pass;
    let no_lods = ShadowLods::default();
    let lods = lods.as_deref().unwrap_or(&no_lods);
    let culled = cull_views(&lights, &instances, lods, &out.views, scratch, culling.gpu_shadows);
    let entries = &scratch.cache.entries;
    for (view, entry) in out.views.iter_mut().zip(entries) {
        view.footprint = entry.footprint;
        view.version = entry.version;
    }
    scratch.scrolls.cached = culling.cached;
    let regions = plan_scrolls(
        &lights,
        &instances,
        lods,
        &changes,
        &mut out.views,
        entries,
        &mut scratch.scrolls,
    );
    // NOTE: with every view reused in the same order, last frame's groups stand as they are.
    let stale = regions > 0 || !out.regions.is_empty();
    if culled || toggled || scratch.cache.reordered || out.groups.len() != entries.len() {
        out.groups.resize_with(entries.len(), DrawGroup::default);
        out.indices.clear();
        out.runs.clear();
        out.run_ranges.clear();
        for (v, (entry, group)) in entries.iter().zip(out.groups.iter_mut()).enumerate() {
            let first = out.runs.len() as u32;
            out.runs
                .extend(entry.runs.iter().map(|r| ShadowRun { view: v as u32, ..*r }));
            out.run_ranges.push((first, entry.runs.len() as u32));
            if entry.runs.is_empty() {
                group.append_copy(&entry.group, &entry.list, &mut out.indices);
            } else {
                // NOTE: a GPU-culled view's batches are room in its own list, not entries here.
                group.clone_from(&entry.group);
            }
        }
        collect_single_pass(&lights, scratch, out);
        scratch.region_base = out.indices.len();
        out.generation += 1;
    }
    if stale {
        // NOTE: the regions' entries follow the groups'; only they are made again when the
        // groups stand, so a level scrolling over a large field copies its strips' casters,
        // not its whole list.
        out.indices.truncate(scratch.region_base);
        // NOTE: regions past this frame's count wait in the spare list with their
        // allocations, so a walk whose strips come and go allocates nothing.
        while out.regions.len() > regions {
            scratch.spare_regions.extend(out.regions.pop());
        }
        while out.regions.len() < regions {
            out.regions.push(scratch.spare_regions.pop().unwrap_or_default());
        }
        for (region, draw) in out.regions.iter_mut().zip(&scratch.scrolls.regions) {
            region.rect = draw.rect;
            region.group.append_copy(&draw.group, &draw.list, &mut out.indices);
        }
        out.generation += 1;
    }
    stats.casters_per_view.clear();
    stats.draws_per_view.clear();
    for entry in entries {
        let candidates: u32 = entry.runs.iter().map(|r| r.count).sum();
        stats.casters_per_view.push(entry.list.len() as u32 + candidates);
        stats.draws_per_view.push(entry.group.draw_count() as u32);
    }
    stats.culling_cpu = start.elapsed();
}
