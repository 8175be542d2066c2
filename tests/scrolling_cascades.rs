//! Cascades that scroll (lavapipe): a cascade whose box moved by whole texels keeps its map,
//! wrapped round its layer, and draws only the texels it newly covers, so a walk draws few
//! whole maps; the maps kept, read in their boxes' order, equal the maps a renderer draws
//! fresh at the walk's end inside their cull volumes (bounded by the receivers), and so does
//! the image. Checked on a scene whose casters the CPU
//! lists and on one whose casters the GPU culls; a sun filtering moments does not scroll.

mod common;

use bevy_app::App;
use common::clipmap::window_texels;
use glam::Vec3;
use penumbra::ecs::ShadowViews;
use penumbra::ecs::view_list::{CullVolume, ShadowView};
use penumbra::render::Renderer;
use penumbra::settings::{ShadowMode, ShadowSettings};

/// `scene` with its sun's cascades at 1024² scrolling (or not), filtered with `mode`, before
/// its first frame.
fn scene(scene: &str, scroll: bool, mode: ShadowMode) -> App {
    let renderer = Renderer::headless(160, 90)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = common::still_scene(renderer, scene);
    let world = app.world_mut();
    let mut settings = world.query::<&mut ShadowSettings>();
    for mut s in settings.iter_mut(world) {
        s.map.resolution = 1024;
        s.map.cascades.scroll = scroll;
        s.filter.mode = mode;
    }
    app
}

/// One step of the walks: 0.37 m towards −z, drifting 0.05 m along x.
fn step(app: &mut App) {
    common::move_camera(app, |t| t.translation += Vec3::new(0.05, 0.0, -0.37));
}

/// Walks `app` `frames` steps after its first frame; returns the maps drawn whole and the
/// maps scrolled (drawn by strip) over the walk.
fn walk(app: &mut App, frames: usize) -> (u32, u32) {
    app.update();
    let (mut whole, mut scrolled) = (0, 0);
    for _ in 0..frames {
        step(app);
        app.update();
        let report = &app.world().resource::<Renderer>().last_report;
        whole += report.shadow_views_drawn;
        scrolled += report.shadow_views_scrolled;
    }
    (whole, scrolled)
}

/// Per texel of `view`'s map (in its box's order, rows from the top): whether it lies inside
/// the view's cull volume, less a texel at its edges: the texels a receiver can sample (a
/// volume bounded by the receivers leaves the others as earlier volumes drew them).
fn culled_texels(view: &ShadowView) -> Vec<bool> {
    let CullVolume::LightBox {
        light_rotation,
        min,
        max,
    } = view.cull
    else {
        panic!("a cascade's volume is a light-frame box");
    };
    let n = view.resolution as usize;
    let corner = |x: f32, y: f32| {
        let world = light_rotation.transpose() * Vec3::new(x, y, min.z);
        let clip = view.clip_from_world.project_point3(world);
        ((clip.x * 0.5 + 0.5) * n as f32, (0.5 - clip.y * 0.5) * n as f32)
    };
    let ((u0, v0), (u1, v1)) = (corner(min.x, max.y), corner(max.x, min.y));
    (0..n * n)
        .map(|i| {
            let (u, v) = ((i % n) as f32 + 0.5, (i / n) as f32 + 0.5);
            u > u0 + 1.0 && u < u1 - 1.0 && v > v0 + 1.0 && v < v1 - 1.0
        })
        .collect()
}

/// One step of the suns' 16-bit depth, and a little: a kept texel was drawn with its box
/// elsewhere, so its triangles' interpolated depth may round to the other step where it lies
/// at a step's midpoint.
const ONE_STEP: f32 = 1.0 / 65_535.0 + 1e-7;

