//! GPU culling of the camera view (lavapipe): the depth pyramid's every level holds the
//! farthest depth of the level above it; the GPU's frustum and occlusion tests find culled
//! exactly the instances the CPU mirror does; and over a camera path through the 100k field the
//! image culled on the GPU (by chunk on the CPU, then frustum and occlusion per instance)
//! equals the image culled on the CPU (every instance against the frustum), pixel for pixel,
//! while it draws fewer instances.

mod common;

use bevy_app::App;
use bevy_ecs::query::With;
use bevy_transform::components::Transform;
use common::{move_camera, still_scene};
use glam::{Quat, Vec3};
use penumbra::ecs::view::ActiveView;
use penumbra::ecs::{Camera3d, CameraLod, RenderInstances, ViewDrawGroups};
use penumbra::math::frustum::Frustum;
use penumbra::math::occlusion::{CullCamera, Pyramid, hidden, in_frustum, level_for};
use penumbra::render::{DepthPrepass, RenderOptions, Renderer};
use std::collections::BTreeMap;

const SCENE: &str = "assets/scenes/field.ron";

/// The field with the prepass on and culling on the GPU (by chunk on the CPU, then frustum and
/// occlusion per instance) `on`, or on the CPU (every instance against the frustum); every mesh
/// drawn whole (the GPU picks levels per instance, the CPU per chunk: culling alone is
/// compared).
fn app(on: bool) -> App {
    app_with_lod(on, CameraLod { max_error_pixels: 0.0 })
}

/// [`app`] with the camera's `lod`.
fn app_with_lod(on: bool, lod: CameraLod) -> App {
    let renderer = Renderer::headless(320, 180)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = still_scene(renderer, SCENE);
    app.insert_resource(lod);
    app.insert_resource(RenderOptions {
        depth_prepass: DepthPrepass::On,
        occlusion_culling: on,
        gpu_culling: on,
        ..RenderOptions::default()
    });
    app
}

fn renderer(app: &App) -> &Renderer {
    app.world().resource::<Renderer>()
}

#[test]
fn the_pyramid_levels_hold_the_farthest_depth_under_them() {
    let mut app = app(true);
    app.update();
    let gpu = renderer(&app).read_occlusion_pyramid();
    assert_eq!(gpu.len(), 9, "320×180 down to one texel");
    let (w, h, level0) = &gpu[0];
    assert!(level0.iter().any(|&d| d > 0.0), "the depth is empty");
    let cpu = Pyramid::build(level0, *w, *h);
    for (k, (g, c)) in gpu.iter().zip(&cpu.levels).enumerate() {
        assert_eq!((g.0, g.1), (c.0, c.1), "level {k} size");
        let wrong = g.2.iter().zip(&c.2).filter(|(a, b)| a != b).count();
        assert_eq!(wrong, 0, "level {k}: {wrong} texels differ from the CPU's");
    }
}

#[test]
fn the_gpu_hides_what_the_cpu_mirror_hides() {
    let mut app = app(true);
    app.update();
    let world = app.world();
    let r = renderer(&app);
    let instances = world.resource::<RenderInstances>();
    let seen = r.read_occlusion_seen(instances.centers.len());
    let pyramid = Pyramid {
        levels: r.read_occlusion_pyramid(),
    };
    let (camera, _) = world.resource::<ActiveView>().camera.expect("a camera");
    let frustum = Frustum::from_clip_from_world(camera.clip_from_world());
    let camera = CullCamera {
        clip_from_view: camera.clip_from_view(),
        view_from_world: camera.view_from_world(),
        near: camera.near,
    };
    let views = world.resource::<ViewDrawGroups>();
    assert!(!views.runs.is_empty(), "the view is culled by chunk for the GPU");
    let entries: Vec<u32> = views.candidates().collect();
    let (mut hidden_count, mut disagree) = (0, 0);
    for &i in &entries {
        let i = i as usize;
        let (c, r) = (instances.centers[i], instances.radii[i]);
        let cpu = !in_frustum(&frustum, c, r) || hidden(&pyramid, &camera, c, r);
        hidden_count += cpu as usize;
        disagree += (cpu != (seen[i] == 0)) as usize;
    }
    eprintln!(
        "{hidden_count} of {} entries hidden, {disagree} disagree",
        entries.len()
    );
    assert!(
        hidden_count * 5 > entries.len(),
        "only {hidden_count} of {} hidden",
        entries.len()
    );
    assert_eq!(disagree, 0, "{disagree} entries judged otherwise on the GPU");
}

