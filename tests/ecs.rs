//! The ECS layer without a GPU: systems build draw groups, bad input is repaired with a
//! warning instead of a panic or a NaN matrix.

use bevy_app::App;
use bevy_ecs::query::{With, Without};
use glam::{Quat, Vec3, Vec4};
use penumbra::ecs::{
    Camera3d, DirectionalLight, FrameLights, Material, Materials, Mesh3d, MeshMaterial3d, Meshes, NotShadowCaster,
    RenderInstances, ShadowDiagnostics, ShadowPlugin, ShadowStats, ShadowViewKind, ShadowViews, Transform,
    ViewDrawGroups,
};
use penumbra::mesh::{cuboid, plane};
use penumbra::settings::{MIN_RESOLUTION, ShadowSettings};

/// An app with a camera, a sun and a row of `n` boxes receding from the camera.
fn app_with_boxes(n: usize, settings: ShadowSettings) -> App {
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    let world = app.world_mut();
    let box_mesh = world.resource_mut::<Meshes>().add(cuboid(Vec3::ONE));
    let ground_mesh = world.resource_mut::<Meshes>().add(plane(glam::Vec2::splat(500.0)));
    let material = world.resource_mut::<Materials>().add(Material {
        base_color: Vec4::ONE,
        ..Default::default()
    });
    world.spawn((
        Camera3d::default(),
        Transform::from_translation(Vec3::new(0.0, 2.0, 0.0)).looking_at(Vec3::new(0.0, 2.0, -10.0), Vec3::Y),
    ));
    world.spawn((
        DirectionalLight::default(),
        Transform::default().looking_at(Vec3::new(0.3, -1.0, 0.2), Vec3::Y),
        settings,
    ));
    world.spawn((
        Transform::default(),
        Mesh3d(ground_mesh),
        MeshMaterial3d(material),
        NotShadowCaster,
    ));
    for i in 0..n {
        let z = -2.0 - i as f32 * (200.0 / n as f32);
        world.spawn((
            Transform::from_translation(Vec3::new(0.0, 0.5, z)),
            Mesh3d(box_mesh),
            MeshMaterial3d(material),
        ));
    }
    app
}

#[test]
fn casters_are_culled_into_every_cascade_they_touch() {
    let mut app = app_with_boxes(100, {
        let mut s = ShadowSettings::default();
        s.map.max_distance = 150.0;
        s
    });
    app.update();
    let world = app.world();
    let groups = world.resource::<ShadowViews>();
    let stats = world.resource::<ShadowStats>();
    assert_eq!(groups.views.len(), 4);
    assert_eq!(groups.groups.len(), 4);
    assert_eq!(stats.casters_per_view.len(), 4);
    // The ground does not cast; each box is in at least one cascade up to max_distance.
    let instances = world.resource::<RenderInstances>();
    assert_eq!(instances.casters.len(), 100);
    for c in 0..4 {
        assert!(
            stats.casters_per_view[c] > 0,
            "cascade {c} is empty: {:?}",
            stats.casters_per_view
        );
        assert_eq!(groups.views[c].kind, ShadowViewKind::cascade(c as u32));
        // All boxes share a mesh and material: one instanced draw per cascade.
        assert_eq!(groups.groups[c].opaque.len(), 1);
        assert!(groups.groups[c].masked.is_empty());
    }
    let total: u32 = stats.casters_per_view.iter().sum();
    assert!(total >= 75, "boxes within max_distance cast into some cascade: {total}");
    // The view sees the ground and the boxes in front of the camera.
    let view = world.resource::<ViewDrawGroups>();
    assert!(view.indices.len() > 50);
}

