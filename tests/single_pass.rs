//! Single-pass cascades: rendering a sun's cascades in one multiview pass draws exactly the
//! shadow maps the per-cascade passes draw (read back texel by texel), with fewer draw calls,
//! and keeps the shadow cache working when only some cascades must be drawn again.

mod common;

use bevy_app::App;
use bevy_ecs::entity::Entity;
use common::{spawn_box, still_scene};
use glam::{Vec3, Vec4};
use penumbra::ecs::{ShadowStorage, ShadowViews, Transform};
use penumbra::render::{RenderOptions, Renderer};

const CASCADES: u32 = 4;

/// The default scene (opaque and alpha-masked casters) with a cube added, rendered twice.
fn app(single_pass: bool, cache: bool) -> (App, Entity) {
    let renderer = Renderer::headless(160, 90)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    assert!(
        renderer.gpu.multiview_views >= CASCADES,
        "the adapter ({}) has no 4-view MULTIVIEW: single-pass cascades cannot be tested (lavapipe from mesa-vulkan-drivers has it)",
        renderer.gpu.adapter_info.name
    );
    let cpu_rasteriser = renderer.gpu.adapter_info.device_type == wgpu::DeviceType::Cpu;
    let mut app = still_scene(renderer, "assets/scenes/default.ron");
    app.insert_resource(RenderOptions {
        single_pass_cascades: single_pass,
        shadow_cache: cache,
        ..RenderOptions::default()
    });
    let world = app.world_mut();
    let cube = spawn_box(
        world,
        Vec3::new(0.8, 1.6, 0.8),
        Vec4::new(0.3, 0.4, 0.9, 1.0),
        Vec3::new(2.0, 0.8, -3.0),
    );
    // NOTE: lavapipe draws a primitive its clipper had to split into layer 0 of a multiview
    // pass, whatever its view (a Mesa defect; GPUs draw this scene identically both ways, see
    // docs/benchmarks.md). The roof slabs, 156 m long, cross every cascade's bounds, so on a
    // CPU rasteriser they are left out and every other caster is compared.
    if cpu_rasteriser {
        let mut slabs = world.query::<(Entity, &Transform)>();
        let slabs: Vec<Entity> = slabs
            .iter(world)
            .filter(|(_, t)| (t.translation.y - 8.25).abs() < 1e-3)
            .map(|(e, _)| e)
            .collect();
        assert_eq!(slabs.len(), 2, "the default scene's roof slabs");
        for slab in slabs {
            world.despawn(slab);
        }
    }
    // NOTE: culling makes the single-pass lists from the second frame on.
    app.update();
    app.update();
    (app, cube)
}

fn renderer(app: &App) -> &Renderer {
    app.world().resource::<Renderer>()
}

/// Every cascade layer, read back.
fn maps(app: &App) -> Vec<Vec<f32>> {
    (0..CASCADES)
        .map(|c| {
            renderer(app)
                .read_shadow_map(ShadowStorage::Cascades, c)
                .expect("cascade layer")
        })
        .collect()
}

/// Asserts both apps hold the same maps and that each map has casters in it (so the
/// comparison judged something); returns the covered texels per cascade.
fn same_maps(a: &App, b: &App, what: &str) -> Vec<usize> {
    let (a, b) = (maps(a), maps(b));
    let mut covered = Vec::new();
    for (c, (a, b)) in a.iter().zip(&b).enumerate() {
        let differing = a.iter().zip(b).filter(|(x, y)| x.to_bits() != y.to_bits()).count();
        assert_eq!(
            differing,
            0,
            "{what}: cascade {c}: {differing} of {} texels differ",
            a.len()
        );
        covered.push(a.iter().filter(|&&d| d > 0.0).count());
    }
    assert!(
        covered.iter().all(|&n| n >= 1000),
        "{what}: too few covered texels to judge: {covered:?}"
    );
    covered
}

#[test]
fn one_multiview_pass_draws_the_maps_of_one_pass_per_cascade() {
    let (single, _) = app(true, false);
    let (per_view, _) = app(false, false);
    let views = single.world().resource::<ShadowViews>();
    assert_eq!(views.single_pass.len(), 1, "one sun, one single-pass list");
    assert_eq!(views.single_pass[0].views, CASCADES);
    same_maps(&single, &per_view, "every cascade drawn");
    let (s, p) = (&renderer(&single).last_report, &renderer(&per_view).last_report);
    assert_eq!((s.shadow_views_drawn, p.shadow_views_drawn), (CASCADES, CASCADES));
    assert!(
        s.shadow_draw_calls < p.shadow_draw_calls,
        "single pass: {} draw calls, per cascade: {}",
        s.shadow_draw_calls,
        p.shadow_draw_calls
    );
    let image = |app: &App| renderer(app).read_image();
    assert_eq!(image(&single), image(&per_view), "the lit images differ");
    // The last frame's timings name one pass for the four cascades.
    let mut single = single;
    let mut renderer = single.world_mut().resource_mut::<Renderer>();
    if renderer.gpu.timestamps {
        let timings = renderer.wait_for_timings();
        let last = timings.last().expect("the last frame's timings");
        let names: Vec<&str> = last.passes.iter().map(|p| p.name.as_str()).collect();
        assert!(
            names.contains(&"shadow cascades 0-3") && !names.iter().any(|n| n.starts_with("shadow cascade ")),
            "{names:?}"
        );
    }
}

#[test]
fn a_caster_moving_in_some_cascades_redraws_them_in_one_pass_and_keeps_the_others() {
    let (mut single, a) = app(true, true);
    let (mut per_view, b) = app(false, false);
    // Far from the camera: the cube leaves the near cascades' casters alone.
    let far = Vec3::new(30.0, 0.8, -60.0);
    for (app, cube) in [(&mut single, a), (&mut per_view, b)] {
        app.world_mut().get_mut::<Transform>(cube).unwrap().translation = far;
        app.update();
    }
    let drawn = renderer(&single).last_report.shadow_views_drawn;
    assert!(
        (1..CASCADES).contains(&drawn),
        "moving a far caster redraws some cascades but not all: {drawn}"
    );
    same_maps(&single, &per_view, "after the move");
    // A still frame draws nothing and keeps every map.
    single.update();
    per_view.update();
    assert_eq!(renderer(&single).last_report.shadow_views_drawn, 0);
    same_maps(&single, &per_view, "still frame");
}
