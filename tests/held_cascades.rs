//! Cascades that hold while the camera moves within a cell of their grid (lavapipe): a
//! cascade whose box and casters held keeps its map, so a walk draws fewer maps than four a
//! frame (fewer still with 16 cells), and the maps kept are exactly the maps a renderer draws
//! fresh at the walk's end.

mod common;

use bevy_app::App;
use glam::Vec3;
use penumbra::layout::ShadowStorage;
use penumbra::render::Renderer;
use penumbra::settings::ShadowSettings;

/// The long field's cascades (1024², PCF), snapped to `cells` cells, before its first frame.
fn field(cells: u32) -> App {
    let renderer = Renderer::headless(160, 90)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = common::still_scene(renderer, "assets/bench/long_field.ron");
    let world = app.world_mut();
    let mut settings = world.query::<&mut ShadowSettings>();
    for mut s in settings.iter_mut(world) {
        s.map.resolution = 1024;
        s.map.cascades.snap_cells = cells;
        // NOTE: held, not scrolled (tests/scrolling_cascades.rs scrolls them).
        s.map.cascades.scroll = false;
    }
    app
}

/// Walks `app` 24 frames of 0.37 m towards −z (after its first frame); returns the shadow
/// views drawn each frame.
fn walk(app: &mut App) -> Vec<u32> {
    app.update();
    (0..24)
        .map(|_| {
            common::move_camera(app, |t| t.translation += Vec3::new(0.05, 0.0, -0.37));
            app.update();
            app.world().resource::<Renderer>().last_report.shadow_views_drawn
        })
        .collect()
}

/// The largest channel difference between two renderers' images and the caster texels of
/// their cascades, after checking every cascade's map is equal texel for texel.
fn compare_with_fresh(walked: &mut App, cells: u32) -> (u8, usize) {
    let at = common::camera_transform(walked);
    let mut fresh = field(cells);
    common::move_camera(&mut fresh, |t| *t = at);
    fresh.update();
    let (a, b) = (
        walked.world().resource::<Renderer>(),
        fresh.world().resource::<Renderer>(),
    );
    let mut judged = 0;
    for slot in 0..4 {
        let (kept, drawn) = (
            a.read_shadow_map(ShadowStorage::Cascades, slot).expect("a cascade"),
            b.read_shadow_map(ShadowStorage::Cascades, slot).expect("a cascade"),
        );
        let differ = kept.iter().zip(&drawn).filter(|(x, y)| x != y).count();
        let covered = drawn.iter().filter(|&&d| d > 0.0).count();
        println!("{cells} cells, cascade {slot}: {covered} caster texels, {differ} differ");
        assert_eq!(
            differ, 0,
            "{cells} cells, cascade {slot}: {differ} texels differ from a fresh map"
        );
        judged += covered;
    }
    (common::largest_difference(&a.read_image(), &b.read_image()), judged)
}

/// Checks that a walk (24 frames of 0.37 m) draws at most 75 of the 96 maps of four cascades
/// moved every frame with the default cells (25 measured) and at most 36 with 16 cells (12),
/// and that either way the maps and image at its end equal those of a renderer that drew the
/// same view fresh.
#[test]
fn held_cascades_draw_fewer_maps_and_keep_the_maps_drawn_fresh() {
    for (cells, most) in [(0, 75), (16, 36)] {
        let mut walked = field(cells);
        let per_frame = walk(&mut walked);
        let held: u32 = per_frame.iter().sum();
        println!("{cells} cells: {held} maps drawn in 24 moving frames ({per_frame:?})");
        assert!(
            held > 0 && held <= most,
            "{cells} cells drew {held} maps ({per_frame:?})"
        );
        let (largest, judged) = compare_with_fresh(&mut walked, cells);
        assert!(judged > 10_000, "the cascades hold only {judged} caster texels");
        assert!(
            largest <= 1,
            "{cells} cells: the image differs from a fresh one by up to {largest}"
        );
    }
}
