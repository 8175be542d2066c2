//! Single-pass cascades: rendering a sun's cascades in one multiview pass draws exactly the
//! shadow maps the per-cascade passes draw (read back texel by texel), with fewer draw calls,
//! also for a caster that crosses a cascade's edge (split by the clipper), and keeps the
//! shadow cache working when only some cascades must be drawn again.

mod common;

use bevy_app::App;
use bevy_ecs::entity::Entity;
use bevy_ecs::query::With;
use common::{spawn_box, still_scene};
use glam::{Mat3, Quat, Vec2, Vec3, Vec4};
use penumbra::ecs::shadow_lods::ShadowLods;
use penumbra::ecs::{
    DirectionalLight, Mesh3d, NotShadowCaster, NotShadowReceiver, ShadowStorage, ShadowViewKind, ShadowViews, Transform,
};
use penumbra::render::{RenderOptions, Renderer};
use penumbra::settings::ShadowSettings;

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
    // NOTE: scrolling cascades are drawn one pass each.
    common::hold_cascades(&mut app);
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
    // CPU rasteriser they are left out and every other caster is compared. A caster that
    // crosses a cascade's edge is split too, which shows where its cascades draw different
    // mesh levels (the layer given the split primitives holds another level there: 229
    // texels of the sphere at z = −11 with the 24 × 12 level); on a CPU rasteriser every
    // cascade draws whole meshes (an NVIDIA H100 draws the levels identically both ways).
    if cpu_rasteriser {
        world.resource_mut::<ShadowLods>().clear();
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

/// The NDC of world point `p` in cascade `c` of the first sun.
fn cascade_ndc(app: &App, c: u32, p: Vec3) -> Vec3 {
    let views = app.world().resource::<ShadowViews>();
    let view = views
        .views
        .iter()
        .find(|v| v.kind == ShadowViewKind::cascade(c))
        .expect("cascade view");
    view.clip_from_world.project_point3(p)
}

#[test]
fn a_caster_the_clipper_splits_is_drawn_alike_in_one_pass() {
    // NOTE: lavapipe mishandles primitives its clipper splits in a multiview pass (see
    // `app`), except in the first view. So here the sun has two cascades and one caster: a
    // slab near the light from just inside cascade 0 to six half-widths from its centre,
    // towards cascade 1, inside which it lies whole. The scene's other meshes only receive.
    let mut apps = [app(true, false).0, app(false, false).0];
    for app in &mut apps {
        let world = app.world_mut();
        let mut suns = world.query::<(&DirectionalLight, &mut ShadowSettings)>();
        for (_, mut s) in suns.iter_mut(world) {
            s.map.cascades.count = 2;
        }
        let mut meshes = world.query_filtered::<Entity, With<Mesh3d>>();
        let meshes: Vec<Entity> = meshes.iter(world).collect();
        for mesh in meshes {
            world.entity_mut(mesh).insert(NotShadowCaster);
        }
        app.update();
        app.update();
    }
    let inverse = |c: u32| {
        let views = apps[0].world().resource::<ShadowViews>();
        let view = views.views.iter().find(|v| v.kind == ShadowViewKind::cascade(c));
        view.expect("cascade view").clip_from_world.inverse()
    };
    let (c0, c1) = (inverse(0), inverse(1));
    // Cascade 1's centre seen from cascade 0, and the way to it in cascade 0's x, y.
    let towards = c0.inverse().project_point3(c1.project_point3(Vec3::splat(0.5)));
    let way = (towards.truncate()).normalize().extend(0.0);
    let at = |ndc: f32| c0.project_point3(way * ndc + Vec3::Z * 0.95);
    let (start, end) = (at(0.8), at(6.0));
    let axis = (end - start).normalize();
    let side = axis.cross(Vec3::Y).normalize();
    let rotation = Quat::from_mat3(&Mat3::from_cols(axis, side.cross(axis), side));
    for app in &mut apps {
        let world = app.world_mut();
        let slab = spawn_box(
            world,
            Vec3::new((end - start).length(), 0.3, 0.6),
            Vec4::new(0.8, 0.3, 0.3, 1.0),
            (start + end) * 0.5,
        );
        world.get_mut::<Transform>(slab).unwrap().rotation = rotation;
        world.entity_mut(slab).insert(NotShadowReceiver);
        app.update();
        app.update();
    }
    let views = apps[0].world().resource::<ShadowViews>();
    assert_eq!(
        views.single_pass.first().map(|g| g.views),
        Some(2),
        "one pass for both cascades"
    );
    let ends = |c: u32| [cascade_ndc(&apps[0], c, start), cascade_ndc(&apps[0], c, end)];
    let (in_0, in_1) = (ends(0), ends(1));
    assert!(
        in_0[0].truncate().abs().max_element() < 1.0 && in_0[1].truncate().abs().max_element() > 5.0,
        "the slab must start in cascade 0 and end five half-widths past its edge: {in_0:?}"
    );
    assert!(
        in_1.iter().all(|p| p.abs().max_element() < 0.95),
        "the slab must lie inside cascade 1: {in_1:?}"
    );
    same_maps(&apps[0], &apps[1], "a caster split by the clipper");
    // The split slab reaches cascade 0's edge: the texels its axis crosses there hold it.
    let map = renderer(&apps[0])
        .read_shadow_map(ShadowStorage::Cascades, 0)
        .expect("cascade 0");
    let side = (map.len() as f64).sqrt() as usize;
    let edge = (0..side)
        .map(|k| (k as f32 + 0.5) / side as f32 * 2.0 - 1.0)
        .filter(|&ndc| ndc.abs() > 0.9)
        .map(|ndc| way * (ndc / way.truncate().abs().max_element()))
        .filter(|p| p.truncate().dot(way.truncate()) > 0.0 && p.truncate().abs().max_element() < 0.995)
        .map(|p| {
            let texel = ((p.truncate() * Vec2::new(0.5, -0.5) + 0.5) * side as f32).as_uvec2();
            map[texel.y as usize * side + texel.x as usize]
        })
        .collect::<Vec<f32>>();
    assert!(
        edge.len() >= 50 && edge.iter().all(|&d| d > 0.0),
        "cascade 0 misses the split slab at its edge: {} texels, {} empty",
        edge.len(),
        edge.iter().filter(|&&d| d <= 0.0).count()
    );
}
