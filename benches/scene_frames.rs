//! Per-frame CPU cost of the shadow systems on the bench scenes as `penumbra render` loads
//! them (`assets/scenes/field.ron`: 100k casters, `assets/bench/many_boxes.ron`: 101 760
//! boxes of 2 120 meshes, `assets/bench/million.ron`: 1M), without a GPU: `ShadowPlugin`
//! alone, culling as for a renderer that culls on the GPU (camera and cascades by chunk) and
//! keeps its shadow layers, the camera walking 0.37 m a frame back and forth along its
//! scene's axis (30 frames each way, so it stays over the scene) — `scene_frame_moving/<scene>`
//! — or standing still
//! (`scene_frame_still/<scene>`); `scene_frame_moving_cold/<scene>` walks the same way with
//! the CPU's caches flushed before each frame (64 MiB written, untimed), as the GPU's work
//! between frames of `penumbra render` flushes them; `scene_frame_moving_held/<scene>` walks
//! with the suns' cascades held instead of scrolling (`cascade_scroll: false`: drawn whole
//! when they move, no regions planned). Run with `cargo bench --bench scene_frames`.

use bevy_app::App;
use bevy_ecs::query::With;
use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use penumbra::app::PreparedScene;
use penumbra::ecs::components::ViewportSize;
use penumbra::ecs::receiver_culling::ShadowCulling;
use penumbra::ecs::{Camera3d, ShadowPlugin, Transform};
use penumbra::scene::SceneDesc;
use penumbra::settings::ShadowSettings;

/// The scenes measured.
const SCENES: [&str; 3] = [
    "assets/scenes/field.ron",
    "assets/bench/many_boxes.ron",
    "assets/bench/million.ron",
];

/// `scene` spawned into an app of `ShadowPlugin` at 1920×1080, culled by chunk for the GPU,
/// its suns' cascades scrolling (as the scenes ask) or held, after its first frame.
fn scene_app(scene: &str, scroll: bool) -> App {
    let desc = SceneDesc::load(scene).expect("the bench scene loads");
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    app.insert_resource(ViewportSize {
        width: 1920,
        height: 1080,
    });
    let mut culling = app.world_mut().resource_mut::<ShadowCulling>();
    (culling.gpu_camera, culling.gpu_shadows, culling.cached) = (true, true, true);
    PreparedScene::new(&desc)
        .expect("the bench scene spawns")
        .spawn(app.world_mut());
    let world = app.world_mut();
    let mut settings = world.query::<&mut ShadowSettings>();
    for mut s in settings.iter_mut(world) {
        s.map.cascades.scroll &= scroll;
    }
    app.update();
    app
}

/// Moves the app's camera 0.37 m along −Z (frames 0–29 of every 60) or +Z (30–59).
fn walk(app: &mut App, frame: &mut u32) {
    let step = if (*frame / 30).is_multiple_of(2) { -0.37 } else { 0.37 };
    let world = app.world_mut();
    let mut cameras = world.query_filtered::<&mut Transform, With<Camera3d>>();
    for mut t in cameras.iter_mut(world) {
        t.translation.z += step;
    }
    *frame += 1;
}

/// Bytes written between cold frames: more than the last-level cache of common CPUs.
const FLUSH_BYTES: usize = 64 << 20;

/// Writes every cache line of `buffer` (with `pass` so no write is elided).
fn flush(buffer: &mut [u8], pass: u8) {
    for line in buffer.chunks_mut(64) {
        line[0] = line[0].wrapping_add(pass);
    }
    std::hint::black_box(&buffer[..]);
}

fn scene_frames(c: &mut Criterion) {
    let runs = [
        ("scene_frame_moving", true, true),
        ("scene_frame_still", false, true),
        ("scene_frame_moving_held", true, false),
    ];
    for (name, moving, scroll) in runs {
        let mut group = c.benchmark_group(name);
        group.sample_size(30);
        for scene in SCENES {
            let mut app = scene_app(scene, scroll);
            let mut frame = 0;
            group.bench_with_input(BenchmarkId::from_parameter(scene_id(scene)), &scene, |b, _| {
                b.iter(|| {
                    if moving {
                        walk(&mut app, &mut frame);
                    }
                    app.update()
                })
            });
        }
        group.finish();
    }
    let mut group = c.benchmark_group("scene_frame_moving_cold");
    group.sample_size(30);
    let mut buffer = vec![0u8; FLUSH_BYTES];
    for scene in SCENES {
        let mut app = scene_app(scene, true);
        let mut frame = 0;
        group.bench_with_input(BenchmarkId::from_parameter(scene_id(scene)), &scene, |b, _| {
            b.iter_batched(
                || flush(&mut buffer, 1),
                |()| {
                    walk(&mut app, &mut frame);
                    app.update()
                },
                BatchSize::PerIteration,
            )
        });
    }
    group.finish();
}

/// The file name of `scene` without its extension.
fn scene_id(scene: &str) -> &str {
    scene.rsplit('/').next().unwrap_or(scene).trim_end_matches(".ron")
}

criterion_group!(benches, scene_frames);
criterion_main!(benches);
