//! Per-frame CPU cost of the directional shadow: computing 1–4 cascades and culling 1k, 10k,
//! 100k and 1M casters against them into a reused mask buffer (`cascades_and_culling`), the
//! whole ECS frame of `ShadowPlugin` — cascades, per-cascade culling into draw groups and
//! camera culling — with the camera still and moving (`shadow_plugin_frame_*`, 1k to 1M casters
//! marked `Static`), a still frame with and without the marker and under `bevy_transform`'s own
//! propagation (`still_frame`), a frame that spawns and despawns a caster
//! (`spawn_and_despawn_frame`), and spot-light views with a
//! brute-force cull of 10k casters per light (`spot_views_and_culling`) and as the engine's
//! system does it (`spot_shadow_view_system`), and point lights' six faces each as the engine
//! does them, still and moving (`point_shadow_view_system_*`).

use std::hint::black_box;

use bevy_app::App;
use bevy_ecs::schedule::{IntoScheduleConfigs, Schedule};
use bevy_transform::{StaticTransformOptimizations, TransformPlugin};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::{Mat4, Quat, Vec3};
use penumbra::ecs::culling::cull_view;
use penumbra::ecs::frame_lights::update_frame_lights;
use penumbra::ecs::receiver_culling::ShadowCulling;
use penumbra::ecs::shadow_views::update_shadow_views;
use penumbra::ecs::view::update_active_view;
use penumbra::ecs::view_list::ShadowLightBudget;
use penumbra::ecs::{
    Camera3d, DirectionalLight, GlobalTransform, Material, Materials, Mesh3d, MeshMaterial3d, Meshes, PointLight,
    ShadowPlugin, ShadowViews, SpotLight, Static, Transform,
};
use penumbra::math::aabb::Aabb;
use penumbra::math::cascades::{CascadeInput, compute_cascades};
use penumbra::math::culling::{cull_casters, cull_spheres_frustum};
use penumbra::math::frustum::CameraView;
use penumbra::math::spot::{SpotInput, spot_view};
use penumbra::settings::{CascadeFit, ShadowSettings};

/// SplitMix64 step mapped to `[0, 1)`; deterministic scene generation.
fn next_unit(state: &mut u64) -> f32 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 40) as f32 / (1u32 << 24) as f32
}

/// `n` bounding spheres scattered over a 2 km × 2 km square, up to 40 m high, radius
/// 0.5–10 m.
fn casters(n: usize, seed: u64) -> (Vec<Vec3>, Vec<f32>) {
    let mut s = seed;
    let mut centers = Vec::with_capacity(n);
    let mut radii = Vec::with_capacity(n);
    for _ in 0..n {
        let x = next_unit(&mut s) * 2000.0 - 1000.0;
        let y = next_unit(&mut s) * 40.0;
        let z = next_unit(&mut s) * 2000.0 - 1000.0;
        centers.push(Vec3::new(x, y, z));
        radii.push(0.5 + next_unit(&mut s) * 9.5);
    }
    (centers, radii)
}

/// A typical frame: a camera 2 m above the ground looking slightly down, a low sun, 4
/// cascades over 300 m.
fn frame_input() -> CascadeInput {
    CascadeInput {
        camera: CameraView {
            world_from_view: Mat4::from_rotation_translation(
                Quat::from_euler(glam::EulerRot::YXZ, 0.7, -0.15, 0.0),
                Vec3::new(35.0, 2.0, -120.0),
            ),
            fov_y: 1.0,
            aspect: 16.0 / 9.0,
            near: 0.1,
            far: 2000.0,
        },
        light_direction: Vec3::new(0.4, -0.6, 0.3),
        scene_bounds: Aabb::new(Vec3::new(-1010.0, -10.0, -1010.0), Vec3::new(1010.0, 50.0, 1010.0)),
        receiver_bounds: Aabb::new(Vec3::new(-1010.0, -10.0, -1010.0), Vec3::new(1010.0, 50.0, 1010.0)),
        count: 4,
        split_lambda: 0.6,
        max_distance: 300.0,
        resolution: 2048,
        fit: CascadeFit::Tight,
        angular_diameter: 0.0093,
        blend_width: 0.1,
        snap_cells: 0,
        scroll: false,
        seen: None,
    }
}

