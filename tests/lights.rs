//! Lights in scene files and code: `lights: [Directional(...), Spot(...), Point(...)]` beside
//! (or instead of) `sun:`, located errors for bad light fields, spot and point light
//! components that require a transform, and every shadowed light's views.

use bevy_app::App;
use bevy_ecs::query::With;
use glam::Vec3;
use penumbra::app::spawn_scene;
use penumbra::ecs::{
    DirectionalLight, GlobalTransform, PointLight, ShadowDiagnostics, ShadowPlugin, ShadowViewKind, SpotLight,
    Transform,
};
use penumbra::scene::{LightDesc, SceneDesc};
use penumbra::settings::ShadowSettings;

const SCENE: &str = r#"Scene(
    camera: (position: (0, 3, 8), target: (0, 0, 0), fov: 60, near: 0.1, far: 100),
    sun: (direction: (-0.5, -1, -0.3)),
    lights: [
        Directional(direction: (0.4, -1, 0.2), illuminance: 0.5, shadows: (cascade_count: 2)),
        Spot(position: (0, 4, 0), direction: (0, -1, 0), outer_angle: 30, inner_angle: 20, radius: 0.1),
        Point(position: (2, 1, 0), range: 5),
    ],
    materials: { "m": () },
    objects: [(shape: Cuboid(size: (1, 1, 1)), material: "m")],
)"#;

fn app_with(text: &str) -> App {
    let desc = SceneDesc::from_str(text, "lights.ron").unwrap_or_else(|e| panic!("{e}"));
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    spawn_scene(app.world_mut(), &desc).unwrap();
    app.update();
    app
}

#[test]
fn scene_lights_spawn_with_their_fields_and_placement() {
    let desc = SceneDesc::from_str(SCENE, "lights.ron").unwrap();
    assert_eq!(desc.lights.len(), 3);
    assert!(
        matches!(desc.lights[1], LightDesc::Spot { range, .. } if range == 20.0),
        "default range"
    );
    let mut app = app_with(SCENE);
    let world = app.world_mut();
    let suns: Vec<(DirectionalLight, ShadowSettings)> = world
        .query::<(&DirectionalLight, &ShadowSettings)>()
        .iter(world)
        .map(|(l, s)| (*l, *s))
        .collect();
    assert_eq!(suns.len(), 2);
    assert_eq!(suns.iter().map(|s| s.1.map.cascades.count).collect::<Vec<_>>(), [4, 2]);
    let (spot, at) = world.query::<(&SpotLight, &GlobalTransform)>().single(world).unwrap();
    assert!((spot.outer_angle - 30f32.to_radians()).abs() < 1e-6);
    assert!((spot.inner_angle - 20f32.to_radians()).abs() < 1e-6);
    assert_eq!(spot.radius, 0.1);
    assert!(at.translation().abs_diff_eq(Vec3::new(0.0, 4.0, 0.0), 1e-6));
    assert!(at.forward().abs_diff_eq(Vec3::NEG_Y, 1e-5), "{:?}", at.forward());
    let (point, at) = world.query::<(&PointLight, &GlobalTransform)>().single(world).unwrap();
    assert_eq!(point.range, 5.0);
    assert!(at.translation().abs_diff_eq(Vec3::new(2.0, 1.0, 0.0), 1e-6));
    // Every light is drawn: both suns with their own cascades, the spot light with its view.
    let lights = world.resource::<penumbra::ecs::FrameLights>();
    assert_eq!(lights.len(), 4);
    let counts: Vec<usize> = lights.suns.iter().map(|s| s.cascades.count).collect();
    assert_eq!(counts, [4, 2]);
    assert!(lights.spots[0].shadow.is_some());
    assert!(lights.points[0].shadow.is_some());
    // Six cascades, the spot light's view and the point light's six cube faces.
    let views = world.resource::<penumbra::ecs::ShadowViews>();
    assert_eq!(views.views.len(), 13);
    let faces: Vec<ShadowViewKind> = views.views[7..].iter().map(|v| v.kind).collect();
    assert_eq!(faces, (0..6).map(ShadowViewKind::point_face).collect::<Vec<_>>());
    let warnings = &world.resource::<ShadowDiagnostics>().current;
    assert!(warnings.is_empty(), "{warnings:?}");
}

#[test]
fn a_scene_may_have_lights_without_a_sun_or_no_light_at_all() {
    let only_spot = SCENE.replace("    sun: (direction: (-0.5, -1, -0.3)),\n", "");
    let desc = SceneDesc::from_str(&only_spot, "lights.ron").unwrap();
    assert!(desc.sun.is_none());
    let mut app = app_with(&only_spot);
    let world = app.world_mut();
    assert_eq!(world.query::<&DirectionalLight>().iter(world).count(), 1);
    let dark = r#"Scene(camera: (position: (0, 3, 8), target: (0, 0, 0), fov: 60, near: 0.1, far: 100))"#;
    let desc = SceneDesc::from_str(dark, "dark.ron").unwrap();
    assert!(desc.sun.is_none() && desc.lights.is_empty());
}

