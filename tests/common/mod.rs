//! What several render tests share: a scene file spawned into a headless app whose frames are
//! identical (the filter taps are not rotated per frame), and a box added to it.

// NOTE: each test binary uses part of this module.
#![allow(dead_code)]

pub mod rays;

use bevy_app::App;
use bevy_ecs::entity::Entity;
use bevy_ecs::world::World;
use glam::{Vec3, Vec4};
use penumbra::app::{headless_app, spawn_scene};
use penumbra::ecs::{Material, Materials, Mesh3d, MeshMaterial3d, Meshes, Transform};
use penumbra::mesh::cuboid;
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
