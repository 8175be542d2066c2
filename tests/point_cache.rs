//! Point-light shadows and the view cache, on the night scene (four shadowed point lights,
//! two spot lights, a moon): a still scene draws no cube face after its first frame; a caster
//! moving near one lamp draws again exactly the faces whose frusta it touches (before or after
//! the move), and the image equals a renderer's that draws every face every frame; past the
//! point-light budget, the lamps smallest on screen lose their shadows and are named.

mod common;

use bevy_app::App;
use bevy_ecs::entity::Entity;
use common::{spawn_box, still_scene};
use glam::{Vec3, Vec4};
use penumbra::ecs::{FrameLights, ShadowDiagnostics, ShadowLightBudget, ShadowStorage, ShadowViews, Transform};
use penumbra::math::aabb::Aabb;
use penumbra::math::point::face_frustum;
use penumbra::render::Renderer;

const NIGHT: &str = "assets/scenes/night.ron";

fn app(cache: bool) -> (App, Entity) {
    let mut app = common::cached_scene(NIGHT, cache);
    let cube = spawn_box(
        app.world_mut(),
        Vec3::splat(0.3),
        Vec4::new(0.9, 0.3, 0.3, 1.0),
        Vec3::new(-8.5, 1.0, -1.2),
    );
    app.update();
    (app, cube)
}

fn report(app: &App) -> &penumbra::render::FrameReport {
    &app.world().resource::<Renderer>().last_report
}

/// (light, face, version) of every point-light face.
fn faces(app: &App) -> Vec<(u32, u32, u64)> {
    let views = app.world().resource::<ShadowViews>();
    views
        .views
        .iter()
        .filter(|v| v.kind.storage == ShadowStorage::Points)
        .map(|v| (v.light, v.kind.index, v.version))
        .collect()
}

fn cube_box(at: Vec3) -> Aabb {
    Aabb {
        min: at - Vec3::splat(0.15),
        max: at + Vec3::splat(0.15),
    }
}

#[test]
fn a_caster_moving_near_one_lamp_redraws_only_the_faces_it_touches() {
    let (mut cached, cube) = app(true);
    let (mut fresh, fresh_cube) = app(false);
    assert_eq!(faces(&cached).len(), 24, "four lamps, six faces each");
    assert_eq!(
        report(&cached).shadow_views_drawn,
        29,
        "the first frame draws every view"
    );
    // NOTE: both apps run the same frames, so lights that rotate their filter taps per frame
    // (the lamp without its own settings) match.
    for _ in 0..2 {
        cached.update();
        fresh.update();
        assert_eq!(report(&cached).shadow_views_drawn, 0, "a still frame draws nothing");
    }
    let before = faces(&cached);
    let (from, to) = (Vec3::new(-8.5, 1.0, -1.2), Vec3::new(-8.5, 1.3, -1.2));
    for (app, e) in [(&mut cached, cube), (&mut fresh, fresh_cube)] {
        app.world_mut().get_mut::<Transform>(e).unwrap().translation = to;
        app.update();
    }
    let after = faces(&cached);
    // The faces whose frustum holds the box before or after the move, per lamp.
    let lights = cached.world().resource::<FrameLights>();
    let first_point = (lights.suns.len() + lights.spots.len()) as u32;
    let expected: Vec<(u32, u32)> = before
        .iter()
        .filter(|&&(light, face, _)| {
            let lamp = &lights.points[(light - first_point) as usize];
            let frustum = face_frustum(lamp.position, face as usize, 0.05, lamp.light.range);
            frustum.intersects_aabb(&cube_box(from)) || frustum.intersects_aabb(&cube_box(to))
        })
        .map(|&(light, face, _)| (light, face))
        .collect();
    let changed: Vec<(u32, u32)> = before
        .iter()
        .zip(&after)
        .filter(|(b, a)| b.2 != a.2)
        .map(|(b, _)| (b.0, b.1))
        .collect();
    assert_eq!(changed, expected);
    assert!(
        (1..=8).contains(&changed.len()),
        "{} of 24 faces redrawn",
        changed.len()
    );
    let image = |app: &App| app.world().resource::<Renderer>().read_image();
    let (a, b) = (image(&cached), image(&fresh));
    let differing = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
    assert_eq!(
        differing, 0,
        "{differing} pixels differ from a renderer without the cache"
    );
}

#[test]
fn past_the_point_light_budget_the_smallest_lamps_lose_their_shadows_and_are_named() {
    let renderer = Renderer::headless(160, 90)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = still_scene(renderer, NIGHT);
    let mut budget = ShadowLightBudget::default();
    budget.lights.point = 2;
    app.insert_resource(budget);
    app.update();
    let world = app.world();
    let lights = world.resource::<FrameLights>();
    let shadowed: Vec<bool> = lights.points.iter().map(|p| p.shadow.is_some()).collect();
    assert_eq!(shadowed.iter().filter(|&&s| s).count(), 2, "{shadowed:?}");
    assert_eq!(faces(&app).len(), 12);
    let warnings = &world.resource::<ShadowDiagnostics>().current;
    let dropped: Vec<&String> = warnings
        .iter()
        .filter(|w| w.contains("gets no shadow: only 2 shadowed point lights fit the budget"))
        .collect();
    // One warning names both dropped lamps (the first, then "the same for 1 more: …").
    assert_eq!(dropped.len(), 1, "{warnings:?}");
    assert!(dropped[0].contains("(the same for 1 more: "), "{}", dropped[0]);
    let names: Vec<&str> = dropped[0].split(|c: char| !c.is_ascii_alphanumeric()).collect();
    for (point, shadowed) in lights.points.iter().zip(&shadowed) {
        let named = names.contains(&point.entity.to_string().as_str());
        assert_eq!(named, !shadowed, "light {} shadowed {shadowed}", point.entity);
    }
    // The lamps nearest the camera (on the near side of the street, z = 1.2; the far side's
    // are at z = -1.2) look largest. NOTE: by position, not by the order lights are listed,
    // which follows the ECS's iteration order.
    let near_side: Vec<bool> = lights.points.iter().map(|p| p.position.z > 0.0).collect();
    assert_eq!(shadowed, near_side);
    assert!(report(&app).shadow_views_drawn > 0);
}
