mod common;
use bevy_app::App;
use glam::Vec3;
use penumbra::app::spawn_scene;
use penumbra::ecs::ShadowPlugin;
use penumbra::ecs::components::ViewportSize;
use penumbra::ecs::light_views::FrameLights;
use penumbra::scene::SceneDesc;

#[test]
fn scratch_walk() {
    let scene = std::env::var("SCENE").unwrap_or("assets/scenes/pillars.ron".into());
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    app.insert_resource(ViewportSize {
        width: 1920,
        height: 1080,
    });
    let desc = SceneDesc::load(&scene).unwrap();
    spawn_scene(app.world_mut(), &desc).unwrap();
    app.update();
    let mut prev = app.world().resource::<FrameLights>().suns[0].cascades;
    for _ in 0..12 {
        common::move_camera(&mut app, |t| t.translation += Vec3::new(0.0, 0.0, -0.37));
        app.update();
        let now = app.world().resource::<FrameLights>().suns[0].cascades;
        let mut line = String::new();
        for c in 0..now.count {
            let (a, b) = (&prev.cascades[c], &now.cascades[c]);
            line.push_str(&format!(
                "c{c} first {:?} texel {:?} z {} {} | ",
                b.grid.first_texel, b.grid.texel, b.light_min.z, b.light_max.z
            ));
            let _ = a;
        }
        eprintln!("{line}");
        prev = now;
    }
}
