//! Shadow LODs: a spawned sphere comes with four coarser meshes; a far cascade, whose texels
//! are wide, draws the spheres with one of them while the near cascades (and the camera, its
//! own levels off) draw the full mesh; and the image barely changes against drawing full
//! meshes everywhere (the triangles each cascade draws are printed).

mod common;

use bevy_app::App;
use common::still_scene;
use penumbra::ecs::draw_groups::DrawBatch;
use penumbra::ecs::shadow_lods::ShadowLods;
use penumbra::ecs::{CameraLod, MeshHandle, Meshes, ShadowViews, ViewDrawGroups};
use penumbra::render::Renderer;

const SCENE: &str = "assets/bench/field.ron";

fn app() -> App {
    let renderer = Renderer::headless(320, 180)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = still_scene(renderer, SCENE);
    // NOTE: the camera's own levels are tested in `camera_lod.rs`; here it draws full meshes.
    app.insert_resource(CameraLod { max_error_pixels: 0.0 });
    app.update();
    app
}

/// The triangles each shadow view draws (its batches' instances times their meshes').
fn view_triangles(app: &App) -> Vec<u64> {
    let world = app.world();
    let meshes = world.resource::<Meshes>();
    let triangles = |b: &DrawBatch| meshes.get(b.mesh).map_or(0, |m| m.indices.len() as u64 / 3) * u64::from(b.count);
    let views = world.resource::<ShadowViews>();
    views
        .groups
        .iter()
        .map(|g| g.opaque.iter().chain(&g.masked).map(triangles).sum())
        .collect()
}

/// The meshes each shadow view draws.
fn view_meshes(app: &App) -> Vec<Vec<MeshHandle>> {
    let views = app.world().resource::<ShadowViews>();
    views
        .groups
        .iter()
        .map(|g| g.opaque.iter().chain(&g.masked).map(|b| b.mesh).collect())
        .collect()
}

#[test]
fn far_cascades_draw_spheres_coarser_and_the_image_barely_changes() {
    let mut app = app();
    let lods = app.world().resource::<ShadowLods>().clone();
    let camera: Vec<MeshHandle> = app
        .world()
        .resource::<ViewDrawGroups>()
        .group
        .opaque
        .iter()
        .map(|b| b.mesh)
        .collect();
    // The ball mesh is the one with levels.
    let ball = camera
        .iter()
        .copied()
        .find(|&m| !lods.get(m).is_empty())
        .expect("the camera sees the balls, which have shadow LODs");
    let coarse: Vec<MeshHandle> = lods.get(ball).iter().map(|l| l.mesh).collect();
    assert_eq!(coarse.len(), 4);
    assert!(
        camera.iter().all(|m| !coarse.contains(m)),
        "the camera draws full meshes"
    );
    let per_view = view_meshes(&app);
    assert_eq!(per_view.len(), 4);
    assert!(
        per_view[0].contains(&ball),
        "cascade 0 draws the full ball: {per_view:?}"
    );
    assert!(
        per_view[3].iter().any(|m| coarse.contains(m)) && !per_view[3].contains(&ball),
        "cascade 3 draws a coarser ball: {per_view:?} (levels {coarse:?})"
    );
    let with_lods = app.world().resource::<Renderer>().read_image();
    let lod_triangles = view_triangles(&app);

    // Without levels every cascade draws the full ball (and every map is drawn again).
    app.world_mut().resource_mut::<ShadowLods>().clear();
    app.update();
    let per_view = view_meshes(&app);
    assert!(
        per_view.iter().all(|v| v.iter().all(|m| !coarse.contains(m))),
        "{per_view:?}"
    );
    assert_eq!(app.world().resource::<Renderer>().last_report.shadow_views_drawn, 4);
    let full_triangles = view_triangles(&app);
    println!("triangles per cascade: {full_triangles:?} with full meshes, {lod_triangles:?} with LODs");
    let full = app.world().resource::<Renderer>().read_image();
    let pixels = (full.width() * full.height()) as usize;
    let differing = with_lods
        .pixels()
        .zip(full.pixels())
        .filter(|(a, b)| a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > 8))
        .count();
    assert!(
        differing * 1000 < pixels,
        "{differing} of {pixels} pixels differ by more than 8/255"
    );
}
