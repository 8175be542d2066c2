//! Which shadow views must be drawn again. A view keeps a content `version`; it gets a new
//! one when its matrix, resolution or what its light's map is drawn from
//! ([`ShadowSettings::map_key`](crate::settings::ShadowSettings::map_key): not the filter) change, or when a caster changed inside
//! its cull volume ([`CasterChanges`]). The renderer skips a view whose layer already holds
//! that version. A view whose matrix is unchanged and whose instance list was not rebuilt is
//! not even culled again: its draw group from the last frame is reused.

use bevy_ecs::entity::Entity;
use glam::Mat4;

use crate::ecs::caster_changes::CasterChanges;
use crate::ecs::draw_groups::{DrawGroup, ShadowRun};
use crate::ecs::view_list::{CullVolume, ShadowViewKind};
use crate::math::aabb::Aabb;
use crate::math::footprint::TileMask;
use crate::settings::MapKey;

/// What one view held when it was last culled.
#[derive(Debug)]
pub struct CachedView {
    /// The light's entity.
    pub entity: Entity,
    /// Cascade index or spot.
    pub kind: ShadowViewKind,
    clip_from_world: Mat4,
    /// What its casters were culled against (a cascade's box follows its receivers).
    volume: CullVolume,
    resolution: u32,
    key: MapKey,
    /// The instance generation `list` indexes.
    generation: u64,
    /// Content version (unique across views).
    pub version: u64,
    /// Culled instance indices, in draw order.
    pub list: Vec<u32>,
    /// The list of the last culling, while a new one is made (see `keep`).
    pub previous: Vec<u32>,
    /// The version to go back to if this frame's culling finds exactly the last casters:
    /// set when only the cull volume changed (a cascade's box following the receivers as
    /// the camera moves) and no caster in it changed, so the same list draws the same map.
    pub keep: Option<u64>,
    /// The view culled by chunk for the GPU ([`crate::ecs::shadow_runs`]): its runs of
    /// casters, `list` then empty and `group`'s batches room in the list the GPU writes.
    pub runs: Vec<ShadowRun>,
    /// The runs of the last culling, while new ones are made (see `keep`).
    pub previous_runs: Vec<ShadowRun>,
    /// A run of this culling (`.0`) or of the last one (`.1`) came from a chunk that only
    /// straddles the view's volume: the GPU's lists may differ although the runs are equal.
    pub partial: (bool, bool),
    /// Batches over `list` (starting at 0).
    pub group: DrawGroup,
    /// The tiles of its map its casters can write.
    pub footprint: TileMask,
    /// Must be culled this frame.
    pub cull: bool,
    /// A scrolling view that keeps its version although a caster changed inside it: the
    /// changed regions are drawn again ([`crate::ecs::clipmap_scroll`]).
    pub touched: bool,
}

/// The views of the last frame, in order, and the version counter.
#[derive(Debug, Default)]
pub struct ViewCache {
    /// One entry per view of the last frame (then of this frame, after [`ViewCache::plan`]).
    pub entries: Vec<CachedView>,
    /// Last frame's entries while this frame's are matched to them (taken ones are None).
    spare: Vec<Option<CachedView>>,
    next_version: u64,
    /// The entries' identities changed order or count this frame.
    pub reordered: bool,
}

/// What [`ViewCache::plan`] needs to know of one view of this frame.
#[derive(Clone, Copy, Debug)]
pub struct ViewInput<'a> {
    /// The light's entity.
    pub entity: Entity,
    /// Cascade index or spot.
    pub kind: ShadowViewKind,
    /// Light clip space from world.
    pub clip_from_world: Mat4,
    /// Side of its map.
    pub resolution: u32,
    /// What the light's maps are drawn from.
    pub key: MapKey,
    /// Its cull volume.
    pub cull: &'a CullVolume,
    /// A scrolling view (a clipmap level): its `clip_from_world` does not depend on where its
    /// window is, and a caster change inside it is drawn by region where the change is
    /// known, so neither gives it a new version.
    pub scrolls: bool,
    /// A scrolling view whose layer the renderer keeps (its cache is on and it did not ask
    /// for the view again): its casters are culled again only when its version changes or
    /// the instances are rebuilt, not every time its window moves (the strips it draws are
    /// culled on their own).
    pub lazy: bool,
}

