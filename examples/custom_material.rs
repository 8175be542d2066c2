//! A material of your own that receives penumbra's shadows.
//!
//! ```text
//! cargo run --release --example custom_material -- [scene.ron] [out.png]
//! ```
//!
//! The shader, `examples/custom_material.wgsl`, `#import`s `penumbra::lights` and loops over
//! the frame's lights, asking each for `shadow_visibility(light, surface)`: cel shading in
//! three bands, with ink hatching where a light is blocked. `Renderer::set_forward_shader`
//! composes and validates it (errors name the file and line) and puts it in place of the
//! shipped forward shader; every light kind and filter mode keeps working, because they live
//! behind the entry point. The image is written headless, with the frame's GPU timings.

use std::path::PathBuf;

use penumbra::app::{headless_app, spawn_scene};
use penumbra::render::Renderer;
use penumbra::scene::SceneDesc;

/// The material's shader source.
const SHADER: &str = include_str!("custom_material.wgsl");

fn main() {
    let mut args = std::env::args().skip(1);
    let scene = PathBuf::from(args.next().unwrap_or_else(|| "assets/scenes/default.ron".to_owned()));
    let out = PathBuf::from(args.next().unwrap_or_else(|| "out/custom_material.png".to_owned()));
    if let Err(e) = run(&scene, &out) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run(scene: &std::path::Path, out: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    let desc = SceneDesc::load(scene)?;
    let mut renderer = Renderer::headless(1280, 720)?;
    renderer.set_forward_shader("custom_material.wgsl", SHADER)?;
    let mut app = headless_app(renderer);
    spawn_scene(app.world_mut(), &desc)?;
    for _ in 0..3 {
        app.update();
    }
    let renderer = app.world().resource::<Renderer>();
    if let Some(error) = renderer.pipeline_error() {
        return Err(error.into());
    }
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    renderer.read_image().save(out)?;
    println!("wrote {} ({})", out.display(), renderer.gpu.describe());
    for pass in &renderer.last_report.passes {
        println!("  GPU {:<17} {:7.3} ms", pass.name, pass.ms);
    }
    Ok(())
}