fn cascades_and_culling(c: &mut Criterion) {
    let mut group = c.benchmark_group("cascades_and_culling");
    group.sample_size(20);
    for count in 1..=4usize {
        let input = CascadeInput { count, ..frame_input() };
        for n in [1_000usize, 10_000, 100_000, 1_000_000] {
            let (centers, radii) = casters(n, 0x5EED + n as u64);
            let mut masks = vec![0u8; n];
            group.throughput(Throughput::Elements(n as u64));
            group.bench_with_input(BenchmarkId::new(format!("{count}_cascades"), n), &n, |b, _| {
                b.iter(|| {
                    let set = compute_cascades(black_box(&input));
                    cull_casters(&set, black_box(&centers), black_box(&radii), &mut masks);
                    black_box(&masks);
                });
            });
        }
    }
    group.finish();

    let input = frame_input();
    c.bench_function("compute_cascades", |b| {
        b.iter(|| compute_cascades(black_box(&input)));
    });
}

/// How a benchmark app propagates transforms and marks its casters.
enum Setup {
    /// `ShadowPlugin`'s own propagation; casters marked [`Static`] (as scenes spawn them).
    Marked,
    /// `ShadowPlugin`'s own propagation; casters without the marker.
    Unmarked,
    /// The app adds `bevy_transform`'s `TransformPlugin` first, with its static-scene option
    /// on (`true`) or off; casters without the marker.
    Bevy(bool),
}

/// An app with `ShadowPlugin`, `n` casters that do not move (marked [`Static`]) and (when
/// `sun`) a shadowed sun, already run for a few frames.
fn plugin_app(n: usize, sun: bool) -> App {
    plugin_app_with(n, sun, Setup::Marked)
}

/// [`plugin_app`] with `setup`.
fn plugin_app_with(n: usize, sun: bool, setup: Setup) -> App {
    let input = frame_input();
    let (centers, radii) = casters(n, 0x5EED + n as u64);
    let mut app = App::new();
    if let Setup::Bevy(on) = setup {
        app.add_plugins(TransformPlugin);
        app.insert_resource(match on {
            true => StaticTransformOptimizations::Enabled,
            false => StaticTransformOptimizations::Disabled,
        });
    }
    app.add_plugins(ShadowPlugin);
    let world = app.world_mut();
    let mesh = world.resource_mut::<Meshes>().add(penumbra::mesh::cuboid(Vec3::ONE));
    let material = world.resource_mut::<Materials>().add(Material::default());
    let camera = input.camera;
    let (_, rotation, translation) = camera.world_from_view.to_scale_rotation_translation();
    world.spawn((
        Camera3d {
            fov_y: camera.fov_y,
            near: camera.near,
            far: camera.far,
            exposure: 1.0,
        },
        Transform {
            translation,
            rotation,
            scale: Vec3::ONE,
        },
    ));
    if sun {
        world.spawn((
            DirectionalLight::default(),
            Transform::default().looking_at(input.light_direction, Vec3::Y),
            {
                let mut s = ShadowSettings::default();
                s.map.max_distance = input.max_distance;
                s
            },
        ));
    }
    for (center, radius) in centers.iter().zip(&radii) {
        // A unit cube scaled by r has a bounding sphere of radius r·√3/2.
        let transform = Transform {
            translation: *center,
            rotation: Quat::IDENTITY,
            scale: Vec3::splat(*radius),
        };
        let mut caster = world.spawn((transform, Mesh3d(mesh), MeshMaterial3d(material)));
        if matches!(setup, Setup::Marked) {
            caster.insert(Static);
        }
    }
    for _ in 0..3 {
        app.update();
    }
    app
}