/// Whether a change in `region` can alter what `volume` renders. Conservative: a cascade is
/// touched by a region whose light-space footprint overlaps the box's (anything between the
/// light and the box casts into it), a spot light by a region touching its frustum.
pub fn touches(volume: &CullVolume, region: &Aabb) -> bool {
    if region.is_empty() {
        return false;
    }
    match volume {
        CullVolume::LightBox {
            light_rotation,
            min,
            max,
        } => {
            let light = region
                .corners()
                .iter()
                .fold(Aabb::EMPTY, |b, &c| b.with_point(*light_rotation * c));
            let overlap = |a0: f32, a1: f32, b0: f32, b1: f32| a0 <= b1 && b0 <= a1;
            overlap(light.min.x, light.max.x, min.x, max.x) && overlap(light.min.y, light.max.y, min.y, max.y)
        }
        CullVolume::Frustum(frustum) | CullVolume::CubeFace { frustum, .. } => frustum.intersects_aabb(region),
    }
}

impl ViewCache {
    /// Matches this frame's views to last frame's by light and kind, decides which must be
    /// culled (new, moved, resized, re-set, or the instance list was rebuilt) and which get a
    /// new content version (all of those except views a rebuild did not touch), and returns
    /// each view's version in order.
    pub fn plan<'a>(
        &mut self,
        views: impl Iterator<Item = ViewInput<'a>>,
        generation: u64,
        changes: &CasterChanges,
        versions: &mut Vec<u64>,
    ) {
        // NOTE: moved, not swapped, so both vectors keep the capacity they grew to.
        self.spare.extend(self.entries.drain(..).map(Some));
        versions.clear();
        let mut reordered = false;
        // NOTE: views come in last frame's order when nothing was added or removed, so the
        // first entry not yet taken is tried first: matching is linear, not quadratic, in the
        // number of views (a point light has six).
        let mut next = 0;
        for view in views {
            while self.spare.get(next).is_some_and(Option::is_none) {
                next += 1;
            }
            let matches = |e: &Option<CachedView>| {
                e.as_ref()
                    .is_some_and(|e| e.entity == view.entity && e.kind == view.kind)
            };
            let found = if self.spare.get(next).is_some_and(matches) {
                Some(next)
            } else {
                self.spare.iter().position(matches)
            };
            reordered |= found != Some(next);
            let mut entry = match found.and_then(|k| self.spare[k].take()) {
                Some(entry) => entry,
                None => CachedView {
                    entity: view.entity,
                    kind: view.kind,
                    clip_from_world: Mat4::NAN,
                    volume: *view.cull,
                    resolution: 0,
                    key: view.key,
                    generation: u64::MAX,
                    version: 0,
                    list: Vec::new(),
                    previous: Vec::new(),
                    keep: None,
                    runs: Vec::new(),
                    previous_runs: Vec::new(),
                    partial: (false, false),
                    group: DrawGroup::default(),
                    footprint: TileMask::EMPTY,
                    cull: true,
                    touched: false,
                },
            };
            let drawn_alike = entry.clip_from_world == view.clip_from_world
                && entry.resolution == view.resolution
                && entry.key == view.key;
            let same = drawn_alike && entry.volume == *view.cull;
            let rebuilt = entry.generation != generation;
            // NOTE: the changes describe only the rebuild to `generation`; a view last culled
            // before an earlier rebuild cannot tell what happened in between.
            let known = changes.generation == generation && entry.generation.wrapping_add(1) == generation;
            let touched =
                rebuilt && (!known || changes.everything || changes.regions.iter().any(|r| touches(view.cull, r)));
            entry.cull = if view.lazy {
                !drawn_alike || rebuilt
            } else {
                !same || rebuilt
            };
            // NOTE: a scrolling view's content follows its grid, not its window; changes
            // drawn by region keep it too.
            let by_region = view.scrolls && known && !changes.everything;
            entry.touched = touched && by_region;
            let renew = if view.scrolls {
                !drawn_alike || (touched && !by_region)
            } else {
                !same || touched
            };
            entry.keep = (!view.scrolls && drawn_alike && !touched && entry.version != 0).then_some(entry.version);
            if renew {
                self.next_version += 1;
                entry.version = self.next_version;
            }
            entry.clip_from_world = view.clip_from_world;
            // NOTE: the volume is what the list was culled against: a lazy view that is not
            // culled keeps the old one, so it is culled when it stops being lazy.
            if entry.cull {
                entry.volume = *view.cull;
            }
            entry.resolution = view.resolution;
            entry.key = view.key;
            entry.generation = generation;
            versions.push(entry.version);
            self.entries.push(entry);
        }
        reordered |= self.spare.iter().any(Option::is_some);
        self.spare.clear();
        // NOTE: grown now, so the next frame's move allocates nothing.
        self.spare.reserve(self.entries.len());
        self.reordered = reordered;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::{PcssQuality, ShadowMode, ShadowSettings};
    use glam::{Mat3, Vec3};

    fn unit_box() -> Aabb {
        Aabb {
            min: Vec3::ZERO,
            max: Vec3::ONE,
        }
    }

    fn cascade_box(x0: f32, x1: f32) -> CullVolume {
        CullVolume::LightBox {
            light_rotation: Mat3::IDENTITY,
            min: Vec3::new(x0, 0.0, -10.0),
            max: Vec3::new(x1, 10.0, 10.0),
        }
    }

    #[test]
    fn a_cascade_is_touched_by_regions_over_its_footprint_only() {
        let b = unit_box();
        assert!(touches(&cascade_box(0.5, 4.0), &b));
        assert!(!touches(&cascade_box(2.0, 4.0), &b));
        // Depth along the light does not matter: a caster far towards the light still casts.
        let far = Aabb {
            min: Vec3::new(1.0, 1.0, 50.0),
            max: Vec3::new(2.0, 2.0, 51.0),
        };
        assert!(touches(&cascade_box(0.5, 4.0), &far));
        assert!(!touches(&cascade_box(0.5, 4.0), &Aabb::EMPTY));
    }

    fn input<'a>(e: u32, m: Mat4, settings: &'a ShadowSettings, cull: &'a CullVolume) -> ViewInput<'a> {
        ViewInput {
            entity: Entity::from_raw_u32(e).unwrap(),
            kind: ShadowViewKind::cascade(0),
            clip_from_world: m,
            resolution: 1024,
            key: settings.map_key(),
            cull,
            scrolls: false,
            lazy: false,
        }
    }

    #[test]
    fn versions_change_only_with_what_changes_a_map() {
        let settings = ShadowSettings::default();
        let (near, far) = (cascade_box(0.0, 4.0), cascade_box(100.0, 104.0));
        let mut cache = ViewCache::default();
        let mut changes = CasterChanges::default();
        let mut v = Vec::new();
        let m = Mat4::IDENTITY;
        let frame = |cache: &mut ViewCache, changes: &CasterChanges, g, m2: Mat4, v: &mut Vec<u64>| {
            cache.plan(
                [input(1, m, &settings, &near), input(2, m2, &settings, &far)].into_iter(),
                g,
                changes,
                v,
            );
        };
        changes.generation = 1;
        changes.everything = true;
        frame(&mut cache, &changes, 1, m, &mut v);
        let first = v.clone();
        assert!(cache.entries.iter().all(|e| e.cull));
        // Still frame: same versions, nothing culled.
        frame(&mut cache, &changes, 1, m, &mut v);
        assert_eq!(v, first);
        assert!(cache.entries.iter().all(|e| !e.cull) && !cache.reordered);
        // A caster moves inside the first view: both are culled again (indices changed), only
        // the first gets a new version.
        changes.generation = 2;
        changes.everything = false;
        changes.regions = vec![unit_box()];
        frame(&mut cache, &changes, 2, m, &mut v);
        assert!(cache.entries.iter().all(|e| e.cull));
        assert_ne!(v[0], first[0]);
        assert_eq!(v[1], first[1]);
        // The second view's matrix changes: only it gets a new version.
        let before = v.clone();
        frame(&mut cache, &changes, 2, Mat4::from_translation(Vec3::X), &mut v);
        assert_eq!(v[0], before[0]);
        assert_ne!(v[1], before[1]);
        // Its settings change.
        let before = v.clone();
        let other = {
            let mut s = settings;
            s.bias.slope_bias = 3.0;
            s
        };
        cache.plan(
            [
                input(1, m, &other, &near),
                input(2, Mat4::from_translation(Vec3::X), &settings, &far),
            ]
            .into_iter(),
            2,
            &changes,
            &mut v,
        );
        assert_ne!(v[0], before[0]);
        assert_eq!(v[1], before[1]);
        // Only how it is sampled changes (the filter, the normal offset): no new version.
        let before = v.clone();
        let sampled = {
            let mut s = other;
            s.filter.mode = ShadowMode::Pcss;
            s.filter.pcf_radius = 4;
            s.filter.pcss_quality = PcssQuality::High;
            s.filter.moments.blur = 0.2;
            s.bias.normal_offset = 2.5;
            s
        };
        cache.plan(
            [
                input(1, m, &sampled, &near),
                input(2, Mat4::from_translation(Vec3::X), &settings, &far),
            ]
            .into_iter(),
            2,
            &changes,
            &mut v,
        );
        assert_eq!(v, before);
        assert!(cache.entries.iter().all(|e| !e.cull));
    }
}
