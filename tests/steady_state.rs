//! A static scene costs no heap allocation per frame (its casters marked `Static` or not):
//! once the instances are built and the
//! draw-group vectors have grown, cascades and culling reuse their buffers, and so do the
//! spot- and point-light shadow views (still or moving) and a sun's clipmap moving with the
//! camera.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use bevy_app::App;
use glam::{Vec3, Vec4};
use penumbra::ecs::{
    Camera3d, DirectionalLight, Material, Materials, Mesh3d, MeshMaterial3d, Meshes, ShadowPlugin, ShadowStats, Static,
    Transform,
};
use penumbra::mesh::cuboid;
use penumbra::settings::ShadowSettings;

/// Counts every allocation made by the process.
struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// The counter is process-wide: tests that read it take this lock so none runs beside them.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

#[test]
fn steady_state_frames_do_not_allocate() {
    let _serial = SERIAL.lock().unwrap_or_else(|p| p.into_inner());
    // The boxes as code spawns them, and marked `Static` as scenes spawn them.
    for marked in [false, true] {
        still_frames_allocate_nothing(marked);
    }
}

/// Ten still frames of 10k boxes (marked `Static` when `marked`) allocate nothing.
fn still_frames_allocate_nothing(marked: bool) {
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    let world = app.world_mut();
    let mesh = world.resource_mut::<Meshes>().add(cuboid(Vec3::ONE));
    let material = world.resource_mut::<Materials>().add(Material {
        base_color: Vec4::ONE,
        ..Default::default()
    });
    world.spawn((
        Camera3d::default(),
        Transform::from_translation(Vec3::new(0.0, 2.0, 0.0)).looking_at(Vec3::new(5.0, 0.0, -10.0), Vec3::Y),
    ));
    world.spawn((
        DirectionalLight::default(),
        Transform::default().looking_at(Vec3::new(0.3, -1.0, 0.2), Vec3::Y),
        ShadowSettings::default(),
    ));
    for i in 0..10_000 {
        let p = Vec3::new((i % 100) as f32 * 3.0 - 150.0, 0.5, (i / 100) as f32 * -3.0);
        let mut entity = world.spawn((Transform::from_translation(p), Mesh3d(mesh), MeshMaterial3d(material)));
        if marked {
            entity.insert(Static);
        }
    }
    for _ in 0..3 {
        app.update();
    }
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    for _ in 0..10 {
        app.update();
    }
    let per_frame = (ALLOCATIONS.load(Ordering::Relaxed) - before) as f64 / 10.0;
    let stats = app.world().resource::<ShadowStats>();
    assert!(
        stats.casters_per_view.len() == 4 && stats.casters_per_view.iter().all(|&c| c > 0),
        "{:?}",
        stats.casters_per_view
    );
    assert_eq!(
        per_frame, 0.0,
        "steady-state frames (static: {marked}) allocate {per_frame} times per frame"
    );
}

/// An app with `ShadowPlugin`, a camera and 10k unit boxes on a 3 m grid (nothing run yet).
fn grid_app() -> App {
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    let world = app.world_mut();
    let mesh = world.resource_mut::<Meshes>().add(cuboid(Vec3::ONE));
    let material = world.resource_mut::<Materials>().add(Material::default());
    world.spawn((
        Camera3d::default(),
        Transform::from_translation(Vec3::new(0.0, 2.0, 0.0)).looking_at(Vec3::new(5.0, 0.0, -10.0), Vec3::Y),
    ));
    for i in 0..10_000 {
        let p = Vec3::new((i % 100) as f32 * 3.0 - 150.0, 0.5, (i / 100) as f32 * -3.0);
        world.spawn((Transform::from_translation(p), Mesh3d(mesh), MeshMaterial3d(material)));
    }
    app
}

#[test]
fn spot_shadow_views_reuse_their_buffers() {
    use bevy_ecs::schedule::{IntoScheduleConfigs, Schedule};
    use penumbra::ecs::frame_lights::update_frame_lights;
    use penumbra::ecs::shadow_views::update_shadow_views;
    use penumbra::ecs::{ShadowViews, SpotLight};

    let _serial = SERIAL.lock().unwrap_or_else(|p| p.into_inner());
    let mut app = grid_app();
    let world = app.world_mut();
    // Twelve spot lights over the grid, all within the budget (a light over it is reported
    // with a message every frame, which allocates).
    world.resource_mut::<penumbra::ecs::ShadowLightBudget>().lights.spot = 12;
    for k in 0..12 {
        let p = Vec3::new(k as f32 * 20.0 - 120.0, 8.0, -20.0 * (k % 4) as f32);
        world.spawn((
            SpotLight::default(),
            Transform::from_translation(p).looking_at(p - Vec3::Y, Vec3::Z),
        ));
    }
    for _ in 0..3 {
        app.update();
    }
    let mut schedule = Schedule::default();
    schedule.add_systems((update_frame_lights, update_shadow_views).chain());
    schedule.run(app.world_mut());
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    for _ in 0..10 {
        schedule.run(app.world_mut());
    }
    let per_frame = (ALLOCATIONS.load(Ordering::Relaxed) - before) as f64 / 10.0;
    let views = app.world().resource::<ShadowViews>();
    assert_eq!(views.views.len(), 12);
    assert!(
        views.groups.iter().all(|g| g.instance_count() > 0),
        "every light sees casters"
    );
    assert_eq!(per_frame, 0.0, "spot shadow views allocate {per_frame} times per frame");
}

