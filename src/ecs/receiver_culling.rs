//! Receiver-bounded caster culling for cascades ([`crate::math::receivers`]): each sun's
//! cascade boxes, as culling sees them, shrink to the light-space bounds of the receivers in
//! the camera's frustum and their slice (grown by the filter's reach, and widened to whole
//! cells where the boxes snap to a coarse grid), so casters whose shadow cannot land on
//! anything the camera sees are not drawn. Receivers are taken by culling
//! chunk. The last slice's bounds (it reaches to the shadows' far end and sees most of a
//! large scene) are those of the camera at the centre of a grid cell (a twentieth of the
//! slice's depth length) for the slice grown by a cell: a walking camera computes them again
//! only when it enters another cell, every few dozen frames; the nearer slices' bounds are
//! computed for the camera itself whenever it moves.

use bevy_ecs::resource::Resource;
use glam::{I64Vec3, Mat3, Mat4, Vec3, Vec4};

use crate::ecs::assets::Meshes;
use crate::ecs::instances::RenderInstances;
use crate::ecs::light_views::FrameLights;
use crate::ecs::view::ActiveView;
use crate::math::aabb::Aabb;
use crate::math::cascades::CascadeSet;
use crate::math::cascades::MAX_SUN_VIEWS;
use crate::math::chunk_groups::{frustum_test, visit_groups};
use crate::math::chunks::CHUNK;
use crate::math::frustum::{CameraView, Frustum, slice_corners};
use crate::math::receivers::{Slice, receiver_bounds, shrink_to_receivers, snap_to_grid};
use crate::shader::contract::INSTANCE_FLAG_RECEIVE_SHADOWS;

/// A chunk whose sphere is larger than this fraction of the largest slice's half extent is
/// taken member by member.
const CHUNK_EXPAND_FRACTION: f32 = 0.25;

/// Marks a receiver id as a chunk index (else it is an instance index).
const CHUNK_BIT: usize = 1 << (usize::BITS - 1);

/// How far, in shadow texels, a receiver's filter reads around it
/// ([`cascades::FILTER_REACH_TEXELS`](crate::math::cascades::FILTER_REACH_TEXELS)).
pub const FILTER_REACH_TEXELS: f32 = crate::math::cascades::FILTER_REACH_TEXELS as f32;

/// Switches of shadow-caster culling.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowCulling {
    /// Shrink cascade cull boxes to the visible receivers (default on).
    pub receivers: bool,
    /// Asks for each sun's casters listed once with the cascades they touch
    /// ([`ShadowViews::single_pass`](crate::ecs::view_list::ShadowViews::single_pass)),
    /// for rendering all its cascades in one multiview pass (default off; the render plugin
    /// sets it from [`RenderOptions::single_pass_cascades`](crate::render::RenderOptions)).
    /// Whether a frame does is [`single_pass_cascades`](crate::ecs::single_pass::single_pass_cascades)'s
    /// decision.
    pub single_pass: bool,
    /// Most views the device renders in one multiview pass (the render plugin sets the
    /// renderer's; without one, [`MAX_CASCADES`](crate::settings::MAX_CASCADES)).
    pub multiview_views: u32,
    /// The renderer keeps shadow layers between frames (its shadow cache is on; the render
    /// plugin sets it): a clipmap level's whole caster list is then made only when the
    /// level must be drawn whole.
    pub cached: bool,
    /// The renderer culls the camera view's instances one by one on the GPU (the render
    /// plugin sets it where multi-draw with an indirect first instance is on): a view whose
    /// frustum's chunks hold at least
    /// [`GPU_CAMERA_MIN_INSTANCES`](crate::ecs::camera_runs::GPU_CAMERA_MIN_INSTANCES) is
    /// then culled by chunk only and listed as runs
    /// ([`ViewDrawGroups::runs`](crate::ecs::ViewDrawGroups::runs)).
    pub gpu_camera: bool,
    /// The renderer culls shadow casters one by one on the GPU (set with `gpu_camera`): the
    /// cascades of a sun in a scene of at least
    /// [`GPU_SHADOW_MIN_CASTERS`](crate::ecs::shadow_runs::GPU_SHADOW_MIN_CASTERS) casters are
    /// then culled by chunk only and listed as runs
    /// ([`ShadowViews::runs`](crate::ecs::view_list::ShadowViews::runs)).
    pub gpu_shadows: bool,
}

impl Default for ShadowCulling {
    fn default() -> Self {
        Self {
            receivers: true,
            single_pass: false,
            multiview_views: crate::settings::MAX_CASCADES as u32,
            cached: false,
            gpu_camera: false,
            gpu_shadows: false,
        }
    }
}

/// What a sun's shrunk set was computed from.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Key {
    camera: Option<Mat4>,
    generation: u64,
    cascades: CascadeSet,
    enabled: bool,
    /// The renderer keeps layers (a scrolling cascade's volume then reaches as deep as its
    /// box).
    cached: bool,
}

