//! Shadow views: every view a shadow map is rendered from this frame — each cascade of each
//! shadowed sun, each shadowed spot light — in one list ([`ShadowViews`]), with the casters of
//! each culled into its own draw group. Nothing here has a fixed count: the lists grow with
//! the lights, keep their capacity between frames, and allocate nothing once the scene has
//! been seen.
//!
//! Each view has a `slot` in the storage of its kind (a layer of the cascades' depth array,
//! a layer of the spot lights' array); the renderer allocates storage from these slots.

use std::time::Instant;

use bevy_ecs::entity::Entity;
use bevy_ecs::resource::Resource;
use bevy_ecs::system::{Local, Res, ResMut};
use glam::{Mat3, Mat4, Vec3};

use crate::ecs::assets::Meshes;
use crate::ecs::caster_changes::CasterChanges;
use crate::ecs::draw_groups::{DrawGroup, push_instance};
use crate::ecs::footprints::chunk_footprint;
use crate::ecs::frame_lights::FrameLights;
use crate::ecs::instances::RenderInstances;
use crate::ecs::receiver_culling::{ReceiverCache, ShadowCulling};
use crate::ecs::single_pass::{MAX_PACKED_INSTANCES, SinglePassGroup, SunList};
use crate::ecs::stats::ShadowStats;
use crate::ecs::view::ActiveView;
use crate::ecs::view_cache::{CachedView, ViewCache, ViewInput};
use crate::math::chunks::{CHUNK, cull_casters_chunked, cull_spheres_frustum_chunked};
use crate::math::footprint::TileMask;
use crate::math::frustum::Frustum;
use crate::math::light_budget::{LightKind, ShadowBudget};
use crate::settings::{MAX_CASCADES, ShadowSettings};

/// How many lights of each kind may cast shadows, and the shadow-map size of a spot light
/// without its own [`ShadowSettings`].
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowLightBudget {
    /// Most shadowed lights per kind (4 suns; the seed's layout: 8 spot lights, 4 point
    /// lights).
    pub lights: ShadowBudget,
    /// Side of a spot light's shadow map, texels.
    pub spot_resolution: u32,
}

impl Default for ShadowLightBudget {
    fn default() -> Self {
        Self {
            lights: ShadowBudget {
                directional: 4,
                spot: 8,
                point: 4,
            },
            spot_resolution: 1024,
        }
    }
}

/// Near plane of a spot light's shadow view, metres: casters closer to the light are clamped
/// to it (depth clamping) or clipped.
pub const SPOT_NEAR: f32 = 0.05;

/// What a shadow view renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowViewKind {
    /// Cascade `i` of a directional light (into the cascades' depth array).
    Cascade(u32),
    /// A spot light's perspective view (into the spot lights' depth array).
    Spot,
}

/// The volume a view's casters must touch to be drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CullVolume {
    /// A cascade's light-space box (casters are extended towards the light).
    LightBox {
        /// Light space from world, rotation only.
        light_rotation: Mat3,
        /// Box corner with the smallest coordinates, light space.
        min: Vec3,
        /// Box corner with the largest coordinates, light space.
        max: Vec3,
    },
    /// A perspective view's frustum.
    Frustum(Frustum),
}

/// One view a shadow map is rendered from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowView {
    /// The light's entity.
    pub entity: Entity,
    /// The light's kind.
    pub light_kind: LightKind,
    /// The light's index in the renderer's light list ([`FrameLights::light_index`]).
    pub light: u32,
    /// What the view renders.
    pub kind: ShadowViewKind,
    /// Light clip space from world (reverse-Z), relative to the render origin.
    pub clip_from_world: Mat4,
    /// What its casters were culled against.
    pub cull: CullVolume,
    /// Its layer in the storage of its kind.
    pub slot: u32,
    /// Side of its shadow map, texels.
    pub resolution: u32,
    /// The tiles of its map its casters can write ([`crate::ecs::footprints`]): what a
    /// redraw of the layer must clear first.
    pub footprint: TileMask,
    /// Content version: the same while nothing that changes this map changed (its matrix,
    /// resolution, light settings, or a caster in its cull volume); unique across views, so
    /// the renderer redraws a layer only when the version it holds differs.
    pub version: u64,
}

