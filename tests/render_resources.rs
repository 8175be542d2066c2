//! What settings changes and shader swaps rebuild on the GPU: a new shadow resolution
//! recreates only the shadow map (and the bind group that samples it), a new cascade count
//! recreates nothing, and a forward shader that fails keeps the last good pipeline.

use bevy_app::App;
use image::RgbaImage;
use penumbra::app::{headless_app, spawn_scene};
use penumbra::layout::ShadowStorage;
use penumbra::render::{DeferredLighting, RenderOptions, Renderer};
use penumbra::scene::SceneDesc;
use penumbra::settings::ShadowSettings;

fn app() -> App {
    let renderer = Renderer::headless(96, 54)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = headless_app(renderer);
    // NOTE: the forward pass draws every material, so a replaced forward shader (which turns
    // the deferred lighting off) draws the same pixels as the shipped one did.
    app.insert_resource(RenderOptions {
        deferred_lighting: DeferredLighting::Off,
        ..RenderOptions::default()
    });
    let desc = SceneDesc::load("assets/scenes/default.ron").expect("default scene loads");
    spawn_scene(app.world_mut(), &desc).expect("default scene spawns");
    // Frames must be identical for the image comparisons below.
    settings(&mut app, |s| s.filter.temporal_rotation = false);
    app.update();
    app
}

/// Asserts two images are equal without printing them.
fn assert_same(a: &RgbaImage, b: &RgbaImage, what: &str) {
    let differing = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
    assert!(differing == 0, "{what}: {differing} pixels differ");
}

fn settings(app: &mut App, edit: impl Fn(&mut ShadowSettings)) {
    let world = app.world_mut();
    let mut q = world.query::<&mut ShadowSettings>();
    for mut s in q.iter_mut(world) {
        edit(&mut s);
    }
}

fn renderer(app: &App) -> &Renderer {
    app.world().resource::<Renderer>()
}

fn image(app: &App) -> RgbaImage {
    renderer(app).read_image()
}

#[test]
fn cascade_count_recreates_nothing_and_resolution_only_the_shadow_map() {
    let mut app = app();
    app.update();
    let before = renderer(&app).counters();
    assert_eq!(before.shadow_maps, 1, "{before:?}");
    assert_eq!(renderer(&app).storage_resolution(ShadowStorage::Cascades), Some(2048));

    settings(&mut app, |s| s.map.cascades.count = 2);
    app.update();
    app.update();
    assert_eq!(
        renderer(&app).counters(),
        before,
        "a new cascade count rebuilt something"
    );

    settings(&mut app, |s| s.map.resolution = 1024);
    app.update();
    let after = renderer(&app).counters();
    assert_eq!(renderer(&app).storage_resolution(ShadowStorage::Cascades), Some(1024));
    assert_eq!(after.shadow_maps, before.shadow_maps + 1);
    // Both shadow bind groups sample the maps: the resolve's and the lighting pass's (which
    // also binds the resolved visibility).
    assert_eq!(after.shadow_groups, before.shadow_groups + 2);
    assert_eq!(after.forward_pipelines, before.forward_pipelines);
    assert_eq!(after.caster_pipelines, before.caster_pipelines);
}

/// A forward shader that replaces the lighting with a flat colour, keeping the interface.
const FLAT: &str = r#"
#import penumbra::frame::frame
#import penumbra::mesh::{fetch_instance, instance_position}

struct VertexOutput {
    @builtin(position) clip_position: vec4<f32>,
}

@vertex
fn vs_main(@builtin(instance_index) instance_index: u32, @location(0) position: vec3<f32>) -> VertexOutput {
    let instance = fetch_instance(instance_index);
    var out: VertexOutput;
    out.clip_position = frame.clip_from_world * vec4<f32>(instance_position(instance, position), 1.0);
    return out;
}

@fragment
fn fs_main(in: VertexOutput) -> @location(0) vec4<f32> {
    return vec4<f32>(1.0, 0.0, 1.0, 1.0);
}
"#;

#[test]
fn a_broken_forward_shader_is_rejected_and_the_last_good_pipeline_keeps_drawing() {
    let mut app = app();
    let good = image(&app);

    // Does not parse: rejected up front, with the file and the problem.
    let err = app
        .world_mut()
        .resource_mut::<Renderer>()
        .set_forward_shader("my_material.wgsl", "fn fs_main( {")
        .expect_err("a shader that does not parse is rejected");
    let text = err.to_string();
    assert!(text.contains("my_material.wgsl"), "{text}");
    app.update();
    assert_same(&image(&app), &good, "the rejected shader changed the image");

    // Parses and validates, but its bindings do not match the pipeline layout: the build
    // fails on the device, the error is reported and the previous pipeline keeps drawing.
    let mismatched = FLAT
        .replace(
            "@fragment",
            "@group(3) @binding(9) var<uniform> extra: vec4<f32>;\n@fragment",
        )
        .replace("return vec4<f32>(1.0, 0.0, 1.0, 1.0);", "return extra;");
    app.world_mut()
        .resource_mut::<Renderer>()
        .set_forward_shader("mismatched.wgsl", &mismatched)
        .expect("the mismatched shader composes and validates");
    app.update();
    let error = renderer(&app).pipeline_error().expect("the pipeline error is reported");
    assert!(error.contains("forward pipeline"), "{error}");
    assert_same(&image(&app), &good, "a failed pipeline build changed the image");

    // A good replacement takes over.
    app.world_mut()
        .resource_mut::<Renderer>()
        .set_forward_shader("flat.wgsl", FLAT)
        .expect("the flat shader is accepted");
    app.update();
    assert!(renderer(&app).pipeline_error().is_none());
    let flat = image(&app);
    let magenta = flat.pixels().filter(|p| p.0 == [255, 0, 255, 255]).count();
    assert!(magenta > flat.len() / 4 / 4, "only {magenta} magenta pixels");

    app.world_mut().resource_mut::<Renderer>().reset_forward_shader();
    app.update();
    assert_same(&image(&app), &good, "resetting did not restore the shipped shader");
}
