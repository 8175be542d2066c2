//! The million-caster bench scene (`assets/bench/million.ron`) renders on software Vulkan
//! (lavapipe, whose storage bindings hold 128 MiB: its 999 995 instances take 80 bytes each),
//! its cascades culled on the GPU, and its image with shadows culled on the GPU equals the
//! image with every view culled on the CPU, pixel for pixel.

mod common;

use common::still_frame;
use penumbra::app::HeadlessFrame;
use penumbra::render::RenderOptions;
use penumbra::scene::SceneDesc;

/// One 64×36 frame of the million, culled on the GPU (`gpu_culling`) or on the CPU.
fn render(gpu_culling: bool) -> HeadlessFrame {
    let desc = SceneDesc::load("assets/bench/million.ron").expect("the million scene");
    let options = RenderOptions {
        gpu_culling,
        ..RenderOptions::default()
    };
    still_frame(&desc, (64, 36), options, false)
}

#[test]
fn the_million_renders_alike_culled_on_the_gpu_and_on_the_cpu() {
    let (gpu, cpu) = (render(true), render(false));
    assert_eq!(gpu.instances, 999_995, "every caster spawned");
    assert!(gpu.warnings.is_empty(), "warnings: {:?}", gpu.warnings);
    let listed: u32 = gpu.stats.casters_per_view.iter().sum();
    eprintln!(
        "{} shadow views drawn, {listed} run casters, {} visible instances; the CPU listed {:?}",
        gpu.report.shadow_views_drawn, gpu.stats.visible_instances, cpu.stats.casters_per_view
    );
    assert_eq!(gpu.report.shadow_views_drawn, 4, "the four cascades are drawn");
    assert!(listed > 100_000, "only {listed} casters in the cascades' runs");
    // NOTE: the image judges shadows: the ground holds both lit and shadowed pixels.
    let luma = |p: &image::Rgba<u8>| (u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2])) / 3;
    let (dark, bright) = gpu.image.pixels().fold((0, 0), |(d, b), p| match luma(p) {
        l if l < 60 => (d + 1, b),
        l if l > 120 => (d, b + 1),
        _ => (d, b),
    });
    eprintln!("{dark} dark and {bright} bright pixels of 2 304");
    // Measured: 232 dark and 2 036 bright.
    assert!(dark > 77 && bright > 678, "{dark} dark, {bright} bright pixels");
    let differing = gpu
        .image
        .pixels()
        .zip(cpu.image.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(differing, 0, "{differing} pixels differ between GPU and CPU culling");
}