#[test]
fn point_shadow_views_reuse_their_buffers_still_and_moving() {
    use bevy_ecs::schedule::{IntoScheduleConfigs, Schedule};
    use penumbra::ecs::frame_lights::update_frame_lights;
    use penumbra::ecs::shadow_views::update_shadow_views;
    use penumbra::ecs::{GlobalTransform, PointLight, ShadowViews};

    let _serial = SERIAL.lock().unwrap_or_else(|p| p.into_inner());
    let mut app = grid_app();
    let world = app.world_mut();
    // Eight point lights over the grid, all within the budget.
    world.resource_mut::<penumbra::ecs::ShadowLightBudget>().lights.point = 8;
    for k in 0..8 {
        let p = Vec3::new(k as f32 * 30.0 - 120.0, 4.0, -30.0 * (k % 4) as f32);
        let light = PointLight {
            range: 12.0,
            ..PointLight::default()
        };
        world.spawn((light, Transform::from_translation(p)));
    }
    for _ in 0..3 {
        app.update();
    }
    let mut schedule = Schedule::default();
    schedule.add_systems((update_frame_lights, update_shadow_views).chain());
    // NOTE: the lights move back and forth by 30 cm, so every face is culled again each frame
    // (through a query made once: making one allocates).
    let mut lights = app.world_mut().query::<(&PointLight, &mut GlobalTransform)>();
    let mut step = |world: &mut bevy_ecs::world::World, frame: i32| {
        let offset = Vec3::X * if frame % 2 == 0 { 0.3 } else { -0.3 };
        for (_, mut global) in lights.iter_mut(world) {
            *global = GlobalTransform::from_translation(global.translation() + offset);
        }
    };
    for frame in 0..4 {
        step(app.world_mut(), frame);
        schedule.run(app.world_mut());
    }
    let versions = |app: &App| -> Vec<u64> {
        let views = app.world().resource::<ShadowViews>();
        views.views.iter().map(|v| v.version).collect()
    };
    for moving in [false, true] {
        let first = versions(&app);
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        for frame in 0..10 {
            if moving {
                step(app.world_mut(), frame);
            }
            schedule.run(app.world_mut());
        }
        let per_frame = (ALLOCATIONS.load(Ordering::Relaxed) - before) as f64 / 10.0;
        // Still, every face keeps its version; moving, every face got a new one.
        let last = versions(&app);
        let changed = first.iter().zip(&last).filter(|(a, b)| a != b).count();
        assert_eq!(changed, if moving { 48 } else { 0 }, "moving: {moving}");
        let views = app.world().resource::<ShadowViews>();
        assert_eq!(views.views.len(), 48, "six faces per light");
        let faces_with_casters = views.groups.iter().filter(|g| g.instance_count() > 0).count();
        assert!(faces_with_casters >= 8, "only {faces_with_casters} faces see casters");
        assert_eq!(
            per_frame, 0.0,
            "point shadow views (moving: {moving}) allocate {per_frame} times per frame"
        );
    }
}

#[test]
fn a_clipmap_moving_with_the_camera_does_not_allocate() {
    use penumbra::ecs::ShadowViews;
    use penumbra::settings::SunLayout;
    let _serial = SERIAL.lock().unwrap_or_else(|p| p.into_inner());
    let mut app = grid_app();
    let mut settings = ShadowSettings::default();
    settings.map.layout = SunLayout::Clipmap {
        levels: 6,
        level0_extent: 16.0,
    };
    app.world_mut().spawn((
        DirectionalLight::default(),
        Transform::default().looking_at(Vec3::new(0.3, -1.0, 0.2), Vec3::Y),
        settings,
    ));
    let mut cameras = app
        .world_mut()
        .query_filtered::<&mut Transform, bevy_ecs::query::With<Camera3d>>();
    let mut step = |app: &mut App, frame: u32| {
        for mut t in cameras.iter_mut(app.world_mut()) {
            t.translation += Vec3::new(0.37, 0.0, -0.51 * (frame % 3) as f32);
            t.rotate_y(0.05);
        }
        app.update();
    };
    // NOTE: the first frames grow the lists to the largest strips the walk exposes.
    for frame in 0..60 {
        step(&mut app, frame);
    }
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    for frame in 0..10 {
        step(&mut app, frame);
    }
    let per_frame = (ALLOCATIONS.load(Ordering::Relaxed) - before) as f64 / 10.0;
    assert_eq!(
        per_frame, 0.0,
        "moving clipmap frames allocate {per_frame} times per frame"
    );
    let views = app.world().resource::<ShadowViews>();
    let regions = views.regions.len();
    assert!(
        views.views.len() == 6 && regions > 0,
        "{} views, {regions} regions",
        views.views.len()
    );
}
