//! Deferred lighting of the prepass's pixels (lavapipe): on scenes that mix untextured,
//! textured, alpha-masked, double-sided and transmitting materials, under a sun, spot and point
//! lights and the storage list of lights past the uniform one, the image lit from the prepass
//! (in compute, into the headless target's storage view) equals the image drawn whole by the
//! lighting pass within one level per channel, and the lighting pass then draws only the
//! batches of the other materials; a target without a storage view (a window's) is lit by the
//! full-screen render pass to the same image; it is not used where it cannot reproduce the
//! forward shader (a material's own shader, MSAA) or has nothing to light (no untextured material).

mod common;

use bevy_app::App;
use bevy_ecs::world::Mut;
use common::{INSTALL, still_scene};
use image::RgbaImage;
use penumbra::app::{headless_app, spawn_scene};
use penumbra::render::frame_inputs::FrameInputs;
use penumbra::render::target::{TargetViews, read_texture, texture_2d};
use penumbra::render::{DeferredLighting, Msaa, RenderOptions, Renderer};
use penumbra::scene::{AlphaMode, SceneDesc};

const SIZE: (u32, u32) = (320, 180);

/// `scene` rendered for two frames with deferred lighting `deferred` (and `msaa`).
fn render(scene: &str, deferred: DeferredLighting, msaa: Msaa) -> App {
    let renderer = Renderer::headless(SIZE.0, SIZE.1).expect(INSTALL);
    let mut app = still_scene(renderer, scene);
    app.insert_resource(RenderOptions {
        deferred_lighting: deferred,
        msaa,
        ..RenderOptions::default()
    });
    app.update();
    app.update();
    app
}

fn renderer(app: &App) -> &Renderer {
    app.world().resource::<Renderer>()
}

/// Whether the last frame recorded the deferred lighting pass: its report says so, and its
/// GPU timings hold the pass. The timings are waited for: the report's pass list is the newest
/// frame whose timings had arrived, on lavapipe now and then still none after two frames.
fn deferred_ran(app: &mut App) -> bool {
    let mut renderer = app.world_mut().resource_mut::<Renderer>();
    let flagged = renderer.last_report.deferred_lighting;
    let timings = renderer.wait_for_timings();
    let last = timings.last().expect("the frames' timings");
    let timed = last.passes.iter().any(|p| p.name == "deferred lighting");
    assert_eq!(
        flagged, timed,
        "frame {}: the report says the deferred lighting ran: {flagged}, its timings: {timed}",
        last.frame
    );
    flagged
}

