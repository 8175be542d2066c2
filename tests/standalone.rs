//! The standalone depth-only passes (`render::shadows::standalone`) on a real wgpu device
//! (lavapipe in CI): a spot light's map and a point light's six faces rendered from a plain
//! list of casters, with no ECS and no renderer, equal the engine's own maps of the same
//! scene texel for texel.

mod common;

use bevy_app::App;
use bevy_ecs::query::Without;
use common::still_scene;
use penumbra::ecs::view_list::POINT_NEAR;
use penumbra::ecs::{FrameLights, GlobalTransform, Mesh3d, Meshes, NotShadowCaster, ShadowStorage};
use penumbra::mesh::MeshData;
use penumbra::render::shadows::standalone::{ShadowCaster, StandaloneShadows, read_depth_layer};
use penumbra::render::{GpuContext, Renderer};

const SCENE: &str = "assets/scenes/night.ron";

/// The night scene rendered once by the engine, and its casters (not the ground, which does
/// not cast) as plain meshes.
fn engine() -> (App, Vec<(MeshData, glam::Mat4)>) {
    let renderer = Renderer::headless(160, 90)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = still_scene(renderer, SCENE);
    app.update();
    let world = app.world_mut();
    let mut q = world.query_filtered::<(&Mesh3d, &GlobalTransform), Without<NotShadowCaster>>();
    let placed: Vec<_> = q.iter(world).map(|(m, t)| (m.0, t.to_matrix())).collect();
    let meshes = world.resource::<Meshes>();
    let casters = placed
        .into_iter()
        .filter_map(|(handle, m)| Some((meshes.get(handle)?.clone(), m)))
        .collect();
    (app, casters)
}

/// Asserts both maps are equal texel for texel; returns how many texels hold a caster.
fn compare(what: &str, ours: &[f32], theirs: &[f32]) -> usize {
    assert_eq!(ours.len(), theirs.len(), "{what}: sizes differ");
    let differing = ours.iter().zip(theirs).filter(|(a, b)| a != b).count();
    assert_eq!(differing, 0, "{what}: {differing} texels differ from the engine's map");
    ours.iter().filter(|&&d| d > 0.0).count()
}

#[test]
fn standalone_spot_and_point_maps_equal_the_engines() {
    let (app, placed) = engine();
    let casters: Vec<ShadowCaster<'_>> = placed
        .iter()
        .filter(|(mesh, _)| !mesh.indices.is_empty())
        .map(|(mesh, m)| ShadowCaster {
            mesh,
            world_from_local: *m,
        })
        .collect();
    // NOTE: the ground is not a caster in the scene; the standalone pass draws what it is
    // given, so it is left out here too (it is the only plane).
    let casters: Vec<ShadowCaster<'_>> = casters.into_iter().filter(|c| c.mesh.vertices.len() != 4).collect();
    let lights = app.world().resource::<FrameLights>();
    let renderer = app.world().resource::<Renderer>();
    let gpu = GpuContext::headless().expect("a GPU adapter");
    let mut pass = StandaloneShadows::new(&gpu);
    // The first spot light (PCSS, 1024²).
    let spot = &lights.spots[0];
    let input = spot.shadow_input();
    let map = pass
        .render_spot(&gpu, &casters, &input, &spot.settings)
        .expect("a spot view");
    assert_eq!(Some(map.shadow.clip_from_world), spot.shadow.map(|s| s.clip_from_world));
    let ours = read_depth_layer(&gpu.device, &gpu.queue, &map.texture, 0).unwrap();
    let theirs = renderer
        .read_shadow_map(ShadowStorage::Spots, 0)
        .expect("the engine's spot map");
    let covered = compare("spot light 0", &ours, &theirs);
    assert!(covered > 1000, "spot light 0: only {covered} texels hold a caster");
    // The first point light (512² faces).
    let point = &lights.points[0];
    let cube = pass
        .render_point(
            &gpu,
            &casters,
            point.position,
            POINT_NEAR,
            point.light.range,
            point.resolution,
            &point.settings,
        )
        .expect("a point view");
    let mut covered = [0; 6];
    for (face, covered) in covered.iter_mut().enumerate() {
        let face = face as u32;
        let ours = read_depth_layer(&gpu.device, &gpu.queue, &cube.texture, face).unwrap();
        let theirs = renderer
            .read_shadow_map(ShadowStorage::Points, face)
            .expect("the engine's cube face");
        *covered = compare(&format!("point light 0, face {face}"), &ours, &theirs);
    }
    // The lamp's post and crates below and beside it: several faces hold casters.
    let faces_with_casters = covered.iter().filter(|&&c| c > 100).count();
    assert!(faces_with_casters >= 3, "casters per face {covered:?}");
}
