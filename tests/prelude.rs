//! An app written against `penumbra::prelude` alone (and the crates it re-exports) builds and
//! computes shadow views: what the README's "Using it from code" promises.

use penumbra::prelude::*;

#[test]
fn an_app_needs_only_the_prelude() {
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    let world = app.world_mut();
    let mesh = world.resource_mut::<Meshes>().add(cuboid(Vec3::ONE));
    let ground = world.resource_mut::<Meshes>().add(plane(Vec2::splat(40.0)));
    let material = world.resource_mut::<Materials>().add(Material::default());
    world.spawn((
        Camera3d::default(),
        Transform::from_translation(Vec3::new(0.0, 3.0, 8.0)).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    world.spawn((
        DirectionalLight::default(),
        Transform::default().looking_at(Vec3::new(-0.5, -1.0, -0.3), Vec3::Y),
        ShadowSettings {
            filter: ShadowFilterSettings {
                mode: ShadowMode::Msm,
                moments: MomentSettings {
                    precision: MomentFormat::Fp16,
                    ..Default::default()
                },
                ..Default::default()
            },
            ..Default::default()
        },
    ));
    world.spawn((
        Transform::from_xyz(0.0, 0.5, 0.0),
        Mesh3d(mesh),
        MeshMaterial3d(material),
    ));
    world.spawn((
        Transform::default(),
        Mesh3d(ground),
        MeshMaterial3d(material),
        NotShadowCaster,
    ));
    app.update();
    let stats = app.world().resource::<ShadowStats>();
    assert_eq!(
        stats.casters_per_view.len(),
        4,
        "four cascades: {:?}",
        stats.casters_per_view
    );
    assert!(stats.casters_per_view.contains(&1), "{:?}", stats.casters_per_view);
    // The re-exported crates are the ones the API takes.
    let _: penumbra::glam::Vec3 = Vec3::X;
    let _: Option<penumbra::wgpu::TextureFormat> = None;
}