#[test]
fn invalid_settings_are_clamped_with_a_warning() {
    let bad = {
        let mut s = ShadowSettings::default();
        s.map.cascades.count = 9;
        s.map.cascades.split_lambda = f32::NAN;
        s.map.resolution = 10;
        s
    };
    let mut app = app_with_boxes(10, bad);
    app.update();
    let world = app.world();
    let sun = world.resource::<FrameLights>().sun().expect("the light is still used");
    assert_eq!(sun.settings.map.cascades.count, 4);
    assert_eq!(sun.settings.map.resolution, MIN_RESOLUTION);
    assert!(sun.cascades.active().iter().all(|c| c.clip_from_world.is_finite()));
    let warnings = &world.resource::<ShadowDiagnostics>().current;
    for field in ["cascade_count", "split_lambda", "resolution"] {
        assert!(
            warnings.iter().any(|w| w.contains(field)),
            "no warning about {field}: {warnings:?}"
        );
    }
}

#[test]
fn non_finite_and_zero_scale_transforms_are_skipped() {
    let mut app = app_with_boxes(3, ShadowSettings::default());
    let world = app.world_mut();
    let mesh = penumbra::ecs::MeshHandle(0);
    let material = penumbra::ecs::MaterialHandle(0);
    world.spawn((
        Transform::from_translation(Vec3::NAN),
        Mesh3d(mesh),
        MeshMaterial3d(material),
    ));
    world.spawn((
        Transform {
            scale: Vec3::ZERO,
            ..Default::default()
        },
        Mesh3d(mesh),
        MeshMaterial3d(material),
    ));
    world.spawn((
        Transform {
            rotation: Quat::from_xyzw(f32::INFINITY, 0.0, 0.0, 1.0),
            ..Default::default()
        },
        Mesh3d(mesh),
        MeshMaterial3d(material),
    ));
    app.update();
    let world = app.world();
    let instances = world.resource::<RenderInstances>();
    assert_eq!(instances.skipped, 3);
    assert_eq!(instances.casters.len(), 3);
    assert!(instances.caster_bounds.is_finite());
    let sun = *world.resource::<FrameLights>().sun().unwrap();
    assert!(sun.cascades.active().iter().all(|c| c.clip_from_world.is_finite()));
}

#[test]
fn a_light_pointing_straight_down_or_up_gives_finite_cascades() {
    for dir in [Vec3::NEG_Y, Vec3::Y] {
        let mut app = app_with_boxes(5, ShadowSettings::default());
        let world = app.world_mut();
        let mut lights = world.query::<(&DirectionalLight, &mut Transform)>();
        for (_, mut t) in lights.iter_mut(world) {
            *t = Transform::default().looking_at(dir, Vec3::Y);
        }
        app.update();
        let sun = *app.world().resource::<FrameLights>().sun().unwrap();
        assert!((sun.direction - dir).length() < 1e-5);
        assert!(
            sun.cascades
                .active()
                .iter()
                .all(|c| c.clip_from_world.is_finite() && c.texel_world_size > 0.0)
        );
    }
}

#[test]
fn changing_cascade_count_between_frames_updates_the_groups() {
    let mut app = app_with_boxes(50, ShadowSettings::default());
    app.update();
    assert_eq!(app.world().resource::<ShadowViews>().views.len(), 4);
    let world = app.world_mut();
    let mut q = world.query::<&mut ShadowSettings>();
    for mut s in q.iter_mut(world) {
        s.map.cascades.count = 2;
    }
    app.update();
    let world = app.world();
    assert_eq!(world.resource::<ShadowViews>().views.len(), 2);
    assert_eq!(world.resource::<ShadowViews>().groups.len(), 2);
    assert_eq!(world.resource::<ShadowStats>().casters_per_view.len(), 2);
}

#[test]
fn static_scenes_are_not_rebuilt_every_frame() {
    let mut app = app_with_boxes(20, ShadowSettings::default());
    app.update();
    let generation = app.world().resource::<RenderInstances>().generation;
    app.update();
    app.update();
    assert_eq!(app.world().resource::<RenderInstances>().generation, generation);
    // Moving one box triggers a rebuild.
    let world = app.world_mut();
    let mut q = world.query_filtered::<&mut Transform, (With<Mesh3d>, Without<NotShadowCaster>)>();
    if let Some(mut t) = q.iter_mut(world).next() {
        t.translation.x += 1.0;
    }
    app.update();
    assert_eq!(app.world().resource::<RenderInstances>().generation, generation + 1);
}
