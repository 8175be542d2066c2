//! What several render tests share: a scene file spawned into a headless app whose frames are
//! identical (the filter taps are not rotated per frame), and a box added to it.

// NOTE: each test binary uses part of this module.
#![allow(dead_code)]

pub mod clipmap;
pub mod rays;
pub mod suns;

use bevy_app::App;
use bevy_ecs::entity::Entity;
use bevy_ecs::world::World;
use glam::{Vec3, Vec4};
use image::RgbaImage;
use penumbra::app::{HeadlessFrame, RenderRequest, headless_app, render_scene_with, spawn_scene};
use penumbra::ecs::{Camera3d, Material, Materials, Mesh3d, MeshMaterial3d, Meshes, Transform};
use penumbra::mesh::cuboid;
use penumbra::render::{RenderOptions, Renderer};
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
        s.filter.temporal_rotation = false;
    }
    app
}

/// `scene` in a 160×90 headless app (as [`still_scene`]) rendering with `options`; no frame
/// rendered yet.
pub fn scene_with(scene: &str, options: RenderOptions) -> App {
    let renderer = Renderer::headless(160, 90)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = still_scene(renderer, scene);
    app.insert_resource(options);
    app
}

/// `app`'s renderer.
pub fn renderer(app: &App) -> &Renderer {
    app.world().resource::<Renderer>()
}

/// [`scene_with`] the shadow cache on or off.
pub fn cached_scene(scene: &str, cache: bool) -> App {
    scene_with(
        scene,
        RenderOptions {
            shadow_cache: cache,
            ..RenderOptions::default()
        },
    )
}

/// Turns off scrolling cascades for every light of `app` that has settings: its cascades
/// are held and drawn whole when they move, and culled to the receivers (what the tests of
/// held cascades, receiver-bounded culling and single-pass cascades judge).
pub fn hold_cascades(app: &mut App) {
    let world = app.world_mut();
    let mut settings = world.query::<&mut ShadowSettings>();
    for mut s in settings.iter_mut(world) {
        s.map.cascades.scroll = false;
    }
}

/// Applies `f` to the transform of every 3D camera of `app`.
pub fn move_camera(app: &mut App, f: impl Fn(&mut Transform)) {
    let world = app.world_mut();
    let mut cameras = world.query_filtered::<&mut Transform, bevy_ecs::query::With<Camera3d>>();
    for mut t in cameras.iter_mut(world) {
        f(&mut t);
    }
}

/// The transform of `app`'s one 3D camera.
pub fn camera_transform(app: &mut App) -> Transform {
    let world = app.world_mut();
    let mut cameras = world.query_filtered::<&Transform, bevy_ecs::query::With<Camera3d>>();
    *cameras.single(world).expect("one camera")
}

/// A bench run small enough for software Vulkan: one shipped scene (a path under `assets/`),
/// the named presets, a 64×36 timing target, 160×90 analysis, 16–32 rays, one timed frame.
pub fn small_bench(scene: &str, presets: &[&str]) -> penumbra::bench::BenchConfig {
    penumbra::bench::BenchConfig {
        scenes: vec![
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("assets")
                .join(scene),
        ],
        presets: penumbra::bench::presets()
            .into_iter()
            .filter(|p| presets.contains(&p.name))
            .collect(),
        width: 64,
        height: 36,
        analysis_width: 160,
        analysis_height: 90,
        timing_frames: 1,
        warmup_frames: 0,
        pages: None,
        sun_depth: penumbra::render::SunDepth::default(),
        reference: penumbra::reference::ReferenceSettings {
            max_samples: 32,
            min_samples: 16,
            seed: 1,
        },
        shimmer_steps: 2,
        max_probes: 200,
        progress: false,
    }
}

/// Removes [`Static`](penumbra::ecs::Static) from every entity (scenes spawn their objects
/// static), so that moving them takes effect; returns how many were marked.
pub fn unmark_static(world: &mut World) -> usize {
    let marked: Vec<Entity> = world
        .query_filtered::<Entity, bevy_ecs::query::With<penumbra::ecs::Static>>()
        .iter(world)
        .collect();
    for &e in &marked {
        world.entity_mut(e).remove::<penumbra::ecs::Static>();
    }
    marked.len()
}