/// Each sun's cascade set as culling uses it, kept between frames.
#[derive(Debug, Default)]
pub struct ReceiverCache {
    keys: Vec<Key>,
    sets: Vec<CascadeSet>,
    slices: Vec<Slice>,
    bounds: Vec<Aabb>,
    /// Receiver spheres of this frame: chunks, or members of expanded chunks.
    members: Vec<(Vec3, f32, usize)>,
    /// Per sun, its last slice's receiver bounds and what they were computed from.
    held: Vec<Option<(SliceKey, Aabb)>>,
}

/// Share of the last slice's depth length by which its receiver bounds reach past it on every
/// side ([`ReceiverCache`]): the side of the grid cells the camera's position snaps to for
/// them.
pub const HOLD_FRACTION: f32 = 0.05;

/// What a slice's receiver bounds were computed from.
#[derive(Clone, Copy, Debug, PartialEq)]
struct SliceKey {
    /// The camera at the world's origin: its rotation and projection.
    turned: CameraView,
    near: f32,
    far: f32,
    /// The grid cell holding the camera's position (cells of the slice's margin).
    cell: I64Vec3,
    generation: u64,
    light_rotation: Mat3,
}

impl ReceiverCache {
    /// Brings every sun's culling set up to date.
    pub fn update(
        &mut self,
        lights: &FrameLights,
        view: &ActiveView,
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
                cached: culling.cached,
            };
            if self.keys.get(i) == Some(&key) {
                continue;
            }
            let mut set = sun.cascades;
            // NOTE: clipmap levels are not view-depth slices: they keep their whole windows.
            if let (true, Some(camera)) = (culling.receivers && !set.clipmap, camera) {
                let count = set.count.min(MAX_SUN_VIEWS);
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
                self.hold_bounds(i, (&set, camera), instances, meshes);
                for (cascade, bound) in set.cascades.iter_mut().zip(&self.bounds) {
                    let reach = FILTER_REACH_TEXELS * cascade.texel_world_size;
                    let whole = (cascade.light_min, cascade.light_max);
                    let shrunk = shrink_to_receivers(whole.0, whole.1, bound, reach);
                    // NOTE: a box that holds while the camera moves within a cell culls to
                    // whole cells too, so its casters (and its map) hold with it.
                    (cascade.light_min, cascade.light_max) = snap_to_grid(shrunk, cascade.hold_grid, whole);
                    // NOTE: a scrolling cascade's kept texels hold the casters of earlier
                    // volumes: it draws again only where its volume newly reaches across
                    // (`ecs::clipmap_scroll`), so the volume reaches as deep as its box (where
                    // the renderer keeps layers at all).
                    if set.scrolls && culling.cached {
                        cascade.light_min.z = whole.0.z;
                    }
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

    /// Fills `bounds` with the receiver bounds of sun `i`'s slices in `slices`, for `set` seen
    /// by `camera`. The nearer slices' bounds are computed for this camera, together. The
    /// last slice, which reaches to the shadows' far end and sees most of a large scene,
    /// takes the bounds of the camera at the centre of the grid cell holding its position
    /// (cells of [`HOLD_FRACTION`] of the slice's depth length) for the slice grown by a
    /// cell on every side (its depth range, its world box and its frustum): the slice of the
    /// camera anywhere in the cell lies in that grown slice, so its receivers are bounded.
    /// Those are computed again only when the camera enters another cell, turns, or the
    /// instances, the slice's depths or the light change, and equal what a fresh cache
    /// computes at the same pose. (Holding the nearer slices too saves little and moves their
    /// cull boxes at other frames than their own boxes, so their maps are drawn more often.)
    fn hold_bounds(
        &mut self,
        i: usize,
        (set, camera): (&CascadeSet, &CameraView),
        instances: &RenderInstances,
        meshes: &Meshes,
    ) {
        let Some((last, nearer)) = self.slices.split_last() else {
            self.bounds.clear();
            return;
        };
        if self.held.len() <= i {
            self.held.resize(i + 1, None);
        }
        // NOTE: receivers are taken chunk by chunk (64 instances, the culling chunks): a
        // chunk's sphere bounds its members, receivers or not, so the bounds only grow (still
        // correct) and cost a fiftieth of a pass over instances. A chunk much larger than its
        // neighbours (it holds a ground plane) is taken member by member, so the plane's flat
        // box can be clipped to each slice.
        let largest = self
            .slices
            .iter()
            .map(|s| s.world.half_extents().max_element())
            .fold(0.0, f32::max);
        let expand = CHUNK_EXPAND_FRACTION * largest;
        let world_box = |id: usize| {
            if id & CHUNK_BIT != 0 {
                return instances.chunks.boxes[id & !CHUNK_BIT];
            }
            let mesh = meshes.get(instances.keys[id].mesh);
            mesh.map_or(Aabb::EMPTY, |m| {
                m.bounds().transformed(&instances.gpu[id].world_from_local())
            })
        };
        self.bounds.clear();
        self.bounds.resize(nearer.len(), Aabb::EMPTY);
        if let (Some(first), Some(end)) = (nearer.first(), nearer.last()) {
            let frustum = depth_range_frustum(camera, (first.near, end.far), 0.0);
            self.members.clear();
            collect_receivers(&frustum, instances, expand, &mut self.members);
            let receivers = self.members.iter().copied();
            let view_from_world = camera.view_from_world();
            receiver_bounds(
                &set.light_rotation,
                &view_from_world,
                nearer,
                receivers,
                world_box,
                &mut self.bounds,
            );
        }
        let margin = (HOLD_FRACTION * (last.far - last.near)).max(MIN_HOLD_MARGIN);
        let (cell, centre) = grid_cell(camera.position(), margin);
        let mut turned = *camera;
        turned.world_from_view.w_axis = Vec4::W;
        let key = SliceKey {
            turned,
            near: last.near,
            far: last.far,
            cell,
            generation: instances.generation,
            light_rotation: set.light_rotation,
        };
        if let Some((held, bound)) = self.held[i]
            && held == key
        {
            self.bounds.push(bound);
            return;
        }
        let mut at = *camera;
        at.world_from_view.w_axis = centre.extend(1.0);
        let world = Aabb::from_points(&slice_corners(&at, last.near, last.far));
        let grown = Slice {
            near: last.near - margin,
            far: last.far + margin,
            world: Aabb {
                min: world.min - margin,
                max: world.max + margin,
            },
        };
        let frustum = depth_range_frustum(&at, (last.near, last.far), margin);
        self.members.clear();
        collect_receivers(&frustum, instances, expand, &mut self.members);
        let mut bound = [Aabb::EMPTY];
        let receivers = self.members.iter().copied();
        receiver_bounds(
            &set.light_rotation,
            &at.view_from_world(),
            &[grown],
            receivers,
            world_box,
            &mut bound,
        );
        self.held[i] = Some((key, bound[0]));
        self.bounds.push(bound[0]);
    }

    /// Sun `i`'s cascade set as culling uses it (after [`update`](Self::update)).
    pub fn set(&self, i: usize) -> &CascadeSet {
        &self.sets[i]
    }
}

/// Lists in `members` (emptied by the caller) the receivers `frustum` sees, chunk by chunk
/// (groups of chunks wholly inside taken without a test per chunk): a chunk's sphere, or for
/// a chunk wider than `expand` that one member dominates (a ground plane among small
/// casters), its receiving members in view.
fn collect_receivers(
    frustum: &Frustum,
    instances: &RenderInstances,
    expand: f32,
    members: &mut Vec<(Vec3, f32, usize)>,
) {
    let chunks = &instances.chunks;
    let test = |center, radius| frustum_test(frustum, None, center, radius);
    visit_groups(&chunks.groups, chunks.len(), test, |first, end, whole| {
        for k in first..end {
            let (center, radius) = (chunks.centers[k], chunks.radii[k]);
            if whole.is_none() && !frustum.intersects_sphere(center, radius) {
                continue;
            }
            let range = k * CHUNK..((k + 1) * CHUNK).min(instances.centers.len());
            // NOTE: a large chunk is split only when one member dominates it (a ground plane
            // among small casters); a chunk of small casters spread wide is taken whole.
            let dominated = || chunks.max_radii.get(k).is_none_or(|&r| r > 0.5 * radius);
            if radius.is_finite() && (radius <= expand || !dominated()) {
                members.push((center, radius, CHUNK_BIT | k));
                continue;
            }
            for i in range {
                let receives = instances.gpu[i].flags & INSTANCE_FLAG_RECEIVE_SHADOWS != 0;
                let (c, r) = (instances.centers[i], instances.radii[i]);
                if receives && frustum.intersects_sphere(c, r) {
                    members.push((c, r, i));
                }
            }
        }
    });
}

/// Smallest margin of a slice's held receiver bounds, metres (a slice of no depth).
const MIN_HOLD_MARGIN: f32 = 1e-3;

/// The frustum of `camera` between view depths `near` and `far` (a slice of no depth still
/// makes one), every plane moved `margin` outwards.
fn depth_range_frustum(camera: &CameraView, (near, far): (f32, f32), margin: f32) -> Frustum {
    let range = CameraView {
        near,
        far: far.max(near + MIN_HOLD_MARGIN),
        ..*camera
    };
    Frustum::from_clip_from_world(range.clip_from_world()).dilated(margin)
}

/// The cell of a grid of `side`-wide cells (from the world's origin) holding `p`, and its
/// centre, computed in f64 so a camera far from the origin keeps its cell.
fn grid_cell(p: Vec3, side: f32) -> (I64Vec3, Vec3) {
    let side = f64::from(side);
    let cell = (p.as_dvec3() / side).floor();
    ((cell.as_i64vec3()), ((cell + 0.5) * side).as_vec3())
}