#[test]
fn culling_changes_no_pixel_along_a_camera_path() {
    let (mut culled, mut full) = (app(true), app(false));
    let mut drawn = (0, 0);
    for step in 0..6 {
        for app in [&mut culled, &mut full] {
            let world = app.world_mut();
            let mut q = world.query_filtered::<&mut Transform, With<Camera3d>>();
            for mut t in q.iter_mut(world) {
                // Forward 4 m and 3° left a frame, after the first.
                if step > 0 {
                    let forward = t.rotation * Vec3::new(0.0, 0.0, -4.0);
                    t.translation += forward;
                    t.rotation = Quat::from_rotation_y(3f32.to_radians()) * t.rotation;
                }
            }
            app.update();
        }
        let (a, b) = (renderer(&culled).read_image(), renderer(&full).read_image());
        let differing = a.pixels().zip(b.pixels()).filter(|(x, y)| x != y).count();
        assert_eq!(differing, 0, "step {step}: {differing} pixels differ");
        let (early, late) = renderer(&culled).read_occlusion_drawn().expect("the culling ran");
        let entries = culled.world().resource::<ViewDrawGroups>().entries() as u64;
        eprintln!("step {step}: {early} + {late} of {entries} instances drawn");
        // NOTE: the first frame draws everything (nothing was seen before it).
        if step > 0 {
            drawn.0 += early + late;
            drawn.1 += entries;
        }
    }
    // Measured: 305 459 of 380 868 (80 %) after the first frame.
    assert!(
        drawn.0 * 10 < drawn.1 * 9,
        "culling drew {} of {} instances",
        drawn.0,
        drawn.1
    );
}

#[test]
fn a_slow_walk_keeps_its_chunk_runs_and_every_pixel() {
    let (mut culled, mut full) = (app(true), app(false));
    let (mut kept, mut judged) = (0, 0);
    let mut last = None;
    for step in 0..10 {
        for app in [&mut culled, &mut full] {
            // 0.37 m forward and 0.1 m sideways a frame: the field's held frustum reaches 3 m
            // (half a percent of its 600 m) past the camera's.
            if step > 0 {
                move_camera(app, |t| t.translation += t.rotation * Vec3::new(0.1, 0.0, -0.37));
            }
            app.update();
        }
        let (a, b) = (renderer(&culled).read_image(), renderer(&full).read_image());
        let differing = a.pixels().zip(b.pixels()).filter(|(x, y)| x != y).count();
        assert_eq!(differing, 0, "step {step}: {differing} pixels differ");
        let views = culled.world().resource::<ViewDrawGroups>();
        kept += usize::from(last == Some(views.generation));
        last = Some(views.generation);
        // Every instance the CPU finds in the frustum is in a listed run.
        let mut listed = vec![false; culled.world().resource::<RenderInstances>().centers.len()];
        for run in &views.runs {
            listed[run.first as usize..(run.first + run.count) as usize].fill(true);
        }
        let visible = &full.world().resource::<ViewDrawGroups>().indices;
        let missing = visible.iter().filter(|&&i| !listed[i as usize]).count();
        assert_eq!(missing, 0, "step {step}: {missing} visible instances in no run");
        judged += visible.len();
    }
    eprintln!("runs kept on {kept} of 9 moving frames; {judged} visible instances judged");
    // Measured: kept on 8 of 9 frames (relisted once, after about 3 m).
    assert!(kept >= 6, "runs kept on only {kept} of 9 frames");
    assert!(kept < 9, "the runs were never listed again");
    // Measured: 802 924.
    assert!(judged > 400_000, "only {judged} visible instances judged");
}