/// Moves the app's camera sideways by `step` metres, alternating direction, so every frame's
/// cascades differ from the last (the moving case: nothing is reused).
fn nudge_camera(app: &mut App, frame: &mut u32, step: f32) {
    let world = app.world_mut();
    let mut cameras = world.query::<(&Camera3d, &mut Transform, &mut GlobalTransform)>();
    if let Some((_, mut t, mut global)) = cameras.iter_mut(world).next() {
        let sign = if frame.is_multiple_of(2) { 1.0 } else { -1.0 };
        t.translation.x += sign * step;
        // NOTE: set directly too, for schedules that run without transform propagation.
        *global = GlobalTransform::from(*t);
    }
    *frame += 1;
}

/// The per-frame work the speed target is about, as ECS systems: find the camera, collect the
/// lights and compute the cascades, then cull the camera view and every caster per cascade
/// into draw groups (no rendering), with the camera moving every frame.
fn cascade_and_culling_systems(c: &mut Criterion) {
    let mut group = c.benchmark_group("cascade_and_culling_systems");
    group.sample_size(40);
    for n in [1_000usize, 10_000, 100_000] {
        let mut app = plugin_app(n, true);
        let mut schedule = Schedule::default();
        schedule.add_systems((update_active_view, update_frame_lights, cull_view, update_shadow_views).chain());
        let mut frame = 0;
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                nudge_camera(&mut app, &mut frame, 0.37);
                schedule.run(app.world_mut())
            })
        });
    }
    group.finish();
}

/// One whole frame of `ShadowPlugin` (sync, cascades, camera culling, caster culling): with
/// the camera still (everything reused) and moving every frame, with the camera view culled
/// per instance on the CPU or (`_gpu_camera`, as for a renderer that culls on the GPU) per
/// chunk, and (`_gpu_culling`) the cascades per chunk too.
fn shadow_plugin_frame(c: &mut Criterion) {
    for (name, step, gpu_camera, gpu_shadows) in [
        ("shadow_plugin_frame_still", 0.0, false, false),
        ("shadow_plugin_frame_moving", 0.37, false, false),
        ("shadow_plugin_frame_moving_gpu_camera", 0.37, true, false),
        ("shadow_plugin_frame_moving_gpu_culling", 0.37, true, true),
    ] {
        let mut group = c.benchmark_group(name);
        group.sample_size(30);
        for n in [1_000usize, 10_000, 100_000, 1_000_000] {
            let mut app = plugin_app(n, true);
            let mut culling = app.world_mut().resource_mut::<ShadowCulling>();
            (culling.gpu_camera, culling.gpu_shadows) = (gpu_camera, gpu_shadows);
            let mut frame = 0;
            group.throughput(Throughput::Elements(n as u64));
            group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
                b.iter(|| {
                    if step > 0.0 {
                        nudge_camera(&mut app, &mut frame, step);
                    }
                    app.update()
                })
            });
        }
        group.finish();
    }
}

/// A still frame of the whole plugin at 10k, 100k and 1M casters that do not move: marked
/// [`Static`] (as scenes spawn them), unmarked, and unmarked under `bevy_transform`'s own
/// `TransformPlugin` with its static-scene option (dirty-tree marking) on and off.
fn static_transform_options(c: &mut Criterion) {
    let mut group = c.benchmark_group("still_frame");
    group.sample_size(20);
    for n in [10_000usize, 100_000, 1_000_000] {
        for (name, setup) in [
            ("static_marker", Setup::Marked),
            ("unmarked", Setup::Unmarked),
            ("bevy_static_optimizations_on", Setup::Bevy(true)),
            ("bevy_static_optimizations_off", Setup::Bevy(false)),
        ] {
            let mut app = plugin_app_with(n, true, setup);
            group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| b.iter(|| app.update()));
        }
    }
    group.finish();
}

