//! `penumbra render --json` (part of the `penumbra` binary): what the text summary prints, as
//! one JSON object on stdout, for scripts that collect timings.

use std::path::Path;

use serde_json::{Value, json};

use penumbra::app::HeadlessFrame;
use penumbra::render::timer::{frame_spread, median_passes};
use penumbra::settings::ShadowSettings;

/// The summary of a headless render of `scene` into `out` (`size`: width, height, frames)
/// with the sun's `settings` (None for a scene without a sun): the commit built from, the adapter, counts, shadow
/// memory, per-view casters and draws, CPU times of the last frame, and each GPU pass's median
/// time (with their sum) and the whole frames' median, mean and slowest time (empty without
/// timestamp queries).
pub fn summary_json(
    scene: &Path,
    out: &Path,
    (width, height, frames): (u32, u32, u32),
    settings: Option<&ShadowSettings>,
    result: &HeadlessFrame,
) -> Value {
    let passes: Vec<Vec<_>> = result.frames.iter().map(|f| f.passes.clone()).collect();
    let medians = median_passes(&passes);
    let gpu: Vec<Value> = medians
        .iter()
        .map(|(name, ms)| json!({ "pass": name, "ms": ms }))
        .collect();
    let total: f64 = medians.iter().map(|m| m.1).sum();
    let report = &result.report;
    let stats = &result.stats;
    json!({
        "scene": scene.display().to_string(),
        "commit": penumbra::BUILD_COMMIT,
        "adapter": result.adapter,
        "image": { "path": out.display().to_string(), "width": width, "height": height, "frames": frames.max(1) },
        "instances": { "total": result.instances, "visible": stats.visible_instances },
        "sun": settings.map(|s| json!({ "mode": s.filter.mode.effective(true), "resolution": s.map.resolution })),
        "shadow_views": stats.casters_per_view.len(),
        "shadow_memory_bytes": report.shadow_memory,
        "shadow_memory_plan": {
            "budget_bytes": result.memory.budget,
            "total_bytes": result.memory.total(),
            "lights": result.memory.lights.iter().map(|l| json!({
                "name": l.name, "asked": l.asked, "granted": l.granted, "views": l.views, "bytes": l.bytes,
            })).collect::<Vec<_>>(),
        },
        "casters_per_view": stats.casters_per_view,
        "draws_per_view": stats.draws_per_view,
        "draw_calls": report.draw_calls,
        "draws": report.draws,
        "deferred_lighting": report.deferred_lighting,
        "shadow_draw_calls": report.shadow_draw_calls,
        "shadow_texels_cleared": report.shadow_cleared_texels,
        "shadow_texels_drawn": report.shadow_drawn_texels,
        "shadow_views_scrolled": report.shadow_views_scrolled,
        "shadow_views_resynced": report.shadow_views_resynced,
        "pages": result.frames.iter().map(|f| f.pages).collect::<Vec<_>>(),
        "forward_fragments": report.forward_fragments,
        "shadow_views_drawn_per_frame": result.frames.iter().map(|f| f.shadow_views_drawn).collect::<Vec<_>>(),
        "occlusion_drawn_per_frame": result.frames.iter().map(|f| f.occlusion_drawn.map(|(e, l)| [e, l])).collect::<Vec<_>>(),
        "skinned_meshes_posed_per_frame": result.frames.iter().map(|f| f.skinned_meshes_posed).collect::<Vec<_>>(),
        "prepass_kept_per_frame": result.frames.iter().map(|f| f.prepass_kept).collect::<Vec<_>>(),
        "cpu_ms": {
            "cascades": stats.cascades_cpu.as_secs_f64() * 1e3,
            "culling": stats.culling_cpu.as_secs_f64() * 1e3,
            "view_culling": stats.view_culling_cpu.as_secs_f64() * 1e3,
            "shadow_systems_median": result.median_frame_cpu_ms(),
        },
        "gpu_ms": {
            "passes": gpu,
            "total": if medians.is_empty() { None } else { Some(total) },
            "frames": frame_spread(&passes).map(|s| json!({
                "median": s.median, "mean": s.mean, "max": s.max, "counted": s.frames,
            })),
        },
        "warnings": result.warnings,
    })
}
