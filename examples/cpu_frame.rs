//! Runs the shadow systems (no GPU) on a scene file for a number of frames and prints the
//! CPU time of cascades, per-cascade culling and camera culling: the per-frame CPU cost a
//! scene puts on the main thread.
//!
//! Run with `cargo run --release --example cpu_frame -- assets/scenes/field.ron`.

use bevy_app::App;
use penumbra::app::spawn_scene;
use penumbra::ecs::{ShadowPlugin, ShadowStats};
use penumbra::scene::SceneDesc;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "assets/scenes/field.ron".to_string());
    let desc = SceneDesc::load(&path)?;
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    let instances = spawn_scene(app.world_mut(), &desc)?;
    let frames = 200;
    let (mut cascades, mut culling, mut view) = (Vec::new(), Vec::new(), Vec::new());
    for frame in 0..frames + 3 {
        app.update();
        let stats = app.world().resource::<ShadowStats>();
        if frame >= 3 {
            cascades.push(stats.cascades_cpu.as_secs_f64() * 1e3);
            culling.push(stats.culling_cpu.as_secs_f64() * 1e3);
            view.push(stats.view_culling_cpu.as_secs_f64() * 1e3);
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let stats = app.world().resource::<ShadowStats>();
    println!(
        "{path}: {instances} instances, casters per shadow view {:?}",
        stats.casters_per_view
    );
    println!(
        "median over {frames} frames: cascades {:.3} ms, caster culling {:.3} ms, camera culling {:.3} ms",
        median(&mut cascades),
        median(&mut culling),
        median(&mut view)
    );
    Ok(())
}