/// A frame that despawns one caster and spawns another (of the same mesh and material) among
/// 100k and 1M static ones: the removed instance is left as a tombstone, the new one appended.
fn spawn_frame(c: &mut Criterion) {
    let mut group = c.benchmark_group("spawn_and_despawn_frame");
    group.sample_size(20);
    for n in [100_000usize, 1_000_000] {
        let mut app = plugin_app(n, true);
        let world = app.world_mut();
        let mut casters = world.query::<(&Mesh3d, &MeshMaterial3d)>();
        let (mesh, material) = casters.iter(world).map(|(m, k)| (*m, *k)).next().expect("casters");
        let mut last = None;
        let mut k = 0u32;
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                let world = app.world_mut();
                if let Some(e) = last.take() {
                    world.despawn(e);
                }
                k = (k + 1) % 64;
                let at = Transform::from_xyz(k as f32, 1.0, -120.0);
                last = Some(world.spawn((at, mesh, material)).id());
                app.update()
            })
        });
    }
    group.finish();
}

/// Spot lights: the shadow view of each light (`spot_view`) and a brute-force cull of 10k
/// casters against its frustum, for 1, 16 and 64 lights of 30 m range scattered over the
/// casters' square. Throughput is in lights, so the per-light time reads off directly.
fn spot_views_and_culling(c: &mut Criterion) {
    let (centers, radii) = casters(10_000, 11);
    let mut group = c.benchmark_group("spot_views_and_culling_10k");
    group.sample_size(20);
    for lights in [1usize, 16, 64] {
        let mut s = 99u64;
        let inputs: Vec<SpotInput> = (0..lights)
            .map(|_| SpotInput {
                position: Vec3::new(
                    next_unit(&mut s) * 2000.0 - 1000.0,
                    12.0,
                    next_unit(&mut s) * 2000.0 - 1000.0,
                ),
                direction: Vec3::new(next_unit(&mut s) - 0.5, -1.0, next_unit(&mut s) - 0.5),
                outer_angle: 40f32.to_radians(),
                range: 30.0,
                near: 0.05,
                resolution: 1024,
            })
            .collect();
        let mut visible = Vec::with_capacity(centers.len());
        group.throughput(Throughput::Elements(lights as u64));
        group.bench_with_input(BenchmarkId::from_parameter(lights), &lights, |b, _| {
            b.iter(|| {
                let mut drawn = 0;
                for input in &inputs {
                    if let Some(view) = spot_view(black_box(input)) {
                        cull_spheres_frustum(&view.frustum, &centers, &radii, &mut visible);
                        drawn += visible.len();
                    }
                }
                black_box(drawn)
            })
        });
    }
    group.finish();
}

/// The light systems as the engine runs them, in a scene with spot lights only: collect and
/// rank the lights under the budget, build each view and cull the 10k casters into its draw
/// group, for 1, 16 and 64 shadowed spot lights of 30 m range placed over the casters (the
/// budget raised to fit them), still (nothing culled again) and moving (every light moves
/// every frame, so every view is culled again). Throughput is in lights.
fn spot_shadow_view_system(c: &mut Criterion) {
    for (name, step) in [
        ("spot_shadow_view_system_10k", 0.0),
        ("spot_shadow_view_system_moving_10k", 0.3),
    ] {
        let mut group = c.benchmark_group(name);
        group.sample_size(20);
        for lights in [1usize, 16, 64] {
            let mut app = plugin_app(10_000, false);
            let world = app.world_mut();
            world.resource_mut::<ShadowLightBudget>().lights.spot = lights;
            let mut s = 7u64;
            for _ in 0..lights {
                let position = Vec3::new(
                    next_unit(&mut s) * 2000.0 - 1000.0,
                    12.0,
                    next_unit(&mut s) * 2000.0 - 1000.0,
                );
                let spot = SpotLight {
                    range: 30.0,
                    outer_angle: 40f32.to_radians(),
                    ..SpotLight::default()
                };
                world.spawn((
                    spot,
                    Transform::from_translation(position).looking_at(position - Vec3::Y, Vec3::Z),
                ));
            }
            app.update();
            let mut schedule = Schedule::default();
            schedule.add_systems((update_frame_lights, update_shadow_views).chain());
            let mut frame = 0u32;
            group.throughput(Throughput::Elements(lights as u64));
            group.bench_with_input(BenchmarkId::from_parameter(lights), &lights, |b, _| {
                b.iter(|| {
                    if step > 0.0 {
                        move_lights::<SpotLight>(&mut app, &mut frame, step);
                    }
                    schedule.run(app.world_mut())
                })
            });
        }
        group.finish();
    }
}

