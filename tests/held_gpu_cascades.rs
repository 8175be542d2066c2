//! Cascades culled on the GPU while the camera walks (lavapipe): the 100k field's sun lists
//! again only the cascades that moved, and after a walk every cascade's map equals the map a
//! renderer draws fresh there — with the shadow cache (held maps kept) and without it (every
//! map drawn each frame from its cascade's runs, those of the cascades that held included).

mod common;

use bevy_app::App;
use glam::Vec3;
use penumbra::ecs::ShadowViews;
use penumbra::layout::ShadowStorage;
use penumbra::render::Renderer;
use penumbra::settings::ShadowSettings;

/// The field (`assets/scenes/field.ron`, 101 736 casters) with 512² cascades, drawn with the
/// shadow cache or without.
fn field(cache: bool) -> App {
    let mut app = common::cached_scene("assets/scenes/field.ron", cache);
    let world = app.world_mut();
    let mut settings = world.query::<&mut ShadowSettings>();
    for mut s in settings.iter_mut(world) {
        s.map.resolution = 512;
        // NOTE: held, not scrolled (tests/scrolling_cascades.rs scrolls them).
        s.map.cascades.scroll = false;
    }
    app
}

/// The cascades' maps of `app`'s renderer.
fn maps(app: &App) -> Vec<Vec<f32>> {
    let renderer = app.world().resource::<Renderer>();
    (0..4)
        .map(|slot| {
            renderer
                .read_shadow_map(ShadowStorage::Cascades, slot)
                .expect("a cascade")
        })
        .collect()
}

/// Checks that a walk of 8 frames (0.37 m each) over the field, its cascades culled on the
/// GPU, ends with every cascade's map equal texel for texel to a fresh renderer's, with and
/// without the shadow cache, and that some frame of it changed some cascades' runs and left
/// the others' as they were.
#[test]
fn gpu_culled_cascades_that_held_keep_runs_that_draw_the_fresh_maps() {
    for cache in [true, false] {
        let mut walked = field(cache);
        walked.update();
        let mut mixed = 0;
        for _ in 0..8 {
            let before = walked.world().resource::<ShadowViews>().run_ranges.clone();
            let runs_before = walked.world().resource::<ShadowViews>().runs.clone();
            common::move_camera(&mut walked, |t| t.translation += Vec3::new(0.05, 0.0, -0.37));
            walked.update();
            let views = walked.world().resource::<ShadowViews>();
            assert!(
                views.run_ranges.len() >= 4 && views.run_ranges[..4].iter().all(|r| r.1 > 0),
                "cache {cache}: the cascades are not culled on the GPU ({:?})",
                views.run_ranges
            );
            let same = |c: usize| {
                let (a, b) = (before.get(c).copied(), views.run_ranges[c]);
                a.is_some_and(|a| {
                    let old = &runs_before[a.0 as usize..(a.0 + a.1) as usize];
                    let new = &views.runs[b.0 as usize..(b.0 + b.1) as usize];
                    old == new
                })
            };
            let kept = (0..4).filter(|&c| same(c)).count();
            if (1..4).contains(&kept) {
                mixed += 1;
            }
        }
        assert!(
            mixed > 0,
            "cache {cache}: no frame changed some cascades' runs and not others"
        );
        let at = common::camera_transform(&mut walked);
        let mut fresh = field(cache);
        common::move_camera(&mut fresh, |t| *t = at);
        fresh.update();
        let what = format!("cache {cache}: the walked cascades against fresh ones");
        let covered = common::equal_layers(&what, &maps(&walked), &maps(&fresh));
        println!("cache {cache}: {mixed} of 8 frames changed some cascades' runs only; caster texels {covered:?}");
        // Measured: 83 510 to 111 446 per cascade.
        assert!(
            covered.iter().all(|&c| c > 27_000),
            "cache {cache}: a cascade holds few caster texels: {covered:?}"
        );
    }
}
