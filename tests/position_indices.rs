//! Position-only index lists (lavapipe): opaque shadow casters drawn from lists whose
//! corners are the first vertex at their position write the same depth as the meshes' own
//! indices, texel for texel, whether the CPU lists the casters (the default scene) or the
//! GPU culls them (the 100k field), and skinned meshes, whose posed vertices move apart,
//! are drawn from their own indices.

mod common;

use bevy_app::App;
use bevy_ecs::query::With;
use penumbra::ecs::{Mesh3d, MeshHandle, ShadowStorage, SkinnedMesh};
use penumbra::render::{RenderOptions, Renderer};
use penumbra::settings::ShadowSettings;

/// `scene` with 1024² maps and position-only lists `on` or off, after `frames` frames.
fn rendered(scene: &str, on: bool, frames: usize) -> App {
    let options = RenderOptions {
        position_indices: on,
        ..RenderOptions::default()
    };
    let mut app = common::scene_with(scene, options);
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
/// the same bit for bit and the images equal; returns the meshes drawn from such lists and
/// the app that drew them, after checking no mesh is with the option off and at least
/// `listed` are with it on, and that more than `covered` caster texels were judged.
fn same_maps(scene: &str, frames: usize, (listed, covered): (usize, usize)) -> (Vec<MeshHandle>, App) {
    let (on, off) = (rendered(scene, true, frames), rendered(scene, false, frames));
    let meshes = on.world().resource::<Renderer>().position_listed_meshes();
    let unlisted = off.world().resource::<Renderer>().position_listed_meshes();
    assert!(unlisted.is_empty(), "{scene}: {unlisted:?} listed with the option off");
    let texels = common::equal_layers(scene, &cascades(&on), &cascades(&off));
    println!(
        "{scene}: {} meshes listed, caster texels per cascade {texels:?}",
        meshes.len()
    );
    let image = |app: &App| app.world().resource::<Renderer>().read_image();
    assert!(image(&on) == image(&off), "{scene}: the images differ");
    assert!(
        meshes.len() >= listed,
        "{scene}: {} meshes drawn from position-only lists",
        meshes.len()
    );
    let judged: usize = texels.iter().sum();
    assert!(judged > covered, "{scene}: {judged} caster texels judged");
    (meshes, on)
}

#[test]
fn cpu_listed_casters_draw_the_same_depth() {
    // Measured: 23 meshes, 335 533 texels.
    let _checked = same_maps("assets/scenes/default.ron", 2, (8, 110_000));
}

#[test]
fn gpu_culled_casters_draw_the_same_depth() {
    // Measured: 7 meshes, 1 565 658 texels.
    let _checked = same_maps("assets/scenes/field.ron", 2, (3, 520_000));
}

#[test]
fn posed_skinned_meshes_draw_the_same_depth_from_their_own_indices() {
    // Measured: 3 meshes, 69 404 texels.
    let (listed, mut app) = same_maps("assets/scenes/walkers.ron", 3, (1, 23_000));
    let world = app.world_mut();
    let mut skins = world.query_filtered::<&Mesh3d, With<SkinnedMesh>>();
    let skinned: Vec<MeshHandle> = skins.iter(world).map(|m| m.0).collect();
    // Measured: 12 skinned meshes.
    assert!(skinned.len() >= 4, "{} skinned meshes judged", skinned.len());
    let welded: Vec<_> = skinned.iter().filter(|m| listed.contains(m)).collect();
    assert!(
        welded.is_empty(),
        "posed skinned meshes drawn from position-only lists: {welded:?}"
    );
}