/// The largest difference of any channel, and how many pixels differ by more than one level.
fn difference(a: &RgbaImage, b: &RgbaImage) -> (u8, usize) {
    let mut largest = 0;
    let mut over_one = 0;
    for (p, q) in a.pixels().zip(b.pixels()) {
        let d = (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap_or(0);
        largest = largest.max(d);
        over_one += usize::from(d > 1);
    }
    (largest, over_one)
}

/// Pixels that are not the clear colour (something was drawn there).
fn drawn_pixels(image: &RgbaImage) -> usize {
    let sky = image.get_pixel(0, 0);
    image.pixels().filter(|p| *p != sky).count()
}

#[test]
fn the_image_lit_from_the_prepass_equals_the_forward_image() {
    // default: untextured boxes and ground, alpha-masked textured foliage; garden: glTF ferns,
    // masked and double-sided; lights: the storage list of lights; point and spot: cube and
    // spot shadows; thin: transmitting double-sided leaves; field: untextured only.
    let scenes = ["default", "garden", "lights", "point", "spot", "thin", "field"];
    for name in scenes {
        let scene = format!("assets/scenes/{name}.ron");
        let mut deferred = render(&scene, DeferredLighting::On, Msaa::Off);
        let mut forward = render(&scene, DeferredLighting::Off, Msaa::Off);
        assert!(
            deferred_ran(&mut deferred),
            "{name}: the deferred lighting did not run ({:?})",
            renderer(&deferred).pipeline_error()
        );
        assert!(
            !deferred_ran(&mut forward),
            "{name}: the deferred lighting ran while turned off"
        );
        let (a, b) = (renderer(&deferred).read_image(), renderer(&forward).read_image());
        let (largest, over_one) = difference(&a, &b);
        let drawn = drawn_pixels(&b);
        let (draws_deferred, draws_forward) = (
            renderer(&deferred).last_report.draws,
            renderer(&forward).last_report.draws,
        );
        println!(
            "{name}: {drawn} of {} pixels drawn; largest difference {largest}, {over_one} pixels over 1; draws {draws_forward} → {draws_deferred}",
            a.width() * a.height()
        );
        assert!(drawn > 10_000, "{name}: only {drawn} pixels drawn to compare");
        assert!(
            largest <= 1 && over_one == 0,
            "{name}: differs by up to {largest} ({over_one} pixels over 1)"
        );
        assert!(
            draws_deferred < draws_forward,
            "{name}: the lighting pass drew {draws_deferred} draws with deferred lighting, {draws_forward} without"
        );
    }
}

#[test]
fn a_material_shader_of_its_own_or_msaa_turns_it_off() {
    let scene = "assets/scenes/default.ron";
    assert!(
        !deferred_ran(&mut render(scene, DeferredLighting::On, Msaa::Sample4)),
        "ran under MSAA"
    );
    let mut renderer = Renderer::headless(SIZE.0, SIZE.1).expect(INSTALL);
    renderer
        .set_forward_shader("custom_material.wgsl", include_str!("../examples/custom_material.wgsl"))
        .unwrap_or_else(|e| panic!("{e}"));
    let mut app = still_scene(renderer, scene);
    app.update();
    assert!(!deferred_ran(&mut app), "ran with a material's own forward shader");
    assert!(self::renderer(&app).pipeline_error().is_none());
}

/// Checks that a scene whose materials are all textured (nothing for the prepass to light)
/// does not run the deferred lighting even when asked to, and is still drawn.
#[test]
fn a_scene_without_untextured_materials_does_not_run_it() {
    let mut desc = SceneDesc::load("assets/scenes/default.ron").expect("the default scene");
    for m in &mut desc.materials {
        m.texture = Some("../textures/foliage.png".into());
        m.alpha = AlphaMode::Opaque;
    }
    let mut app = headless_app(Renderer::headless(SIZE.0, SIZE.1).expect(INSTALL));
    spawn_scene(app.world_mut(), &desc).expect("the scene spawns");
    app.insert_resource(RenderOptions {
        deferred_lighting: DeferredLighting::On,
        ..RenderOptions::default()
    });
    app.update();
    app.update();
    assert!(!deferred_ran(&mut app), "ran without an untextured material");
    let drawn = drawn_pixels(&renderer(&app).read_image());
    println!("{drawn} pixels drawn");
    assert!(drawn > 10_000, "only {drawn} pixels drawn");
}

/// The next frame of `app` rendered into a plain sRGB texture of its own, which has no storage
/// view (as a window's swapchain image): the deferred lighting draws a full-screen triangle.
fn render_without_storage(app: &mut App) -> RgbaImage {
    let (width, height) = SIZE;
    app.world_mut().resource_scope(|world, mut renderer: Mut<Renderer>| {
        let device = renderer.gpu.device.clone();
        let format = wgpu::TextureFormat::Rgba8UnormSrgb;
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let texture = texture_2d(&device, "window-like target", (width, height, 1), format, usage);
        let target = TargetViews::for_color(texture.create_view(&Default::default()), format, width, height);
        renderer.render_to(&FrameInputs::from_world(world, 2), &target, &mut |_, _| {});
        assert!(
            renderer.last_report.deferred_lighting,
            "the full-screen deferred lighting did not run"
        );
        let pixels = read_texture(&device, &renderer.gpu.queue, &texture, 4);
        RgbaImage::from_raw(width, height, pixels).expect("a whole image")
    })
}

#[test]
fn a_target_without_a_storage_view_is_lit_by_a_full_screen_pass_to_the_same_image() {
    for name in ["default", "field"] {
        let scene = format!("assets/scenes/{name}.ron");
        let mut deferred = render(&scene, DeferredLighting::On, Msaa::Off);
        let compute = renderer(&deferred).read_image();
        let fragment = render_without_storage(&mut deferred);
        let forward = renderer(&render(&scene, DeferredLighting::Off, Msaa::Off)).read_image();
        let drawn = drawn_pixels(&forward);
        assert!(drawn > 10_000, "{name}: only {drawn} pixels drawn to compare");
        for (what, image) in [("full-screen pass", &fragment), ("compute pass", &compute)] {
            let (largest, over_one) = difference(image, &forward);
            println!(
                "{name}, {what} against the forward image: largest difference {largest}, {over_one} pixels over 1 ({drawn} drawn)"
            );
            assert!(
                largest <= 1 && over_one == 0,
                "{name}, {what}: differs by up to {largest} ({over_one} pixels over 1)"
            );
        }
    }
}
