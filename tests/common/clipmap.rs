//! The long field with its sun on a clipmap, and the camera walks the clipmap tests take.

use bevy_app::App;
use glam::Vec3;
use penumbra::settings::ShadowMode;

/// The long field with its sun on a 6-level clipmap of `resolution`² levels (the cache on
/// or off), rendered once.
pub fn long_field_with(resolution: u32, cache: bool) -> App {
    long_field_filtered(resolution, cache, ShadowMode::Pcf)
}

/// [`long_field_with`], its sun filtered with `mode` (moments without contact hardening).
pub fn long_field_filtered(resolution: u32, cache: bool, mode: ShadowMode) -> App {
    let mut app = long_field_unrendered(resolution, cache, mode);
    app.update();
    app
}

/// [`long_field_filtered`] before its first frame, its suns' layers in 32-bit floats.
pub fn long_field_unrendered(resolution: u32, cache: bool, mode: ShadowMode) -> App {
    use penumbra::settings::{ShadowSettings, SunLayout};
    let mut app = super::cached_scene("assets/bench/long_field.ron", cache);
    let world = app.world_mut();
    // NOTE: 32-bit float depth, so that layers kept from an earlier window compare with
    // fresh ones to a few ulps; in 16 bits a depth that close to a step's midpoint may round
    // either way (`tests/sun_depth.rs` checks the 16-bit layers against these).
    world.resource_mut::<penumbra::render::RenderOptions>().sun_depth = penumbra::render::SunDepth::Float32;
    let mut settings = world.query::<&mut ShadowSettings>();
    for mut s in settings.iter_mut(world) {
        s.map.resolution = resolution;
        s.filter.mode = mode;
        // NOTE: every pixel then reads the moments (no depth comparison at casters' feet).
        s.filter.moments.contact_hardening = false;
        s.map.layout = SunLayout::Clipmap {
            levels: 6,
            level0_extent: 32.0,
        };
    }
    app
}

pub fn long_field() -> App {
    long_field_with(2048, true)
}

pub fn drawn(app: &App) -> u32 {
    app.world()
        .resource::<penumbra::render::Renderer>()
        .last_report
        .shadow_views_drawn
}

pub fn matrices(app: &App) -> Vec<glam::Mat4> {
    let views = app.world().resource::<penumbra::ecs::ShadowViews>();
    views.views.iter().map(|v| v.clip_from_world).collect()
}

/// Moves the camera of `app` by `step` and turns it by `yaw`.
pub fn walk(app: &mut App, step: Vec3, yaw: f32) {
    use penumbra::ecs::{Camera3d, Transform};
    let world = app.world_mut();
    let mut cameras = world.query_filtered::<&mut Transform, bevy_ecs::query::With<Camera3d>>();
    for mut t in cameras.iter_mut(world) {
        t.translation += step;
        t.rotate_y(yaw);
    }
}

/// The texels of `view`'s layer in its window's order: where the layer wraps, turned back
/// round from where it holds the window's first texel.
pub fn window_texels(app: &App, view: &penumbra::ecs::view_list::ShadowView) -> Vec<f32> {
    use penumbra::layout::ShadowStorage;
    use penumbra::render::Renderer;
    use penumbra::render::shadows::gpu::wrap_origin;
    let renderer = app.world().resource::<Renderer>();
    let layer = renderer
        .read_shadow_map(ShadowStorage::Cascades, view.slot)
        .expect("a level");
    let side = (layer.len() as f64).sqrt() as usize;
    match wrap_origin(view, side as u32) {
        None => layer,
        Some([ox, oy]) => {
            let (ox, oy) = (ox as usize, oy as usize);
            (0..side * side)
                .map(|i| layer[((i / side + oy) % side) * side + (i % side + ox) % side])
                .collect()
        }
    }
}

/// The layers of `app`'s levels of `sun` (every sun's where None), in level order, in their
/// windows' order ([`window_texels`]).
pub fn sun_levels(app: &App, sun: Option<bevy_ecs::entity::Entity>) -> Vec<Vec<f32>> {
    let views = app.world().resource::<penumbra::ecs::ShadowViews>();
    let mut levels: Vec<_> = views
        .views
        .iter()
        .filter(|v| v.scroll.is_some() && sun.is_none_or(|s| v.entity == s))
        .collect();
    levels.sort_by_key(|v| (v.slot, v.kind.index));
    levels.iter().map(|v| window_texels(app, v)).collect()
}

/// The layers of `app`'s first sun's levels, in level order, in their windows' order.
pub fn first_sun_levels(app: &App, sun: bevy_ecs::entity::Entity) -> Vec<Vec<f32>> {
    sun_levels(app, Some(sun))
}