/// `line:column` (from 1, in characters) of the value in `field: value` within `text`.
fn value_at(text: &str, field_and_value: &str) -> String {
    let start = text.find(field_and_value).expect("the edit is in the text");
    let value = start + field_and_value.find(": ").map_or(0, |i| i + 2);
    let line = text[..value].matches('\n').count() + 1;
    let column = text[..value].rsplit('\n').next().unwrap_or("").chars().count() + 1;
    format!("{line}:{column}")
}

#[test]
fn bad_light_fields_are_located() {
    let cases = [
        (
            "outer_angle: 30",
            "outer_angle: 95",
            "expected a half-angle in degrees greater than 0 and at most 89 for `lights[1].outer_angle`, found 95",
        ),
        (
            "inner_angle: 20",
            "inner_angle: 40",
            "expected a half-angle in degrees from 0 to `outer_angle` (30) for `lights[1].inner_angle`, found 40",
        ),
        (
            "range: 5",
            "range: 0",
            "expected a distance greater than 0 (metres) for `lights[2].range`, found 0",
        ),
        (
            "radius: 0.1",
            "radius: -1",
            "expected an emitter radius ≥ 0 (metres) for `lights[1].radius`, found -1",
        ),
        ("cascade_count: 2", "cascade_count: 9", "expected "),
        // Values that a 32-bit float cannot carry are named as such, with their size.
        (
            "outer_angle: 30",
            "outer_angle: 1e-45",
            "expected a half-angle in degrees greater than 0 and at most 89 for `lights[1].outer_angle`, found 1e-45, which is 0 in radians",
        ),
        (
            "direction: (0, -1, 0)",
            "direction: (0, -1e-30, 0)",
            "expected a direction long enough to normalise (length at least 1e-22) for `lights[1].direction`, found (0, -1e-30, 0), length 1e-30",
        ),
        // A light that casts shadows must reach past its shadow views' near plane: `render`
        // could make no view.
        (
            "range: 5",
            "range: 1e-30",
            "expected a distance greater than 0.05 m (its shadow views' near plane) for a light that casts shadows, or `shadows_enabled: false` for `lights[2].range`, found 1e-30",
        ),
        // Numbers far from one are shown in scientific notation.
        (
            "radius: 0.1",
            "radius: -3e38",
            "expected an emitter radius ≥ 0 (metres) for `lights[1].radius`, found -3e38",
        ),
    ];
    for (good, bad, expected) in cases {
        let text = SCENE.replace(good, bad);
        let err = SceneDesc::from_str(&text, "lights.ron").unwrap_err().to_string();
        let expected = format!("lights.ron:{}: {expected}", value_at(&text, bad));
        assert!(err.starts_with(&expected), "{bad}:\n{err}\nexpected: {expected}");
    }
    // An unknown field and an unknown kind of light are parse errors that list what is known.
    let err = SceneDesc::from_str(&SCENE.replace("range: 5", "reach: 5"), "lights.ron")
        .unwrap_err()
        .to_string();
    let text = SCENE.replace("range: 5", "reach: 5");
    let expected = format!("lights.ron:{}: expected one of the fields ", value_at(&text, "reach"));
    assert!(err.starts_with(&expected), "{err}\nexpected: {expected}");
    assert!(
        err.contains("`range`") && err.contains("found unknown field `reach`"),
        "{err}"
    );
    // An unknown name, however long, is echoed cut to a bounded length.
    let long = "A".repeat(100_000);
    let err = SceneDesc::from_str(&SCENE.replace("Point(", &format!("{long}(")), "lights.ron")
        .unwrap_err()
        .to_string();
    assert!(err.len() < 600, "{} bytes: {}", err.len(), &err[..600.min(err.len())]);
    assert!(err.contains("... (99921 more characters)`"), "{err}");
    // Unless the light casts no shadow, which needs no view.
    let tiny = SCENE.replace("range: 5", "range: 0.01, shadows_enabled: false");
    assert!(SceneDesc::from_str(&tiny, "lights.ron").is_ok());
    let err = SceneDesc::from_str(&SCENE.replace("Point(", "Area("), "lights.ron")
        .unwrap_err()
        .to_string();
    let text = SCENE.replace("Point(", "Area(");
    let expected = format!(
        "lights.ron:{}: expected one of `Directional`, `Spot`, `Point`",
        value_at(&text, "Area(")
    );
    assert!(err.starts_with(&expected), "{err}\nexpected: {expected}");
}