/// Compares every cascade of `walked` (read in its box's order) and its image with a fresh
/// app of `scene` at the same pose; returns the caster texels judged, the texels that differ
/// by more than [`ONE_STEP`] (and prints those that differ by one) and the largest channel
/// difference of the images.
fn compare_with_fresh(walked: &mut App, scene_path: &str) -> (usize, usize, u8) {
    let at = common::camera_transform(walked);
    let mut fresh = scene(scene_path, true, ShadowMode::Pcf);
    common::move_camera(&mut fresh, |t| *t = at);
    fresh.update();
    let (mut judged, mut differ) = (0, 0);
    let (a, b) = (
        walked.world().resource::<ShadowViews>(),
        fresh.world().resource::<ShadowViews>(),
    );
    assert_eq!(a.views.len(), b.views.len());
    for (v, w) in a.views.iter().zip(&b.views) {
        assert_eq!(
            v.clip_from_world, w.clip_from_world,
            "the walked and fresh boxes differ"
        );
        assert_eq!(v.cull, w.cull, "the walked and fresh cull volumes differ");
        let inside = culled_texels(w);
        let pick = |t: Vec<f32>| -> Vec<f32> {
            t.into_iter()
                .zip(&inside)
                .filter(|(_, i)| **i)
                .map(|(t, _)| t)
                .collect()
        };
        let (kept, drawn) = (pick(window_texels(walked, v)), pick(window_texels(&fresh, w)));
        let by = |most: f32| {
            kept.iter()
                .zip(&drawn)
                .filter(|(x, y)| (**x - **y).abs() > most)
                .count()
        };
        let (d, stepped) = (by(ONE_STEP), by(0.0));
        let covered = drawn.iter().filter(|&&t| t > 0.0).count();
        println!(
            "{scene_path}, cascade {}: {covered} caster texels, {stepped} differ, {d} by more than a step",
            v.kind.index
        );
        judged += covered;
        differ += d;
    }
    let (p, q) = (
        walked.world().resource::<Renderer>().read_image(),
        fresh.world().resource::<Renderer>().read_image(),
    );
    (judged, differ, common::largest_difference(&p, &q))
}

/// Walks `path` `frames` steps with scrolling cascades (and, where `held` is given, with held
/// ones, checking the scrolling walk draws at most 60 % of the whole maps the held one
/// draws); checks it scrolled, and that its maps (inside their volumes, to a step of depth)
/// and image (to one level) equal a fresh renderer's with more than `fewest` caster texels
/// judged.
fn judge_walk(path: &str, frames: usize, held: bool, fewest: usize) {
    let mut app = scene(path, true, ShadowMode::Pcf);
    let (whole, scrolled) = walk(&mut app, frames);
    println!("{path}: {whole} maps drawn whole, {scrolled} scrolled");
    assert!(scrolled > 0, "{whole} whole, {scrolled} scrolled");
    if held {
        let (redrawn, _) = walk(&mut scene(path, false, ShadowMode::Pcf), frames);
        println!("{path}: held, {redrawn} maps drawn");
        assert!(whole * 5 <= redrawn * 3, "{whole} whole maps, {redrawn} held");
    }
    let (judged, differ, largest) = compare_with_fresh(&mut app, path);
    assert!(judged > fewest, "the cascades hold only {judged} caster texels");
    assert_eq!(
        differ, 0,
        "{differ} kept texels differ from a fresh map by more than a step"
    );
    assert!(largest <= 1, "the image differs from a fresh one by up to {largest}");
}

/// The long field (9 015 casters, listed by the CPU): a 24-frame walk with scrolling
/// cascades draws at most 60 % of the whole maps held cascades draw (9 of 23 measured, and 6
/// scrolled), and its kept maps (inside their volumes, to a step of depth) and image (to one
/// level) equal a fresh renderer's.
#[test]
fn scrolling_cascades_listed_on_the_cpu_keep_the_maps_drawn_fresh() {
    judge_walk("assets/bench/long_field.ron", 24, true, 10_000);
}

/// The pillars, where the receivers bound the near cascades' volumes inside their boxes: a
/// 24-frame walk scrolls, and keeps the maps (inside the volumes, to a step of depth) and
/// image (to one level) a fresh renderer draws.
#[test]
fn scrolling_cascades_bounded_by_the_receivers_keep_the_maps_drawn_fresh() {
    judge_walk("assets/scenes/pillars.ron", 24, false, 1_000);
}

/// The bench field (100k casters, culled on the GPU): a 10-frame walk with scrolling cascades
/// draws at most 60 % of the whole maps held cascades draw (6 of 24 measured, and 16
/// scrolled), and keeps the maps (inside their volumes, to a step of depth) and image (to one
/// level) a fresh renderer draws.
#[test]
fn scrolling_cascades_culled_on_the_gpu_keep_the_maps_drawn_fresh() {
    judge_walk("assets/bench/field.ron", 10, true, 10_000);
}

/// A sun filtering moments blurs them up to its layers' edges: its cascades are drawn whole,
/// never scrolled, though it asks for scrolling.
#[test]
fn a_moments_sun_does_not_scroll_its_cascades() {
    let mut app = scene("assets/bench/long_field.ron", true, ShadowMode::Evsm);
    let (whole, scrolled) = walk(&mut app, 4);
    let views = &app.world().resource::<ShadowViews>().views;
    assert!(views.iter().all(|v| v.scroll.is_none()), "a moments cascade scrolls");
    assert_eq!(scrolled, 0);
    assert!(whole > 0, "the walk drew no map");
}