/// Moves every light with component `L` sideways by `step` metres, alternating direction
/// (its global transform directly: the bench schedules run without transform propagation).
fn move_lights<L: bevy_ecs::component::Component>(app: &mut App, frame: &mut u32, step: f32) {
    let world = app.world_mut();
    let sign = if frame.is_multiple_of(2) { step } else { -step };
    let mut q = world.query_filtered::<&mut GlobalTransform, bevy_ecs::query::With<L>>();
    for mut global in q.iter_mut(world) {
        let mut affine = global.affine();
        affine.translation += glam::Vec3A::X * sign;
        *global = GlobalTransform::from(affine);
    }
    *frame += 1;
}

/// Point lights as the engine runs them, in a scene of 10k casters: collect and rank the
/// lights under the budget, build each light's six face views, plan their cache versions and
/// cull the casters into the faces that need it, for 1, 8 and 32 shadowed point lights of
/// 30 m range over the casters (the budget raised to fit them). Still: nothing moves, so no
/// face is culled or re-versioned (the bench asserts it). Moving: every light moves every
/// frame, so every face is culled again. Throughput is in lights.
fn point_shadow_view_system(c: &mut Criterion) {
    for (name, step) in [
        ("point_shadow_view_system_still_10k", 0.0),
        ("point_shadow_view_system_moving_10k", 0.3),
    ] {
        let mut group = c.benchmark_group(name);
        group.sample_size(20);
        for lights in [1usize, 8, 32] {
            let mut app = plugin_app(10_000, false);
            let world = app.world_mut();
            world.resource_mut::<ShadowLightBudget>().lights.point = lights;
            let mut s = 17u64;
            for _ in 0..lights {
                let position = Vec3::new(
                    next_unit(&mut s) * 2000.0 - 1000.0,
                    6.0,
                    next_unit(&mut s) * 2000.0 - 1000.0,
                );
                let point = PointLight {
                    range: 30.0,
                    ..PointLight::default()
                };
                world.spawn((point, Transform::from_translation(position)));
            }
            app.update();
            let mut schedule = Schedule::default();
            schedule.add_systems((update_frame_lights, update_shadow_views).chain());
            schedule.run(app.world_mut());
            let versions = |app: &App| -> Vec<u64> {
                app.world()
                    .resource::<ShadowViews>()
                    .views
                    .iter()
                    .map(|v| v.version)
                    .collect()
            };
            let before = versions(&app);
            assert_eq!(before.len(), 6 * lights);
            let mut frame = 0u32;
            group.throughput(Throughput::Elements(lights as u64));
            group.bench_with_input(BenchmarkId::from_parameter(lights), &lights, |b, _| {
                b.iter(|| {
                    if step > 0.0 {
                        move_lights::<PointLight>(&mut app, &mut frame, step);
                    }
                    schedule.run(app.world_mut())
                })
            });
            if step == 0.0 {
                assert_eq!(versions(&app), before, "a still scene re-versioned a face");
            }
        }
        group.finish();
    }
}

criterion_group!(
    benches,
    point_shadow_view_system,
    spot_shadow_view_system,
    cascades_and_culling,
    cascade_and_culling_systems,
    shadow_plugin_frame,
    static_transform_options,
    spawn_frame,
    spot_views_and_culling
);
criterion_main!(benches);
