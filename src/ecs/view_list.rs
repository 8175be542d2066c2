//! The frame's shadow views as data: every view a shadow map is rendered from ([`ShadowView`],
//! listed in [`ShadowViews`] with their draw groups), what each renders ([`ShadowViewKind`])
//! and what its casters are culled against ([`CullVolume`]); and how many lights may cast
//! ([`ShadowLightBudget`]). [`update_shadow_views`](crate::ecs::shadow_views::update_shadow_views)
//! fills them each frame.

use bevy_ecs::entity::Entity;
use bevy_ecs::resource::Resource;
use glam::{I64Vec2, Mat3, Mat4, Vec3, Vec4};

use crate::ecs::draw_groups::{DrawGroup, ShadowRun};
use crate::ecs::single_pass::SinglePassGroup;
pub use crate::layout::ShadowStorage;
use crate::math::footprint::{TexelRect, TileMask};
use crate::math::frustum::Frustum;
use crate::math::light_budget::{LightKind, ShadowBudget};

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

/// What a shadow view renders: view `index` of its light in `storage` (a cascade's number;
/// a cube face, in layer order +X, −X, +Y, −Y, +Z, −Z; 0 for a spot light's one view).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ShadowViewKind {
    /// The storage it renders into.
    pub storage: ShadowStorage,
    /// Its place among its light's views in that storage.
    pub index: u32,
}

impl ShadowViewKind {
    /// Cascade `c` of a directional light.
    pub const fn cascade(c: u32) -> Self {
        Self {
            storage: ShadowStorage::Cascades,
            index: c,
        }
    }

    /// A spot light's perspective view.
    pub const SPOT: Self = Self {
        storage: ShadowStorage::Spots,
        index: 0,
    };

    /// Face `f` of a point light's cube.
    pub const fn point_face(f: u32) -> Self {
        Self {
            storage: ShadowStorage::Points,
            index: f,
        }
    }

    /// Its bit in a single-pass caster entry's view mask (0 for a storage not drawn in one
    /// pass per light).
    pub fn single_pass_bit(self) -> u32 {
        if self.storage.desc().single_pass {
            1 << self.index
        } else {
            0
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
    /// A cube face: the casters within `radius` of `center` (found once for the faces of
    /// one light), then those of them in the face's frustum.
    CubeFace {
        /// The face's frustum.
        frustum: Frustum,
        /// The light's position, world space relative to the render origin.
        center: Vec3,
        /// The light's reach, metres.
        radius: f32,
    },
}

/// What a view's layout says about it to the shaders and the inspector, in the layout's own
/// terms: the renderer copies it as it is.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewShading {
    /// Depth range along the light, metres (a cascade's near and far view depths; a spot
    /// light's near and far planes; a point light's near plane and reach).
    pub near: f32,
    /// See `near`.
    pub far: f32,
    /// World size of one texel, metres, where it is the same across the view (an
    /// orthographic view); 0 where it grows with distance.
    pub texel_world_size: f32,
    /// The words the layout's WGSL module reads as `ShadowViewGpu::params`.
    pub params: Vec4,
    /// The words it reads as `ShadowViewGpu::range`.
    pub range: Vec4,
    /// A paged level's place in its page table (None for a view with its own layer).
    pub page: Option<ViewPaging>,
}

/// Where a paged level's window lies on its page grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ViewPaging {
    /// Grid page of the window's first page.
    pub first_page: I64Vec2,
    /// Texels per side of a page.
    pub page_size: u32,
}

/// One view a shadow map is rendered from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowView {
    /// The light's entity.
    pub entity: Entity,
    /// The light's kind.
    pub light_kind: LightKind,
    /// The light's index in the renderer's light list ([`FrameLights::light_index`](crate::ecs::light_views::FrameLights::light_index)).
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
    /// What its layout tells the shaders about it.
    pub shading: ViewShading,
    /// The tiles of its map its casters can write ([`crate::ecs::footprints`]): what a
    /// redraw of the layer must clear first.
    pub footprint: TileMask,
    /// Content version: the same while nothing that changes this map changed (its matrix,
    /// resolution, light settings, or a caster in its cull volume); unique across views, so
    /// the renderer redraws a layer only when the version it holds differs.
    pub version: u64,
    /// How a scrolling view's layer moves this frame (a clipmap level's; None for the
    /// others). Its version then stays while the window moves: a layer that holds it and
    /// last frame's window is moved by whole texels and only the regions listed are drawn.
    pub scroll: Option<Scroll>,
}

