//! The custom-material example's shader: it composes with `penumbra::lights` for every
//! shipped forward variant, and when it replaces the forward shader its ink hatching lands where the
//! shipped shader finds shadow, and not where it finds sun.

use penumbra::app::{RenderRequest, headless_app, render_scene_with, spawn_scene};
use penumbra::render::Renderer;
use penumbra::scene::SceneDesc;
use penumbra::shader::{ForwardVariant, ShaderLibrary};

const SHADER: &str = include_str!("../examples/custom_material.wgsl");
const INSTALL: &str = "no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)";

#[test]
fn the_example_shader_composes_for_every_shipped_variant() {
    let mut library = ShaderLibrary::new().unwrap();
    for variant in ForwardVariant::all() {
        library
            .compose("custom_material.wgsl", SHADER, variant.shader_defs())
            .unwrap_or_else(|e| panic!("{}: {e}", variant.label()));
    }
}

#[test]
fn ink_hatching_follows_the_shadow() {
    let desc = SceneDesc::load("assets/scenes/pillars.ron").unwrap();
    let (width, height) = (192, 108);
    let tweak = |s: &mut penumbra::settings::ShadowSettings| s.filter.temporal_rotation = false;
    let reference = render_scene_with(
        &desc,
        &RenderRequest {
            width,
            height,
            frames: 1,
            tweak: Some(&tweak),
            analysis: true,
            options: Default::default(),
            shadow_budget: None,
            count_fragments: false,
            camera_lod: None,
            camera_motion: Default::default(),
        },
    )
    .expect(INSTALL);
    let analysis = reference.analysis.expect("analysis targets");

    let mut renderer = Renderer::headless(width, height).expect(INSTALL);
    renderer
        .set_forward_shader("custom_material.wgsl", SHADER)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut app = headless_app(renderer);
    let mut desc = desc.clone();
    tweak(&mut desc.shadows);
    spawn_scene(app.world_mut(), &desc).unwrap();
    app.update();
    let renderer = app.world().resource::<Renderer>();
    assert!(renderer.pipeline_error().is_none(), "{:?}", renderer.pipeline_error());
    let image = renderer.read_image();

    // The ink is linear (0, 0, 0.2): sRGB (0, 0, 124) in the image; nothing else is that blue.
    let ink = |p: &image::Rgba<u8>| p[0] == 0 && p[1] == 0 && (100..150).contains(&p[2]);
    let (mut shadow, mut shadow_ink, mut lit, mut lit_ink) = (0, 0, 0, 0);
    for (i, p) in image.pixels().enumerate() {
        if !analysis.evaluated[i] {
            continue;
        }
        match analysis.shadow[i] {
            v if v < 0.05 => {
                shadow += 1;
                shadow_ink += ink(p) as u32;
            }
            v if v > 0.95 => {
                lit += 1;
                lit_ink += ink(p) as u32;
            }
            _ => {}
        }
    }
    assert!(
        shadow > 200 && lit > 200,
        "too few pixels to judge: {shadow} shadowed, {lit} lit"
    );
    let in_shadow = shadow_ink as f64 / shadow as f64;
    let in_sun = lit_ink as f64 / lit as f64;
    // Two of every six diagonals are inked in shadow: about a third.
    assert!(in_shadow > 0.2, "ink covers only {in_shadow:.3} of the shadow");
    assert!(in_sun < 0.02, "ink covers {in_sun:.3} of the sunlit pixels");
}
