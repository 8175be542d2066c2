//! The inspector, driven headless through egui's accessibility tree (no window): edits made
//! with its widgets reach the sun's `ShadowSettings` and, on the next frame, the renderer's
//! resources; "save settings" writes a file that reads back equal.

use bevy_app::App;
use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use penumbra::app::{headless_app, spawn_scene};
use penumbra::ecs::Transform;
use penumbra::ecs::components::DirectionalLight;
use penumbra::ecs::{AnimationPlayer, ShadowViews};
use penumbra::layout::ShadowStorage;
use penumbra::render::{DeferredLighting, DepthPrepass, Msaa, RenderOptions, Renderer};
use penumbra::scene::{SceneDesc, load_settings};
use penumbra::settings::{ContactShadows, ShadowDebugView, ShadowMode, ShadowSettings};
use penumbra::viewer::{FrameInfo, Inspector};

struct State {
    app: App,
    inspector: Inspector,
    errors: Vec<String>,
}

fn state(name: &str) -> State {
    let renderer = Renderer::headless(64, 36)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = headless_app(renderer);
    let desc = SceneDesc::load("assets/scenes/default.ron").expect("default scene loads");
    spawn_scene(app.world_mut(), &desc).expect("default scene spawns");
    app.update();
    let path = std::env::temp_dir().join(format!("penumbra-inspector-{name}-{}.ron", std::process::id()));
    State {
        app,
        inspector: Inspector::new(path),
        errors: Vec::new(),
    }
}

fn harness(state: State) -> Harness<'static, State> {
    Harness::builder().with_size(egui::vec2(420.0, 1600.0)).build_ui_state(
        |ui, s: &mut State| {
            let info = FrameInfo {
                report: None,
                errors: &s.errors,
            };
            s.inspector.ui(ui, s.app.world_mut(), &info, None);
        },
        state,
    )
}

fn settings(h: &mut Harness<'_, State>) -> ShadowSettings {
    let world = h.state_mut().app.world_mut();
    *world.query::<&ShadowSettings>().single(world).unwrap()
}

fn renderer<'a>(h: &'a Harness<'_, State>) -> &'a Renderer {
    h.state().app.world().resource::<Renderer>()
}

/// The slider labelled `label` (its text label is a separate node).
fn slider<'a>(h: &'a Harness<'_, State>, label: &'a str) -> egui_kittest::Node<'a> {
    h.get_by_role_and_label(Role::Slider, label)
}

/// Opens the combo box labelled `combo` and picks `option`.
fn choose(h: &mut Harness<'_, State>, combo: &str, option: &str) {
    h.get_by_label(combo).click();
    h.run();
    h.get_by_label(option).click();
    h.run();
}

#[test]
fn mode_and_pcss_switches_reach_the_settings_and_the_renderer() {
    let mut state = state("mode");
    // NOTE: the lighting pass filters the shadows (so its pipelines follow the mode) where the
    // prepass does not run.
    state.app.insert_resource(RenderOptions {
        depth_prepass: DepthPrepass::Off,
        ..RenderOptions::default()
    });
    state.app.update();
    let mut h = harness(state);
    h.run();
    // The default scene starts with PCSS, so its pipelines exist.
    assert_eq!(settings(&mut h).filter.mode, ShadowMode::Pcss);
    let pcss_only = renderer(&h).counters().forward_pipelines;

    choose(&mut h, "mode", "PCF");
    assert_eq!(settings(&mut h).filter.mode, ShadowMode::Pcf);
    h.state_mut().app.update();
    let with_pcf = renderer(&h).counters().forward_pipelines;
    assert!(with_pcf > pcss_only, "no PCF pipeline was built after the switch");

    // Back to PCSS: the cached pipelines are reused, nothing is rebuilt.
    choose(&mut h, "mode", "PCSS");
    assert_eq!(settings(&mut h).filter.mode, ShadowMode::Pcss);
    h.state_mut().app.update();
    assert_eq!(renderer(&h).counters().forward_pipelines, with_pcf);

    // The PCSS-only controls are back; the early-out switch toggles.
    let early_out = settings(&mut h).filter.blocker_early_out;
    h.get_by_label("blocker early-out").click();
    h.run();
    assert_eq!(settings(&mut h).filter.blocker_early_out, !early_out);
}

#[test]
fn contact_shadows_turn_on_with_their_controls() {
    let mut h = harness(state("contact"));
    h.run();
    assert!(!settings(&mut h).filter.contact.enabled());
    assert!(
        h.query_by_label("contact steps").is_none(),
        "contact controls shown while off"
    );
    h.get_by_label("contact shadows").click();
    h.run();
    assert_eq!(settings(&mut h).filter.contact, ContactShadows::ON);
    slider(&h, "contact steps").set_value_accesskit(8.0);
    h.run();
    assert_eq!(settings(&mut h).filter.contact.steps, 8);
    choose(&mut h, "debug view", "contact shadows alone");
    assert_eq!(settings(&mut h).filter.debug_view, ShadowDebugView::Contact);
    // The frame renders with them (the prepass and the resolve turned on for the march).
    h.state_mut().app.update();
    assert!(
        renderer(&h).last_report.resolved_memory > 0,
        "no resolve target for the march"
    );
}

