//! What several render tests share: a scene file spawned into a headless app whose frames are
//! identical (the filter taps are not rotated per frame).

use bevy_app::App;
use penumbra::app::{headless_app, spawn_scene};
use penumbra::render::Renderer;
use penumbra::scene::SceneDesc;
use penumbra::settings::ShadowSettings;

/// `scene` spawned into a headless app rendering with `renderer`, with temporal rotation off
/// for every light; no frame rendered yet.
pub fn still_scene(renderer: Renderer, scene: &str) -> App {
    let mut app = headless_app(renderer);
    let desc = SceneDesc::load(scene).expect("scene loads");
    spawn_scene(app.world_mut(), &desc).expect("scene spawns");
    let world = app.world_mut();
    let mut settings = world.query::<&mut ShadowSettings>();
    for mut s in settings.iter_mut(world) {
        s.temporal_rotation = false;
    }
    app
}