#[test]
fn positional_lights_spawned_in_code_get_a_transform() {
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    let spot = app.world_mut().spawn(SpotLight::default()).id();
    let point = app.world_mut().spawn(PointLight::default()).id();
    app.update();
    let world = app.world();
    for e in [spot, point] {
        assert!(world.get::<Transform>(e).is_some());
        assert!(world.get::<GlobalTransform>(e).is_some());
    }
    let defaults = SpotLight::default();
    assert_eq!(defaults.outer_angle, std::f32::consts::FRAC_PI_4);
    let world = app.world_mut();
    assert_eq!(world.query_filtered::<(), With<SpotLight>>().iter(world).count(), 1);
}

const SPOT_SCENE: &str = r#"Scene(
    camera: (position: (0, 6, 12), target: (0, 0, 0), fov: 60, near: 0.1, far: 200),
    lights: [
        Spot(position: (0, 4, 0), direction: (0, -1, 0), outer_angle: 30, range: 10),
        Spot(position: (3, 3, 3), direction: (0, -1, 0), outer_angle: 20, range: 6),
        Spot(position: (60, 2, -80), direction: (0, -1, 0), outer_angle: 20, range: 3),
    ],
    materials: { "m": () },
    objects: [
        (shape: Plane(size: (200, 200)), material: "m", cast_shadows: false),
        (shape: Cuboid(size: (1, 1, 1)), material: "m", translation: (0, 0.5, 0)),
        (shape: Cuboid(size: (1, 1, 1)), material: "m", translation: (50, 0.5, 0)),
    ],
)"#;

#[test]
fn each_shadowed_spot_light_gets_a_view_with_the_casters_in_its_cone() {
    let app = app_with(SPOT_SCENE);
    let world = app.world();
    let views = world.resource::<penumbra::ecs::ShadowViews>();
    let lights = world.resource::<penumbra::ecs::FrameLights>();
    assert_eq!(views.views.len(), 3);
    assert_eq!(views.groups.len(), 3);
    assert!(
        views
            .views
            .iter()
            .all(|v| v.kind == penumbra::ecs::ShadowViewKind::SPOT)
    );
    // Each view belongs to one spot light (the scene has no sun, so light i is spot i).
    let spot_of = |i: usize| lights.spots[views.views[i].light as usize].shadow.unwrap();
    let by_range = |far: f32| {
        (0..3)
            .find(|&i| (spot_of(i).far - far).abs() < 1e-6)
            .unwrap_or_else(|| panic!("no view with range {far}"))
    };
    let (big, far) = (by_range(10.0), by_range(3.0));
    assert_eq!(
        views.groups[big].instance_count(),
        1,
        "the box under the light, not the far one"
    );
    assert_eq!(views.groups[far].instance_count(), 0, "nothing under the far light");
    let box_centre = Vec3::new(0.0, 0.5, 0.0);
    assert!(spot_of(big).frustum.contains_point(box_centre));
    assert!(!spot_of(big).frustum.contains_point(Vec3::new(50.0, 0.5, 0.0)));
}

#[test]
fn spot_lights_over_the_budget_are_named_and_the_smallest_lose_their_shadows() {
    let desc = SceneDesc::from_str(SPOT_SCENE, "spots.ron").unwrap();
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    app.world_mut()
        .resource_mut::<penumbra::ecs::ShadowLightBudget>()
        .lights
        .spot = 2;
    spawn_scene(app.world_mut(), &desc).unwrap();
    app.update();
    let world = app.world();
    let views = world.resource::<penumbra::ecs::ShadowViews>();
    let lights = world.resource::<penumbra::ecs::FrameLights>();
    assert_eq!(views.views.len(), 2);
    assert!(
        views
            .views
            .iter()
            .all(|v| lights.spots[v.light as usize].shadow.unwrap().far > 3.0),
        "the far, small light is dropped"
    );
    let warnings = &world.resource::<ShadowDiagnostics>().current;
    let dropped: Vec<&String> = warnings.iter().filter(|w| w.contains("gets no shadow")).collect();
    assert_eq!(dropped.len(), 1, "{warnings:?}");
    assert!(
        dropped[0].ends_with("only 2 shadowed spot lights fit the budget, and it is smaller on screen"),
        "{dropped:?}"
    );
}

#[test]
fn spot_lights_without_shadows_make_no_view() {
    let text = SPOT_SCENE.replace("range: 10)", "range: 10, shadows_enabled: false)");
    let app = app_with(&text);
    assert_eq!(app.world().resource::<penumbra::ecs::ShadowViews>().views.len(), 2);
}