#[test]
fn the_gpu_frustum_lists_hold_the_cpu_lists_and_what_the_mirror_keeps() {
    // Occlusion off: the GPU tests the frustum only, as the CPU does instance by instance.
    let mut apps = [true, false].map(|gpu| {
        let mut app = app(false);
        app.insert_resource(RenderOptions {
            depth_prepass: DepthPrepass::On,
            occlusion_culling: false,
            gpu_culling: gpu,
            ..RenderOptions::default()
        });
        app
    });
    for step in 0..3 {
        for app in &mut apps {
            let world = app.world_mut();
            let mut q = world.query_filtered::<&mut Transform, With<Camera3d>>();
            for mut t in q.iter_mut(world) {
                t.rotation = Quat::from_rotation_y((step * 10) as f32 * 1f32.to_radians()) * t.rotation;
            }
            app.update();
        }
        let gpu_lists = renderer(&apps[0]).read_gpu_culled().expect("the GPU culled");
        assert!(renderer(&apps[1]).read_gpu_culled().is_none(), "the CPU culled alone");
        let world = apps[0].world();
        let (instances, views) = (world.resource::<RenderInstances>(), world.resource::<ViewDrawGroups>());
        let (camera, _) = world.resource::<ActiveView>().camera.expect("a camera");
        let frustum = Frustum::from_clip_from_world(camera.clip_from_world());
        // Per (mesh, material): the sorted instances drawn by the GPU, kept by the mirror from
        // the runs, and drawn by the CPU's list.
        let mut gpu = BTreeMap::<(u32, u32), Vec<u32>>::new();
        let mut mirror = BTreeMap::<(u32, u32), Vec<u32>>::new();
        let batches: Vec<_> = views.group.opaque.iter().chain(&views.group.masked).collect();
        for (b, batch) in batches.iter().enumerate() {
            gpu.entry((batch.mesh.0, batch.material.0))
                .or_default()
                .extend(&gpu_lists[b]);
        }
        for run in &views.runs {
            let batch = batches[run.batch as usize];
            let kept = (run.first..run.first + run.count)
                .filter(|&i| in_frustum(&frustum, instances.centers[i as usize], instances.radii[i as usize]));
            mirror.entry((batch.mesh.0, batch.material.0)).or_default().extend(kept);
        }
        let cpu_views = apps[1].world().resource::<ViewDrawGroups>();
        let mut cpu = BTreeMap::<(u32, u32), Vec<u32>>::new();
        for batch in cpu_views.group.opaque.iter().chain(&cpu_views.group.masked) {
            let listed = &cpu_views.indices[batch.first as usize..(batch.first + batch.count) as usize];
            cpu.entry((batch.mesh.0, batch.material.0)).or_default().extend(listed);
        }
        for lists in [&mut gpu, &mut mirror, &mut cpu] {
            lists.retain(|_, l| !l.is_empty());
            lists.values_mut().for_each(|l| l.sort_unstable());
        }
        let total: usize = gpu.values().map(Vec::len).sum();
        let cpu_total: usize = cpu.values().map(Vec::len).sum();
        let missing: usize = (cpu.iter())
            .map(|(k, l)| {
                l.iter()
                    .filter(|i| gpu.get(k).is_none_or(|g| g.binary_search(i).is_err()))
                    .count()
            })
            .sum();
        eprintln!(
            "step {step}: GPU {total}, CPU {cpu_total} instances in {} lists",
            cpu.len()
        );
        assert!(cpu_total > 20_000, "only {cpu_total} instances judged");
        assert!(gpu == mirror, "step {step}: the GPU's lists differ from the mirror's");
        assert_eq!(missing, 0, "step {step}: instances the CPU drew and the GPU did not");
        // What only the GPU keeps touches a plane within its padding (measured 0–2 a step).
        assert!(
            total - cpu_total <= 6,
            "step {step}: {} more on the GPU",
            total - cpu_total
        );
    }
}

#[test]
fn the_gpu_draws_each_instance_at_the_level_the_mirror_picks() {
    let mut app = app_with_lod(true, CameraLod::default());
    app.insert_resource(RenderOptions {
        depth_prepass: DepthPrepass::On,
        occlusion_culling: false,
        ..RenderOptions::default()
    });
    app.update();
    let lists = renderer(&app).read_gpu_culled().expect("the GPU culled");
    let world = app.world();
    let (instances, views) = (world.resource::<RenderInstances>(), world.resource::<ViewDrawGroups>());
    let (camera, _) = world.resource::<ActiveView>().camera.expect("a camera");
    let view = (camera.position(), camera.forward());
    // The run of each instance listed.
    let mut run_of = std::collections::HashMap::new();
    for run in &views.runs {
        for i in run.first..run.first + run.count {
            run_of.insert(i, run);
        }
    }
    let (mut coarse, mut wrong, mut drawn, mut triangles) = (0, 0, 0, 0);
    let meshes = world.resource::<penumbra::ecs::Meshes>();
    let batches: Vec<_> = views.group.opaque.iter().chain(&views.group.masked).collect();
    for (b, list) in lists.iter().enumerate() {
        let mesh_triangles = meshes.get(batches[b].mesh).map_or(0, |m| m.indices.len() / 3);
        triangles += mesh_triangles * list.len();
        for &i in list {
            let run = run_of[&i];
            let errors = &run.errors[..run.levels as usize];
            let (c, r) = (instances.centers[i as usize], instances.radii[i as usize]);
            let level = level_for(errors, view, views.lod_error_per_depth, c, r);
            wrong += usize::from(b != (run.batch as usize + level));
            coarse += usize::from(level > 0);
            drawn += 1;
        }
    }
    eprintln!(
        "{coarse} of {drawn} instances at a coarser level ({triangles} triangles), {wrong} at another level than the mirror's"
    );
    // Measured: 28 757 of 80 723 (the field's 65 536 boxes have no levels).
    assert!(coarse > 9_000, "only {coarse} of {drawn} instances at a coarser level");
    assert_eq!(wrong, 0, "{wrong} instances at another level than the mirror's");
}