/// How a clipmap level's layer moves this frame: its content is moved from the window it was
/// drawn for last frame (`from`, the grid texel of the window's first texel) to this frame's
/// (`to`), then the regions [`ShadowViews::regions`]`[first_region..][..region_count]` are
/// drawn: the strips the window newly covers and where casters changed. A layer that wraps
/// (`origin`) is not moved: its texels stay where they are and the regions are drawn where
/// the window's texels lie in it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Scroll {
    /// Last frame's window.
    pub from: I64Vec2,
    /// This frame's window.
    pub to: I64Vec2,
    /// First region in [`ShadowViews::regions`].
    pub first_region: u32,
    /// Number of regions.
    pub region_count: u32,
    /// The view's draw group was culled this frame (for this window); otherwise it holds
    /// the casters of an earlier window, and a renderer that must draw the view whole asks
    /// for it again ([`ScrollResync`](crate::ecs::clipmap_scroll::ScrollResync)).
    pub fresh: bool,
    /// Where the layer holds the window's first texel, when it wraps: each grid texel stays at
    /// the layer texel it was drawn at when the level was last drawn whole, modulo the
    /// layer's side (columns left to right, rows top to bottom); `[0, 0]` after a whole draw.
    /// None where the layer is moved instead (a sun filtering moments, which are blurred up
    /// to the layer's edges). A renderer wraps only a view that fills its layer.
    pub origin: Option<[u32; 2]>,
}

/// Part of a scrolling view's layer to draw again, with the casters that reach it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Region {
    /// The layer's texels, `[x0, x1) × [y0, y1)`.
    pub rect: TexelRect,
    /// The casters overlapping it (indexing [`ShadowViews::indices`]).
    pub group: DrawGroup,
}

/// This frame's shadow views and their culled casters: `groups[i]` holds the draws of
/// `views[i]`, indexing `indices`. Views are listed suns first (cascade by cascade), then
/// spot lights, then point lights (six faces each), in the order of [`FrameLights`](crate::ecs::light_views::FrameLights).
#[derive(Resource, Debug, Default)]
pub struct ShadowViews {
    /// Every view rendered this frame.
    pub views: Vec<ShadowView>,
    /// The casters of each view, as instanced draws.
    pub groups: Vec<DrawGroup>,
    /// Each sun's casters listed once for a single-pass draw of its cascades, while
    /// [`ShadowCulling::single_pass`](crate::ecs::receiver_culling::ShadowCulling::single_pass) is on (else empty); their packed entries follow the
    /// groups' in `indices`.
    pub single_pass: Vec<SinglePassGroup>,
    /// Instance indices of every group, concatenated.
    pub indices: Vec<u32>,
    /// The runs of casters of the views culled by chunk for the GPU
    /// ([`crate::ecs::shadow_runs`]), view after view, each naming its view.
    pub runs: Vec<ShadowRun>,
    /// Per view (parallel to `groups`): its runs, `runs[first..first + count]` as `(first,
    /// count)`. A view with runs lists nothing in `indices`: its group's batches are room in
    /// a list only the GPU writes (starting at 0 for each view); one without was culled by the
    /// CPU.
    pub run_ranges: Vec<(u32, u32)>,
    /// Bumped whenever `groups` and `indices` are rebuilt (the renderer uploads them then).
    pub generation: u64,
    /// The regions scrolling views draw this frame ([`Scroll`]); their entries follow the
    /// others in `indices`.
    pub regions: Vec<Region>,
}

impl ShadowViews {
    /// What `storage` must hold this frame: the side of its largest view and the number of
    /// layers (0, 0 without views).
    pub fn extent(&self, storage: ShadowStorage) -> (u32, u32) {
        self.views
            .iter()
            .filter(|v| v.kind.storage == storage)
            .fold((0, 0), |(side, layers), v| {
                (side.max(v.resolution), layers.max(v.slot + 1))
            })
    }
}