/// This frame's shadow views and their culled casters: `groups[i]` holds the draws of
/// `views[i]`, indexing `indices`. Views are listed suns first (cascade by cascade), then
/// spot lights, in the order of [`FrameLights`].
#[derive(Resource, Debug, Default)]
pub struct ShadowViews {
    /// Every view rendered this frame.
    pub views: Vec<ShadowView>,
    /// The casters of each view, as instanced draws.
    pub groups: Vec<DrawGroup>,
    /// Each sun's casters listed once for a single-pass draw of its cascades, while
    /// [`ShadowCulling::single_pass`] is on (else empty); their packed entries follow the
    /// groups' in `indices`.
    pub single_pass: Vec<SinglePassGroup>,
    /// Instance indices of every group, concatenated.
    pub indices: Vec<u32>,
    /// Bumped whenever `groups` and `indices` are rebuilt (the renderer uploads them then).
    pub generation: u64,
}

impl ShadowViews {
    /// What the storage of cascades (`true`) or of spot lights (`false`) must hold this
    /// frame: the side of its largest view and the number of layers (0, 0 without views).
    pub fn extent(&self, cascades: bool) -> (u32, u32) {
        self.views
            .iter()
            .filter(|v| matches!(v.kind, ShadowViewKind::Cascade(_)) == cascades)
            .fold((0, 0), |(side, layers), v| {
                (side.max(v.resolution), layers.max(v.slot + 1))
            })
    }
}

/// Reused buffers of [`update_shadow_views`], and what each view held last frame.
#[derive(Default)]
pub struct ViewScratch {
    /// Cascade bit mask per caster.
    masks: Vec<u8>,
    visible: Vec<u32>,
    chunk_scratch: Vec<u32>,
    /// The light settings of each view of this frame.
    settings: Vec<ShadowSettings>,
    versions: Vec<u64>,
    cache: ViewCache,
    receivers: ReceiverCache,
    /// Per sun: its light entity and single-pass list (while single-pass lists are made).
    suns: Vec<(Option<Entity>, SunList)>,
    /// Single-pass lists were made last frame.
    single_pass: bool,
}

