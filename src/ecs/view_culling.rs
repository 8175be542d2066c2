//! Culling casters into the draw groups of the shadow views that need it
//! ([`update_shadow_views`](crate::ecs::shadow_views::update_shadow_views)): a sun's cascades
//! in one pass over the casters (with each cascade's footprint and shadow LODs), a spot light
//! against its frustum, a point light's faces against theirs from the casters within its
//! reach; and each sun's single-pass list. For a renderer that culls casters on the GPU, a
//! large scene's views are culled by chunk only ([`crate::ecs::shadow_runs`]).

use bevy_ecs::entity::Entity;

use crate::ecs::assets::MeshHandle;
use crate::ecs::clipmap_scroll::ScrollScratch;
use crate::ecs::draw_groups::push_instance;
use crate::ecs::footprints::add_chunk_footprint;
use crate::ecs::instances::RenderInstances;
use crate::ecs::light_views::FrameLights;
use crate::ecs::lod_table::{lod_key, lod_table};
use crate::ecs::receiver_culling::ReceiverCache;
use crate::ecs::shadow_lods::ShadowLods;
use crate::ecs::shadow_runs::{GPU_SHADOW_MIN_CASTERS, cull_frustum_runs, cull_sun_runs};
use crate::ecs::single_pass::{SinglePassGroup, SunList};
use crate::ecs::view_cache::{CachedView, ViewCache};
use crate::ecs::view_list::{CullVolume, Region, ShadowView, ShadowViews};
use crate::math::cascades::MAX_SUN_VIEWS;
use crate::math::chunks::{CHUNK, cull_casters_chunked, cull_spheres_frustum_chunked, cull_spheres_sphere_chunked};
use crate::math::footprint::{ClipProjector, TileMask};
use crate::settings::ShadowSettings;

/// Reused buffers of [`update_shadow_views`](crate::ecs::shadow_views::update_shadow_views), and what each view held last frame.
#[derive(Default)]
pub struct ViewScratch {
    /// Cascade bit mask per caster.
    pub(crate) masks: Vec<u8>,
    pub(crate) visible: Vec<u32>,
    pub(crate) chunk_scratch: Vec<u32>,
    /// The light settings of each view of this frame.
    pub(crate) settings: Vec<ShadowSettings>,
    pub(crate) versions: Vec<u64>,
    pub(crate) cache: ViewCache,
    pub(crate) receivers: ReceiverCache,
    /// Per sun: its light entity and single-pass list (while single-pass lists are made).
    pub(crate) suns: Vec<(Option<Entity>, SunList)>,
    /// Single-pass lists were made last frame.
    pub(crate) single_pass: bool,
    /// Per mesh handle, the mesh each cascade of the sun being culled draws.
    pub(crate) lods: Vec<[MeshHandle; MAX_SUN_VIEWS]>,
    /// The casters within reach of one point light (the candidates of its faces), and the
    /// light they belong to this frame.
    pub(crate) point_candidates: Vec<u32>,
    /// Scrolling views' last windows and this frame's regions.
    pub(crate) scrolls: ScrollScratch,
    /// Regions no longer listed, kept with their allocations.
    pub(crate) spare_regions: Vec<Region>,
    /// Where the regions' entries start in the shadow views' index list (after the groups'
    /// and the single-pass lists').
    pub(crate) region_base: usize,
    pub(crate) candidates_of: Option<u32>,
    /// The views were culled for a renderer that culls casters on the GPU.
    pub(crate) gpu_shadows: bool,
}

/// Appends each sun's single-pass list after the view groups (none while they are off).
pub(crate) fn collect_single_pass(lights: &FrameLights, scratch: &ViewScratch, out: &mut ShadowViews) {
    let suns = if scratch.single_pass { lights.suns.len() } else { 0 };
    // NOTE: resized, not rebuilt, so the groups keep their allocations.
    out.single_pass.resize_with(suns, SinglePassGroup::default);
    let mut first_view = 0;
    for (i, ((_, sun), pass)) in scratch.suns.iter().zip(out.single_pass.iter_mut()).enumerate() {
        let set = scratch.receivers.set(i);
        pass.first_view = first_view;
        // NOTE: scrolling views are drawn one pass each (a clipmap's masks need more bits than
        // an entry packs, and a kept layer draws only strips); an empty run is never drawn
        // as one.
        pass.views = if set.scrolls { 0 } else { set.count as u32 };
        pass.group.append_copy(&sun.group, &sun.list, &mut out.indices);
        first_view += set.count as u32;
    }
}

