//! Shadow views: every view a shadow map is rendered from this frame — each cascade of each
//! shadowed sun, each shadowed spot light, each cube face of each shadowed point light — in
//! one list ([`ShadowViews`]), with the casters of
//! each culled into its own draw group. Nothing here has a fixed count: the lists grow with
//! the lights, keep their capacity between frames, and allocate nothing once the scene has
//! been seen.
//!
//! Each view has a `slot` in the storage of its kind (a layer of the cascades' depth array,
//! a layer of the spot lights' array, a face of the point lights' cube array); the renderer
//! allocates storage from these slots.

use std::time::Instant;

use bevy_ecs::entity::Entity;
use bevy_ecs::resource::Resource;
use bevy_ecs::system::{Local, Res, ResMut};
use glam::{Mat3, Mat4, Vec3};

use crate::ecs::assets::Meshes;
use crate::ecs::caster_changes::CasterChanges;
use crate::ecs::draw_groups::DrawGroup;
use crate::ecs::frame_lights::FrameLights;
use crate::ecs::instances::RenderInstances;
use crate::ecs::receiver_culling::ShadowCulling;
use crate::ecs::shadow_lods::ShadowLods;
use crate::ecs::single_pass::{MAX_PACKED_INSTANCES, SinglePassGroup};
use crate::ecs::stats::ShadowStats;
use crate::ecs::view::ActiveView;
use crate::ecs::view_cache::ViewInput;
use crate::ecs::view_culling::{ViewScratch, collect_single_pass, cull_views};
use crate::math::footprint::TileMask;
use crate::math::frustum::Frustum;
use crate::math::light_budget::{LightKind, ShadowBudget};
use crate::math::point::FACES;

/// How many lights of each kind may cast shadows, and the shadow-map size of a spot or point
/// light without its own [`ShadowSettings`](crate::settings::ShadowSettings).
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowLightBudget {
    /// Most shadowed lights per kind (4 suns; the seed's layout: 8 spot lights, 4 point
    /// lights).
    pub lights: ShadowBudget,
    /// Side of a spot light's shadow map, texels.
    pub spot_resolution: u32,
    /// Side of each cube face of a point light's shadow, texels.
    pub point_resolution: u32,
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
            point_resolution: 512,
        }
    }
}

/// Near plane of a spot light's shadow view, metres: casters closer to the light are clamped
/// to it (depth clamping) or clipped.
pub const SPOT_NEAR: f32 = 0.05;

/// Near plane of a point light's cube faces, metres (along each face's axis).
pub const POINT_NEAR: f32 = 0.05;

/// The storage a shadow view renders into: one depth array per kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShadowStorage {
    /// The cascades of every shadowed sun, a layer each.
    Cascades,
    /// Every shadowed spot light, a layer each.
    Spots,
    /// Every shadowed point light, six layers (a cube) each.
    Points,
}

impl ShadowStorage {
    /// Every storage, in the order of the renderer's arrays.
    pub const ALL: [ShadowStorage; 3] = [ShadowStorage::Cascades, ShadowStorage::Spots, ShadowStorage::Points];
}

/// What a shadow view renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowViewKind {
    /// Cascade `i` of a directional light (into the cascades' depth array).
    Cascade(u32),
    /// A spot light's perspective view (into the spot lights' depth array).
    Spot,
    /// Face `f` (cube-map layer order: +X, −X, +Y, −Y, +Z, −Z) of a point light's cube (into
    /// the point lights' depth array).
    PointFace(u32),
}

impl ShadowViewKind {
    /// The storage a view of this kind renders into.
    pub fn storage(self) -> ShadowStorage {
        match self {
            ShadowViewKind::Cascade(_) => ShadowStorage::Cascades,
            ShadowViewKind::Spot => ShadowStorage::Spots,
            ShadowViewKind::PointFace(_) => ShadowStorage::Points,
        }
    }
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
/// spot lights, then point lights (six faces each), in the order of [`FrameLights`].
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
    /// What `storage` must hold this frame: the side of its largest view and the number of
    /// layers (0, 0 without views).
    pub fn extent(&self, storage: ShadowStorage) -> (u32, u32) {
        self.views
            .iter()
            .filter(|v| v.kind.storage() == storage)
            .fold((0, 0), |(side, layers), v| {
                (side.max(v.resolution), layers.max(v.slot + 1))
            })
    }
}

/// Lists the shadow views of the shadowed lights, gives each its content version
/// ([`ViewCache`](crate::ecs::view_cache::ViewCache)), and culls every caster into the draw group of each view it touches — only
/// for views that moved or whose instance list was rebuilt; the others keep last frame's
/// group. A sun's cascades are culled in one pass over the casters (sorted by draw key, so
/// each list comes out in draw order), a spot light or a point light's face against its
/// frustum.
#[allow(clippy::too_many_arguments)]
pub fn update_shadow_views(
    lights: Res<FrameLights>,
    instances: Res<RenderInstances>,
    changes: Res<CasterChanges>,
    view: Res<ActiveView>,
    meshes: Res<Meshes>,
    culling: Option<Res<ShadowCulling>>,
    lods: Option<Res<ShadowLods>>,
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
    let mut point_slot = 0;
    for (i, point) in lights.points.iter().enumerate() {
        let Some(shadow) = &point.shadow else { continue };
        for face in 0..FACES {
            out.views.push(ShadowView {
                entity: point.entity,
                light_kind: LightKind::Point,
                light: lights.light_index(LightKind::Point, i) as u32,
                kind: ShadowViewKind::PointFace(face as u32),
                clip_from_world: shadow.faces[face],
                cull: CullVolume::Frustum(shadow.frusta[face]),
                slot: point_slot,
                resolution: point.settings.resolution,
                footprint: TileMask::EMPTY,
                version: 0,
            });
            scratch.settings.push(point.settings);
            point_slot += 1;
        }
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
    let no_lods = ShadowLods::default();
    let lods = lods.as_deref().unwrap_or(&no_lods);
    let culled = cull_views(&lights, &instances, lods, &out.views, scratch);
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
            group.append_copy(&entry.group, &entry.list, &mut out.indices);
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