/// Adds a box of `size` metres with a plain `color` material at `at`; returns its entity.
pub fn spawn_box(world: &mut World, size: Vec3, color: Vec4, at: Vec3) -> Entity {
    let mesh = world.resource_mut::<Meshes>().add(cuboid(size));
    let material = world.resource_mut::<Materials>().add(Material {
        base_color: color,
        ..Default::default()
    });
    world
        .spawn((Transform::from_translation(at), Mesh3d(mesh), MeshMaterial3d(material)))
        .id()
}

/// What a GPU test says when it finds no adapter.
pub const INSTALL: &str =
    "no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)";

/// One frame of `desc` at `width × height` with `options` and temporal rotation off, with the
/// analysis targets when `analysis` is set.
pub fn still_frame(
    desc: &SceneDesc,
    (width, height): (u32, u32),
    options: RenderOptions,
    analysis: bool,
) -> HeadlessFrame {
    let tweak = |s: &mut ShadowSettings| s.filter.temporal_rotation = false;
    render_scene_with(
        desc,
        &RenderRequest {
            width,
            height,
            frames: 1,
            tweak: Some(&tweak),
            analysis,
            options,
            shadow_budget: None,
            count_fragments: false,
            camera_lod: None,
            camera_motion: Default::default(),
        },
    )
    .expect(INSTALL)
}

/// Where on a 1.5 m plane in y = 0 centred at `(x, 0, 0)` a point `p` lies, for a 0.4 m
/// square of shadow cast onto its middle: in the shadow (true), in the sun (false), or near
/// the shadow's edge or off the plane (None).
pub fn plane_region(p: Vec3, x: f32) -> Option<bool> {
    let (u, v) = (p.x - x, p.z);
    if p.y.abs() > 1e-3 || u.abs() > 0.7 || v.abs() > 0.7 {
        return None;
    }
    let inside = u.abs() < 0.1 && v.abs() < 0.1;
    let outside = u.abs() > 0.35 || v.abs() > 0.35;
    (inside || outside).then_some(inside)
}

/// Mean colour (sRGB levels) of the pixels of `image` whose `positions` lie in the shadow
/// (`shadowed`) or the sun on the plane at `x` ([`plane_region`]), and their count.
pub fn plane_colour(image: &RgbaImage, positions: &[Vec3], x: f32, shadowed: bool) -> ([f32; 3], usize) {
    let mut sum = [0.0f32; 3];
    let mut n = 0;
    for (p, pixel) in positions.iter().zip(image.pixels()) {
        if plane_region(*p, x) == Some(shadowed) {
            for (total, &channel) in sum.iter_mut().zip(&pixel.0) {
                *total += f32::from(channel);
            }
            n += 1;
        }
    }
    (sum.map(|s| s / n.max(1) as f32), n)
}

/// Checks that two renderers' layers of one storage are as many (at least one) and equal bit
/// for bit, naming `what` in the failure; returns each layer's caster texels (depth > 0).
pub fn equal_layers(what: &str, a: &[Vec<f32>], b: &[Vec<f32>]) -> Vec<usize> {
    assert!(
        !a.is_empty() && a.len() == b.len(),
        "{what}: {} and {} layers",
        a.len(),
        b.len()
    );
    a.iter()
        .zip(b)
        .enumerate()
        .map(|(layer, (a, b))| {
            let differ = a.iter().zip(b).filter(|(x, y)| x.to_bits() != y.to_bits()).count();
            assert_eq!(differ, 0, "{what}: layer {layer}: {differ} texels differ");
            a.iter().filter(|&&d| d > 0.0).count()
        })
        .collect()
}

/// The largest difference of any colour channel (sRGB levels) between two images.
pub fn largest_difference(a: &RgbaImage, b: &RgbaImage) -> u8 {
    a.pixels()
        .zip(b.pixels())
        .map(|(x, y)| (0..3).map(|c| x[c].abs_diff(y[c])).max().unwrap_or(0))
        .max()
        .unwrap_or(0)
}