#[test]
fn resolution_recreates_the_shadow_map_and_cascade_count_nothing() {
    let mut h = harness(state("resolution"));
    h.run();
    let before = renderer(&h).counters();

    slider(&h, "cascades").set_value_accesskit(2.0);
    h.run();
    assert_eq!(settings(&mut h).map.cascades.count, 2);
    h.state_mut().app.update();
    assert_eq!(h.state().app.world().resource::<ShadowViews>().views.len(), 2);
    assert_eq!(
        renderer(&h).counters(),
        before,
        "the cascade count rebuilt a GPU resource"
    );

    choose(&mut h, "resolution", "1024");
    assert_eq!(settings(&mut h).map.resolution, 1024);
    h.state_mut().app.update();
    assert_eq!(renderer(&h).storage_resolution(ShadowStorage::Cascades), Some(1024));
    assert_eq!(renderer(&h).counters().shadow_maps, before.shadow_maps + 1);
}

#[test]
fn sliders_move_the_sun_and_the_split() {
    let mut h = harness(state("sun"));
    h.run();
    let world = h.state_mut().app.world_mut();
    let before = world
        .query::<(&DirectionalLight, &Transform)>()
        .single(world)
        .unwrap()
        .1
        .forward();

    slider(&h, "elevation °").set_value_accesskit(80.0);
    slider(&h, "angular diameter °").set_value_accesskit(2.0);
    slider(&h, "split λ").set_value_accesskit(0.25);
    h.run();
    let world = h.state_mut().app.world_mut();
    let (light, transform) = world.query::<(&DirectionalLight, &Transform)>().single(world).unwrap();
    let forward = transform.forward();
    assert!(
        (forward.y + 80_f32.to_radians().sin()).abs() < 1e-3,
        "{before} -> {forward}"
    );
    assert!((light.angular_diameter.to_degrees() - 2.0).abs() < 1e-3);
    assert!((settings(&mut h).map.cascades.split_lambda - 0.25).abs() < 1e-6);
}

#[test]
fn the_memory_budget_slider_lowers_the_maps_and_the_account_shows_it() {
    let mut h = harness(state("memory"));
    h.run();
    // 16-bit depth (the default): 2 bytes a texel.
    assert!(h.query_by_label("directional light sun: 4 × 2048², 32.0 MiB").is_some());
    // 8 MiB holds four cascades of 1024².
    slider(&h, "budget MiB").set_value_accesskit(8.0);
    h.run();
    h.state_mut().app.update();
    h.run();
    assert_eq!(renderer(&h).storage_resolution(ShadowStorage::Cascades), Some(1024));
    assert!(
        h.query_by_label("directional light sun: 4 × 1024² (asked 2048²), 8.0 MiB")
            .is_some()
    );
    assert!(h.query_by_label_contains("8.0 MiB of a 8.0 MiB budget").is_some());
}

