//! Position-only index lists (lavapipe): opaque shadow casters drawn from lists whose
//! corners are the first vertex at their position write the same depth as the meshes' own
//! indices, texel for texel, whether the CPU lists the casters (the default scene) or the
//! GPU culls them (the 100k field), and skinned meshes, whose posed vertices move apart,
//! are drawn from their own indices.

mod common;

use bevy_app::App;
use penumbra::ecs::ShadowStorage;
use penumbra::render::{RenderOptions, Renderer};
use penumbra::settings::ShadowSettings;

/// `scene` with 1024² maps and position-only lists `on` or off, after `frames` frames.
fn rendered(scene: &str, on: bool, frames: usize) -> App {
    let renderer = Renderer::headless(160, 90)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = common::still_scene(renderer, scene);
    app.insert_resource(RenderOptions {
        position_indices: on,
        ..RenderOptions::default()
    });
    let world = app.world_mut();
    let mut settings = world.query::<&mut ShadowSettings>();
    for mut s in settings.iter_mut(world) {
        s.map.resolution = 1024;
    }
    for _ in 0..frames {
        app.update();
    }
    app
}

/// Every cascade layer of `app`.
fn cascades(app: &App) -> Vec<Vec<f32>> {
    let renderer = app.world().resource::<Renderer>();
    (0..)
        .map_while(|layer| renderer.read_shadow_map(ShadowStorage::Cascades, layer))
        .collect()
}

/// Renders `scene` with and without position-only lists and checks every cascade texel is
/// the same bit for bit; returns the meshes drawn from such lists and the caster texels
/// judged.
fn same_maps(scene: &str, frames: usize) -> (usize, usize) {
    let (on, off) = (rendered(scene, true, frames), rendered(scene, false, frames));
    let listed = on.world().resource::<Renderer>().position_listed_meshes();
    let unlisted = off.world().resource::<Renderer>().position_listed_meshes();
    assert_eq!(unlisted, 0, "{scene}: {unlisted} meshes listed with the option off");
    let covered = common::equal_layers(scene, &cascades(&on), &cascades(&off));
    println!("{scene}: caster texels per cascade {covered:?}");
    let covered = covered.iter().sum();
    let image = |app: &App| app.world().resource::<Renderer>().read_image();
    assert!(image(&on) == image(&off), "{scene}: the images differ");
    (listed, covered)
}

#[test]
fn cpu_listed_casters_draw_the_same_depth() {
    let (listed, covered) = same_maps("assets/scenes/default.ron", 2);
    println!("default: {listed} meshes drawn from position-only lists");
    // Measured: 335 533 texels.
    assert!(
        listed >= 8,
        "{listed} meshes drawn from position-only lists (measured 23)"
    );
    assert!(covered > 110_000, "{covered} caster texels judged");
}

#[test]
fn gpu_culled_casters_draw_the_same_depth() {
    let (listed, covered) = same_maps("assets/scenes/field.ron", 2);
    println!("field: {listed} meshes drawn from position-only lists");
    // Measured: 1 565 658 texels.
    assert!(
        listed >= 3,
        "{listed} meshes drawn from position-only lists (measured 7)"
    );
    assert!(covered > 520_000, "{covered} caster texels judged");
}

#[test]
fn posed_skinned_meshes_draw_the_same_depth() {
    let (listed, covered) = same_maps("assets/scenes/walkers.ron", 3);
    println!("walkers: {listed} meshes drawn from position-only lists");
    // Measured: 69 404 texels.
    assert!(covered > 23_000, "{covered} caster texels judged");
}
