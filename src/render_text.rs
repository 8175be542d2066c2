//! `penumbra render`'s text summary (part of the `penumbra` binary): the scene, the adapter,
//! the shadow account, draw calls, the work the shadow passes did each frame, CPU times and
//! each GPU pass's median time and the whole frames' spread.

use std::path::Path;

use penumbra::app::HeadlessFrame;
use penumbra::math::light_budget::LightKind;
use penumbra::render::timer::{frame_spread, median_passes};
use penumbra::settings::ShadowSettings;
use penumbra::text::format_bytes;

/// Prints the summary of a headless render of `scene` into `out` (`size`: width, height,
/// frames); `(sun, s)`: whether the scene has a sun, and the settings it was rendered with.
pub fn print_summary(
    scene: &Path,
    out: &Path,
    (width, height, frames): (u32, u32, u32),
    (sun, s): (bool, &ShadowSettings),
    result: &HeadlessFrame,
) {
    println!("scene      {}", scene.display());
    println!("commit     {}", penumbra::BUILD_COMMIT);
    println!("adapter    {}", result.adapter);
    println!(
        "image      {} ({}x{}, {} frames)",
        out.display(),
        width,
        height,
        frames.max(1)
    );
    println!(
        "instances  {} ({} visible)",
        result.instances, result.stats.visible_instances
    );
    // NOTE: the scene's `shadows` are the sun's; a scene without a sun (spot lights only)
    // says nothing about cascades.
    let sun_side = result.memory.lights.iter().find(|l| l.kind == LightKind::Directional);
    let cascades = if sun {
        format!(
            ", sun {:?} with {}² texels per cascade",
            s.filter.mode.effective(true),
            sun_side.map_or(s.map.resolution, |l| l.granted)
        )
    } else {
        String::new()
    };
    println!(
        "shadows    {} shadow views{cascades}, {}",
        result.stats.casters_per_view.len(),
        format_bytes(result.report.shadow_memory)
    );
    for (i, line) in result.memory.lines().iter().enumerate() {
        println!("{} {line}", if i == 0 { "memory    " } else { "          " });
    }
    let casters: Vec<String> = result.stats.casters_per_view.iter().map(|c| c.to_string()).collect();
    let draws: Vec<String> = result.stats.draws_per_view.iter().map(|c| c.to_string()).collect();
    println!(
        "casters    per view [{}], draws per view [{}]",
        casters.join(", "),
        draws.join(", ")
    );
    let report = &result.report;
    println!(
        "draw calls {} ({} shadow; {} draws), shadow texels cleared {:.2} M (last frame)",
        report.draw_calls,
        report.shadow_draw_calls,
        report.draws,
        report.shadow_cleared_texels as f64 / 1e6
    );
    if let Some(n) = result.report.forward_fragments {
        let pixels = u64::from(width) * u64::from(height);
        println!(
            "fragments {n} lighting-pass invocations, {:.3} per pixel of the image",
            n as f64 / pixels.max(1) as f64
        );
    }
    let drawn: Vec<String> = result.frames.iter().map(|f| f.shadow_views_drawn.to_string()).collect();
    println!("shadow views drawn per frame [{}]", drawn.join(", "));
    print_pages(&result.frames, result.memory.pages);
    if result.frames.iter().any(|f| f.occlusion_drawn.is_some()) {
        let drawn: Vec<String> = (result.frames.iter())
            .map(|f| f.occlusion_drawn.map_or("-".to_owned(), |(e, l)| format!("{e}+{l}")))
            .collect();
        println!(
            "occlusion  instances drawn early+late per frame [{}] of {} in the frustum",
            drawn.join(", "),
            result.stats.visible_instances
        );
    }
    if result.frames.iter().any(|f| f.skinned_meshes_posed > 0) {
        let posed: Vec<String> = result
            .frames
            .iter()
            .map(|f| f.skinned_meshes_posed.to_string())
            .collect();
        println!("skinned meshes posed per frame [{}]", posed.join(", "));
    }
    let kept = result.frames.iter().filter(|f| f.prepass_kept).count();
    if kept > 0 {
        println!(
            "depth prepass kept from the frame before in {kept} of {} frames",
            result.frames.len()
        );
    }
    if result.frames.iter().any(|f| f.shadow_views_scrolled > 0) {
        let texels: Vec<String> = (result.frames.iter())
            .map(|f| format!("{} ({} scrolled)", f.shadow_drawn_texels, f.shadow_views_scrolled))
            .collect();
        println!("shadow texels drawn per frame [{}]", texels.join(", "));
    }
    println!(
        "cpu        cascades {:.3} ms, culling {:.3} ms, view culling {:.3} ms (last frame)",
        result.stats.cascades_cpu.as_secs_f64() * 1e3,
        result.stats.culling_cpu.as_secs_f64() * 1e3,
        result.stats.view_culling_cpu.as_secs_f64() * 1e3
    );
    if let Some(ms) = result.median_frame_cpu_ms() {
        println!("cpu        shadow systems {ms:.3} ms per frame (median; propagation to culling)");
    }
    let passes: Vec<Vec<_>> = result.frames.iter().map(|f| f.passes.clone()).collect();
    let medians = median_passes(&passes);
    if medians.is_empty() {
        println!("gpu        (the adapter has no timestamp queries)");
    }
    for (name, ms) in &medians {
        println!("gpu        {name:<17} {ms:8.3} ms");
    }
    if !medians.is_empty() {
        println!(
            "gpu        {:<17} {:8.3} ms",
            "total",
            medians.iter().map(|m| m.1).sum::<f64>()
        );
    }
    if let Some(s) = frame_spread(&passes) {
        println!(
            "gpu        frames: median {:.3} ms, mean {:.3} ms, slowest {:.3} ms ({} frames)",
            s.median, s.mean, s.max, s.frames
        );
    }
    for w in &result.warnings {
        println!("warning    {w}");
    }
}

/// Prints what a paged sun's pages did each frame, and its pool's memory (depth and any
/// moments; nothing without a paged sun).
fn print_pages(frames: &[penumbra::render::FrameReport], pool_bytes: u64) {
    let pages: Vec<_> = frames.iter().filter_map(|f| f.pages).collect();
    let Some(last) = pages.last() else {
        return;
    };
    println!(
        "pages      pool {} pages, {} ({} resident after the last frame)",
        last.pool,
        format_bytes(pool_bytes),
        last.resident
    );
    let each: Vec<String> = pages
        .iter()
        .map(|p| format!("{}/{}/{}/{}", p.needed, p.drawn, p.evicted, p.overflowed))
        .collect();
    println!(
        "pages      needed/drawn/evicted/overflowed per frame [{}]",
        each.join(", ")
    );
    if pages.iter().any(|p| p.overflowed > 0) {
        println!("warning    the page pool overflowed: pixels read a coarser level (raise --pool-pages)");
    }
}