#[test]
fn statistics_errors_and_save_are_shown() {
    let mut s = state("save");
    s.errors.push("scene.ron:3:7: expected a number".to_owned());
    let mut h = harness(s);
    h.run();
    // One row per shadow view with its range and texel density.
    assert!(h.query_by_label("texels/m").is_some());
    assert!(h.query_by_label("range m").is_some());
    assert!(h.query_by_label("cascade 0").is_some());
    assert!(h.query_by_label("cascade 3").is_some());
    assert!(h.query_by_label("scene.ron:3:7: expected a number").is_some());

    choose(&mut h, "debug view", "cascade colours");
    assert_eq!(settings(&mut h).filter.debug_view, ShadowDebugView::Cascades);
    h.get_by_label("save settings").click();
    h.run();
    let path = h.state().inspector.settings_path.clone();
    let saved = load_settings(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(saved, settings(&mut h));
    assert!(h.query_by_label_contains("saved to").is_some());
    let _ = std::fs::remove_file(path);
}

#[test]
fn a_spot_light_panel_edits_the_light_and_gives_it_settings() {
    use penumbra::ecs::SpotLight;

    let mut s = state("spot");
    let world = s.app.world_mut();
    world.spawn((
        SpotLight::default(),
        Transform::from_xyz(0.0, 4.0, 0.0).looking_to(-glam::Vec3::Y, glam::Vec3::Z),
    ));
    s.app.update();
    let mut h = harness(s);
    h.run();
    // Collapsed by default, so the sun's controls stay the only ones with their labels.
    h.get_by_label("spot light 0").click();
    h.run();
    slider(&h, "outer angle °").set_value_accesskit(30.0);
    h.run();
    let world = h.state_mut().app.world_mut();
    let spot = *world.query::<&SpotLight>().single(world).unwrap();
    assert!(
        (spot.outer_angle - 30f32.to_radians()).abs() < 1e-4,
        "{}",
        spot.outer_angle
    );
    // The light had no settings; editing its filter gives it some, at the budget resolution.
    // The spot panel comes after the sun's settings, so its slider is the last of the name.
    h.get_all_by_role_and_label(Role::Slider, "normal offset")
        .last()
        .expect("a normal offset slider")
        .set_value_accesskit(2.0);
    h.run();
    let world = h.state_mut().app.world_mut();
    let mut q = world.query_filtered::<&ShadowSettings, bevy_ecs::query::With<SpotLight>>();
    let settings = *q.single(world).expect("the spot light got its own settings");
    assert_eq!(settings.bias.normal_offset, 2.0);
    assert_eq!(settings.map.resolution, 1024);
    // Its shadow is drawn on the next frame.
    h.state_mut().app.update();
    let views = h.state().app.world().resource::<ShadowViews>();
    assert_eq!(
        views
            .views
            .iter()
            .filter(|v| v.kind == penumbra::ecs::ShadowViewKind::SPOT)
            .count(),
        1
    );
}

#[test]
fn a_point_light_panel_switches_its_filter_to_vsm_and_edits_the_blur() {
    use penumbra::ecs::PointLight;

    let mut s = state("point");
    s.app
        .world_mut()
        .spawn((PointLight::default(), Transform::from_xyz(0.0, 3.0, 0.0)));
    s.app.update();
    let mut h = harness(s);
    h.run();
    h.get_by_label("point light 0").click();
    h.run();
    slider(&h, "radius m").set_value_accesskit(0.25);
    h.run();
    // The point panel comes after the sun's settings, so its mode box is the last of the name.
    h.get_all_by_label("mode").last().expect("a mode box").click();
    h.run();
    h.get_by_label("VSM").click();
    h.run();
    slider(&h, "VSM blur (texels)").set_value_accesskit(5.0);
    h.run();
    let world = h.state_mut().app.world_mut();
    let (light, settings) = world
        .query::<(&PointLight, &ShadowSettings)>()
        .single(world)
        .expect("the point light got its own settings");
    assert_eq!(light.radius, 0.25);
    assert_eq!((settings.filter.mode, settings.filter.vsm.blur), (ShadowMode::Vsm, 5));
    assert_eq!(settings.map.resolution, 512, "the budget's point resolution");
    // Its six faces are drawn on the next frame.
    h.state_mut().app.update();
    let views = h.state().app.world().resource::<ShadowViews>();
    let faces = views
        .views
        .iter()
        .filter(|v| v.kind.storage == penumbra::layout::ShadowStorage::Points)
        .count();
    assert_eq!(faces, 6);
}

#[test]
fn render_switches_reach_the_render_options() {
    let mut h = harness(state("render-options"));
    h.run();
    let options = |h: &Harness<'_, State>| *h.state().app.world().resource::<RenderOptions>();
    let before = options(&h);
    for label in ["shadow cache", "compute resolve", "single-pass cascades"] {
        h.get_by_label(label).click();
        h.run();
    }
    let after = options(&h);
    assert_eq!(after.shadow_cache, !before.shadow_cache);
    assert_eq!(after.visibility_resolve, !before.visibility_resolve);
    assert_eq!(after.single_pass_cascades, !before.single_pass_cascades);
    // Two rows of auto / on / off: the depth prepass's, then the deferred lighting's.
    h.get_all_by_label("off").next().expect("the prepass's off").click();
    h.run();
    assert_eq!(options(&h).depth_prepass, DepthPrepass::Off);
    assert_eq!(
        before.deferred_lighting,
        DeferredLighting::Auto,
        "deferred lighting on auto by default"
    );
    h.get_all_by_label("off")
        .last()
        .expect("the deferred lighting's off")
        .click();
    h.run();
    assert_eq!(options(&h).deferred_lighting, DeferredLighting::Off);
    assert_eq!(before.msaa, Msaa::Off, "MSAA off by default");
    h.get_by_label("4×").click();
    h.run();
    assert_eq!(options(&h).msaa, Msaa::Sample4);
    // The renderer draws with them: without the cache every cascade is drawn each frame.
    h.state_mut().app.update();
    h.state_mut().app.update();
    assert_eq!(renderer(&h).last_report.shadow_views_drawn, 4);
}

#[test]
fn the_animation_section_pauses_and_speeds_every_walker() {
    let mut s = state("animation");
    let desc = SceneDesc::load("assets/scenes/walkers.ron").expect("walkers scene loads");
    spawn_scene(s.app.world_mut(), &desc).expect("walkers spawn");
    s.app.update();
    let mut h = harness(s);
    h.run();
    h.get_by_label("Animation").click();
    h.run();
    h.get_by_label("play (12 animated meshes)").click();
    h.run();
    slider(&h, "animation speed").set_value_accesskit(2.0);
    h.run();
    let world = h.state_mut().app.world_mut();
    let players: Vec<AnimationPlayer> = world.query::<&AnimationPlayer>().iter(world).copied().collect();
    assert_eq!(players.len(), 12);
    assert!(players.iter().all(|p| p.paused && p.speed == 2.0), "{players:?}");
}