/// Lists the shadow views of the shadowed lights, gives each its content version
/// ([`ViewCache`]), and culls every caster into the draw group of each view it touches — only
/// for views that moved or whose instance list was rebuilt; the others keep last frame's
/// group. A sun's cascades are culled in one pass over the casters (sorted by draw key, so
/// each list comes out in draw order), a spot light against its frustum.
#[allow(clippy::too_many_arguments)]
pub fn update_shadow_views(
    lights: Res<FrameLights>,
    instances: Res<RenderInstances>,
    changes: Res<CasterChanges>,
    view: Res<ActiveView>,
    meshes: Res<Meshes>,
    culling: Option<Res<ShadowCulling>>,
    mut out: ResMut<ShadowViews>,
    mut stats: ResMut<ShadowStats>,
    mut scratch: Local<ViewScratch>,
) {
    let start = Instant::now();
    let out = &mut *out;
    let scratch = &mut *scratch;
    let culling = culling.map_or_else(ShadowCulling::default, |c| *c);
    scratch.receivers.update(&lights, &view, &instances, &meshes, culling);
    out.views.clear();
    scratch.settings.clear();
    let mut cascade_slot = 0;
    for (i, sun) in lights.suns.iter().enumerate() {
        let set = &sun.cascades;
        let culled = scratch.receivers.set(i);
        for (c, (cascade, cull)) in set.active().iter().zip(culled.active()).enumerate() {
            out.views.push(ShadowView {
                entity: sun.entity,
                light_kind: LightKind::Directional,
                light: lights.light_index(LightKind::Directional, i) as u32,
                kind: ShadowViewKind::Cascade(c as u32),
                clip_from_world: cascade.clip_from_world,
                cull: CullVolume::LightBox {
                    light_rotation: set.light_rotation,
                    min: cull.light_min,
                    max: cull.light_max,
                },
                slot: cascade_slot,
                resolution: sun.settings.resolution,
                footprint: TileMask::EMPTY,
                version: 0,
            });
            scratch.settings.push(sun.settings);
            cascade_slot += 1;
        }
    }
    let mut spot_slot = 0;
    for (i, spot) in lights.spots.iter().enumerate() {
        let Some(shadow) = &spot.shadow else { continue };
        out.views.push(ShadowView {
            entity: spot.entity,
            light_kind: LightKind::Spot,
            light: lights.light_index(LightKind::Spot, i) as u32,
            kind: ShadowViewKind::Spot,
            clip_from_world: shadow.clip_from_world,
            cull: CullVolume::Frustum(shadow.frustum),
            slot: spot_slot,
            resolution: spot.settings.resolution,
            footprint: TileMask::EMPTY,
            version: 0,
        });
        scratch.settings.push(spot.settings);
        spot_slot += 1;
    }
    let inputs = out.views.iter().zip(&scratch.settings).map(|(v, settings)| ViewInput {
        entity: v.entity,
        kind: v.kind,
        clip_from_world: v.clip_from_world,
        resolution: v.resolution,
        settings,
        cull: &v.cull,
    });
    scratch
        .cache
        .plan(inputs, instances.generation, &changes, &mut scratch.versions);
    for (view, &version) in out.views.iter_mut().zip(&scratch.versions) {
        view.version = version;
    }
    let single_pass = culling.single_pass && instances.keys.len() <= MAX_PACKED_INSTANCES;
    let toggled = single_pass != scratch.single_pass;
    scratch.single_pass = single_pass;
    let culled = cull_views(&lights, &instances, &out.views, scratch);
    let entries = &scratch.cache.entries;
    for (view, entry) in out.views.iter_mut().zip(entries) {
        view.footprint = entry.footprint;
        view.version = entry.version;
    }
    // NOTE: with every view reused in the same order, last frame's groups stand as they are.
    if culled || toggled || scratch.cache.reordered || out.groups.len() != entries.len() {
        out.groups.resize_with(entries.len(), DrawGroup::default);
        out.indices.clear();
        out.generation += 1;
        for (entry, group) in entries.iter().zip(out.groups.iter_mut()) {
            let offset = out.indices.len() as u32;
            out.indices.extend_from_slice(&entry.list);
            // NOTE: field by field, so the vectors keep their allocations.
            group.opaque.clone_from(&entry.group.opaque);
            group.masked.clone_from(&entry.group.masked);
            group
                .opaque
                .iter_mut()
                .chain(group.masked.iter_mut())
                .for_each(|b| b.first += offset);
        }
        collect_single_pass(&lights, scratch, out);
    }
    stats.casters_per_view.clear();
    stats.draws_per_view.clear();
    for entry in entries {
        stats.casters_per_view.push(entry.list.len() as u32);
        stats.draws_per_view.push(entry.group.draw_count() as u32);
    }
    stats.culling_cpu = start.elapsed();
}

/// Appends each sun's single-pass list after the view groups (none while they are off).
fn collect_single_pass(lights: &FrameLights, scratch: &ViewScratch, out: &mut ShadowViews) {
    out.single_pass.clear();
    if !scratch.single_pass {
        return;
    }
    let mut first_view = 0;
    for (i, (_, sun)) in scratch.suns.iter().enumerate().take(lights.suns.len()) {
        let views = scratch.receivers.set(i).count as u32;
        let offset = out.indices.len() as u32;
        out.indices.extend_from_slice(&sun.list);
        let mut group = sun.group.clone();
        group
            .opaque
            .iter_mut()
            .chain(group.masked.iter_mut())
            .for_each(|b| b.first += offset);
        out.single_pass.push(SinglePassGroup {
            first_view,
            views,
            group,
        });
        first_view += views;
    }
}