/// Culls the casters of the views whose cache entry asks for it into the entry's list and
/// group (all cascades of a sun together when any of them needs it); returns whether any
/// view was culled. With `gpu_shadows` (the renderer culls casters on the GPU), in a scene of
/// at least [`GPU_SHADOW_MIN_CASTERS`] casters, the cascades of a sun without a single-pass
/// list or a clipmap ([`cull_sun_runs`]), spot lights and cube faces ([`cull_frustum_runs`])
/// are culled by chunk into runs.
pub(crate) fn cull_views(
    lights: &FrameLights,
    instances: &RenderInstances,
    lods: &ShadowLods,
    views: &[ShadowView],
    scratch: &mut ViewScratch,
    gpu_shadows: bool,
) -> bool {
    let entries = &mut scratch.cache.entries;
    let mut culled = false;
    let gpu_shadows = gpu_shadows && instances.casters.len() >= GPU_SHADOW_MIN_CASTERS;
    let mut first = 0;
    scratch.suns.resize_with(lights.suns.len(), Default::default);
    for (i, sun) in lights.suns.iter().enumerate() {
        let set = scratch.receivers.set(i);
        let range = first..first + set.count;
        first += set.count;
        // NOTE: a sun's single-pass list is made when its views are culled; one missing (just
        // turned on, or the sun at this index changed) has its views culled again.
        let (owner, list) = &mut scratch.suns[i];
        let single_pass = scratch.single_pass && !set.scrolls;
        let stale = single_pass && *owner != Some(sun.entity);
        if set.count == 0 || !(stale || entries[range.clone()].iter().any(|e| e.cull)) {
            continue;
        }
        debug_assert!(set.count <= MAX_SUN_VIEWS);
        culled = true;
        lod_table(lods, instances, sun.cascades.active(), &mut scratch.lods);
        let table = &scratch.lods;
        if gpu_shadows && !single_pass && !set.clipmap {
            // NOTE: each cascade's runs stand alone: only the cascades that moved are listed
            // again (a moving camera redraws the near ones most frames, the far ones seldom).
            let mut want = 0u8;
            for (c, entry) in entries[range.clone()].iter_mut().enumerate() {
                if entry.cull {
                    want |= 1 << c;
                    start_cull(entry);
                }
            }
            cull_sun_runs(
                set,
                instances,
                table,
                &views[range.clone()],
                (&mut entries[range.clone()], want),
            );
            for entry in entries[range.clone()].iter_mut().filter(|e| e.cull) {
                end_cull(entry);
            }
            *owner = None;
            continue;
        }
        for entry in &mut entries[range.clone()] {
            start_cull(entry);
        }
        scratch.masks.clear();
        scratch.masks.resize(instances.casters.len(), 0);
        cull_casters_chunked(
            set,
            &instances.caster_centers,
            &instances.caster_radii,
            &instances.caster_chunks,
            &mut scratch.masks,
        );
        // NOTE: most casters of a large scene are in no cascade; a run of them is skipped
        // with one test per culling chunk.
        let mut projectors = [ClipProjector::new(&glam::Mat4::IDENTITY); MAX_SUN_VIEWS];
        for (projector, view) in projectors.iter_mut().zip(&views[range.clone()]) {
            *projector = ClipProjector::new(&view.clip_from_world);
        }
        let casters = instances.casters.chunks(CHUNK).zip(scratch.masks.chunks(CHUNK));
        for (k, (casters, masks)) in casters.enumerate() {
            let any = masks.iter().fold(0, |a, &m| a | m);
            if any == 0 {
                continue;
            }
            let mut bits = any;
            while bits != 0 {
                let c = bits.trailing_zeros();
                let v = range.start + c as usize;
                let members = (0..masks.len())
                    .filter(|&j| masks[j] & 1 << c != 0)
                    .map(|j| k * CHUNK + j);
                add_chunk_footprint(
                    &mut entries[v].footprint,
                    &projectors[c as usize],
                    instances,
                    k,
                    (members, 1),
                );
                bits &= bits - 1;
            }
            for (&instance, &mask) in casters.iter().zip(masks) {
                let mut bits = mask;
                while bits != 0 {
                    let c = bits.trailing_zeros() as usize;
                    let key = lod_key(table, instances.keys[instance as usize], c);
                    let entry = &mut entries[range.start + c];
                    push_instance(&mut entry.group, &mut entry.list, key, instance);
                    bits &= bits - 1;
                }
            }
        }
        for entry in &mut entries[range.clone()] {
            end_cull(entry);
        }
        if single_pass {
            list.build(&instances.casters, &scratch.masks, &instances.keys, table);
            *owner = Some(sun.entity);
        } else {
            *owner = None;
        }
    }
    scratch.candidates_of = None;
    for (view, entry) in views.iter().zip(entries.iter_mut()).skip(first) {
        let (frustum, reach) = match view.cull {
            CullVolume::Frustum(frustum) => (frustum, None),
            CullVolume::CubeFace {
                frustum,
                center,
                radius,
            } => (frustum, Some((center, radius))),
            CullVolume::LightBox { .. } => continue,
        };
        if !entry.cull {
            continue;
        }
        culled = true;
        start_cull(entry);
        if gpu_shadows {
            cull_frustum_runs(&frustum, reach, &view.clip_from_world, instances, entry);
            end_cull(entry);
            continue;
        }
        let (centers, radii) = (&instances.caster_centers, &instances.caster_radii);
        match reach {
            // NOTE: a cube face is culled from the casters within its light's reach, found
            // once for the six faces of the light.
            Some((center, range)) => {
                if scratch.candidates_of != Some(view.light) {
                    let candidates = &mut scratch.point_candidates;
                    cull_spheres_sphere_chunked(center, range, centers, radii, &instances.caster_chunks, candidates);
                    scratch.candidates_of = Some(view.light);
                }
                scratch.visible.clear();
                let inside = |&&k: &&u32| frustum.intersects_sphere(centers[k as usize], radii[k as usize]);
                scratch.visible.extend(scratch.point_candidates.iter().filter(inside));
            }
            None => cull_spheres_frustum_chunked(
                &frustum,
                centers,
                radii,
                &instances.caster_chunks,
                &mut scratch.visible,
                &mut scratch.chunk_scratch,
            ),
        }
        // NOTE: visible casters come in ascending order, so a chunk's members are a run.
        let projector = ClipProjector::new(&view.clip_from_world);
        for run in scratch
            .visible
            .chunk_by(|a, b| *a as usize / CHUNK == *b as usize / CHUNK)
        {
            let chunk = run[0] as usize / CHUNK;
            let members = run.iter().map(|&k| k as usize);
            add_chunk_footprint(&mut entry.footprint, &projector, instances, chunk, (members, 1));
        }
        for &k in &scratch.visible {
            let instance = instances.casters[k as usize];
            push_instance(
                &mut entry.group,
                &mut entry.list,
                instances.keys[instance as usize],
                instance,
            );
        }
        end_cull(entry);
    }
    culled
}

/// Empties a view's list, runs and group for culling, keeping the last list and runs to
/// compare.
fn start_cull(entry: &mut CachedView) {
    std::mem::swap(&mut entry.list, &mut entry.previous);
    std::mem::swap(&mut entry.runs, &mut entry.previous_runs);
    entry.list.clear();
    entry.runs.clear();
    entry.partial = (false, entry.partial.0);
    entry.group.clear();
    entry.footprint = TileMask::EMPTY;
}

/// After culling: a view that may keep its version ([`CachedView::keep`]) keeps it when it
/// found exactly the casters of its last culling (its map would be drawn the same): the same
/// list, or for the GPU the same runs from chunks wholly inside the volume both times.
fn end_cull(entry: &mut CachedView) {
    let same_runs = entry.runs == entry.previous_runs && entry.partial == (false, false);
    if let Some(version) = entry.keep
        && entry.list == entry.previous
        && same_runs
    {
        entry.version = version;
    }
}
