//! A static scene costs no heap allocation per frame: once the instances are built and the
//! draw-group vectors have grown, cascades and culling reuse their buffers.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use bevy_app::App;
use glam::{Vec3, Vec4};
use penumbra::ecs::{
    Camera3d, DirectionalLight, Material, Materials, Mesh3d, MeshMaterial3d, Meshes, ShadowPlugin, ShadowStats,
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

#[test]
fn steady_state_frames_do_not_allocate() {
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
        world.spawn((Transform::from_translation(p), Mesh3d(mesh), MeshMaterial3d(material)));
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
        stats.casters_per_cascade.iter().all(|&c| c > 0),
        "{:?}",
        stats.casters_per_cascade
    );
    assert_eq!(
        per_frame, 0.0,
        "steady-state frames allocate {per_frame} times per frame"
    );
}