/// Culls the casters of the views whose cache entry asks for it into the entry's list and
/// group (all cascades of a sun together when any of them needs it); returns whether any
/// view was culled.
fn cull_views(
    lights: &FrameLights,
    instances: &RenderInstances,
    views: &[ShadowView],
    scratch: &mut ViewScratch,
) -> bool {
    let entries = &mut scratch.cache.entries;
    let mut culled = false;
    let mut first = 0;
    scratch.suns.resize_with(lights.suns.len(), Default::default);
    for (i, sun) in lights.suns.iter().enumerate() {
        let set = scratch.receivers.set(i);
        let range = first..first + set.count;
        first += set.count;
        // NOTE: a sun's single-pass list is made when its views are culled; one missing (just
        // turned on, or the sun at this index changed) has its views culled again.
        let (owner, list) = &mut scratch.suns[i];
        let stale = scratch.single_pass && *owner != Some(sun.entity);
        if set.count == 0 || !(stale || entries[range.clone()].iter().any(|e| e.cull)) {
            continue;
        }
        debug_assert!(set.count <= MAX_CASCADES);
        culled = true;
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
                let tiles = chunk_footprint(&views[v].clip_from_world, instances, k, members);
                entries[v].footprint = entries[v].footprint.union(tiles);
                bits &= bits - 1;
            }
            for (&instance, &mask) in casters.iter().zip(masks) {
                let mut bits = mask;
                while bits != 0 {
                    let key = instances.keys[instance as usize];
                    let entry = &mut entries[range.start + bits.trailing_zeros() as usize];
                    push_instance(&mut entry.group, &mut entry.list, key, instance);
                    bits &= bits - 1;
                }
            }
        }
        for entry in &mut entries[range.clone()] {
            end_cull(entry);
        }
        if scratch.single_pass {
            list.build(&instances.casters, &scratch.masks, &instances.keys);
            *owner = Some(sun.entity);
        } else {
            *owner = None;
        }
    }
    for (view, entry) in views.iter().zip(entries.iter_mut()).skip(first) {
        let CullVolume::Frustum(frustum) = &view.cull else {
            continue;
        };
        if !entry.cull {
            continue;
        }
        culled = true;
        start_cull(entry);
        cull_spheres_frustum_chunked(
            frustum,
            &instances.caster_centers,
            &instances.caster_radii,
            &instances.caster_chunks,
            &mut scratch.visible,
            &mut scratch.chunk_scratch,
        );
        // NOTE: visible casters come in ascending order, so a chunk's members are a run.
        for run in scratch
            .visible
            .chunk_by(|a, b| *a as usize / CHUNK == *b as usize / CHUNK)
        {
            let chunk = run[0] as usize / CHUNK;
            let members = run.iter().map(|&k| k as usize);
            let tiles = chunk_footprint(&view.clip_from_world, instances, chunk, members);
            entry.footprint = entry.footprint.union(tiles);
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

/// Empties a view's list and group for culling, keeping the last list to compare.
fn start_cull(entry: &mut CachedView) {
    std::mem::swap(&mut entry.list, &mut entry.previous);
    entry.list.clear();
    entry.group.clear();
    entry.footprint = TileMask::EMPTY;
}

/// After culling: a view that may keep its version ([`CachedView::keep`]) keeps it when it
/// found exactly the casters of its last culling (its map would be drawn the same).
fn end_cull(entry: &mut CachedView) {
    if let Some(version) = entry.keep
        && entry.list == entry.previous
    {
        entry.version = version;
    }
}
