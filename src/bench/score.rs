//! Scoring one scene: the ray-traced reference of its scored light (see
//! [`focus`](crate::bench::focus)) at the analysis resolution, then for every preset that
//! applies to that light its error against the reference and its temporal stability under
//! sub-texel camera moves and in-place turns.

use std::path::Path;

use glam::Vec3;

use crate::analysis::edges::{EdgeSplit, edge_split};
use crate::analysis::metrics::{ErrorMetrics, Thresholds, error_metrics, per_cascade};
use crate::analysis::results::ScoredLight;
use crate::analysis::shimmer::{Shimmer, shimmer};
use crate::bench::config::{BenchConfig, BenchError, short};
use crate::bench::focus::FocusKind;
use crate::bench::gallery::SceneShots;
use crate::bench::progress::Progress;
use crate::bench::session::SceneSession;
use crate::ecs::CameraLod;
use crate::reference::{ReferencePoint, near_casters};
use crate::render::frame_inputs::FrameInputs;
use crate::render::probe::ProbeGpu;
use crate::render::target::AnalysisImage;
use crate::render::{RenderOptions, Renderer};
use crate::scene::SceneDesc;

/// Renders one analysis frame of the session with the given renderer. When the frame brought
/// new seen depths (a depth-bounds fit), it is rendered again fitted to them, so the fit is
/// scored on its own view, as a still camera's frames are.
fn analysis_frame(session: &mut SceneSession, renderer: &mut Renderer) -> AnalysisImage {
    let render = |session: &mut SceneSession, renderer: &mut Renderer| {
        session.update();
        renderer.render(&FrameInputs::from_world(session.app.world(), 0));
        session.take_seen_depths(renderer)
    };
    if render(session, renderer) {
        render(session, renderer);
    }
    renderer.read_analysis().unwrap_or_default()
}

/// The points (and the pixels they were seen at) where the shadow was evaluated.
pub struct Points {
    /// Pixel index of each point.
    pub pixels: Vec<usize>,
    /// The points, for the ray-traced reference.
    pub reference: Vec<ReferencePoint>,
    /// The points, for the shadow-probe pass.
    pub probes: Vec<ProbeGpu>,
}

/// Every pixel of an analysis frame where the shadow was evaluated, as reference points and
/// shadow probes.
pub fn evaluated_points(a: &AnalysisImage) -> Points {
    evaluated_points_where(a, |_| true)
}

/// [`evaluated_points`] limited to the pixels `i` for which `keep(i)` holds.
pub fn evaluated_points_where(a: &AnalysisImage, keep: impl Fn(usize) -> bool) -> Points {
    let pixels: Vec<usize> = (0..a.shadow.len())
        .filter(|&i| a.evaluated[i] && a.position[i].is_finite() && a.normal[i].is_finite() && keep(i))
        .collect();
    let reference = pixels
        .iter()
        .map(|&i| ReferencePoint {
            position: a.position[i],
            normal: a.normal[i],
        })
        .collect();
    let probes = pixels
        .iter()
        .map(|&i| ProbeGpu::new(a.position[i], a.normal[i], ((i as u32) % a.width, (i as u32) / a.width)))
        .collect();
    Points {
        pixels,
        reference,
        probes,
    }
}

/// Shadow values at `probes` for each pose of a camera path.
fn path_values(
    session: &mut SceneSession,
    renderer: &mut Renderer,
    probes: &[ProbeGpu],
    poses: &[(Vec3, f32)],
) -> Vec<Vec<f32>> {
    let values = poses
        .iter()
        .map(|&(offset, yaw)| {
            session.move_camera(offset, yaw);
            session.update();
            renderer.render(&FrameInputs::from_world(session.app.world(), 0));
            session.take_seen_depths(renderer);
            renderer.evaluate_probes(&FrameInputs::from_world(session.app.world(), 0), probes)
        })
        .collect();
    session.move_camera(Vec3::ZERO, 0.0);
    values
}

/// One preset's scores on one scene.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PresetScore {
    /// Error over every scored point.
    pub errors: ErrorMetrics,
    /// Error per cascade (a spot light's view is cascade 0).
    pub per_cascade: [ErrorMetrics; 4],
    /// Stability under sub-texel camera moves.
    pub shimmer_translation: Shimmer,
    /// Stability under in-place turns.
    pub shimmer_rotation: Shimmer,
    /// Acne and leaks split by their distance to a shadow edge.
    pub edges: EdgeSplit,
    /// Error of the image's own shadow factor (what the material multiplied in: the resolved
    /// filter times contact shadows) over every scored point.
    pub image: ErrorMetrics,
    /// The same over the contact band: the points within [`CONTACT_BAND`] of a caster.
    pub contact_band: ErrorMetrics,
}

/// Largest distance from a caster of a point in the contact band, metres.
pub const CONTACT_BAND: f32 = 0.3;

/// Errors and stability of every preset on one scene.
pub(crate) struct SceneScores {
    /// The light scored.
    pub light: ScoredLight,
    /// Points scored.
    pub points: usize,
    /// Step of the translation path, metres.
    pub texel: f32,
    /// One entry per configured preset.
    pub presets: Vec<PresetScore>,
}

/// Scores every preset of `config` on the scene's scored light.
pub(crate) fn score_scene(
    path: &Path,
    desc: &SceneDesc,
    config: &BenchConfig,
    overall: &Progress,
    gallery: Option<&mut Vec<SceneShots>>,
) -> Result<SceneScores, BenchError> {
    let name = path.display().to_string();
    let (w, h) = (config.analysis_width, config.analysis_height);
    let mut session = SceneSession::new(desc, w, h)?;
    session.pages = config.pages;
    // NOTE: the reference traces the full meshes from the analysis pixels' positions, and a
    // coarser mesh level's surface lies inside its mesh (a sphere's facets are chords): its
    // pixels would be scored as shadowed by their own mesh. The analysis frames, smaller than
    // the timed ones (whose camera keeps its LOD), draw every mesh whole for the camera.
    session.app.insert_resource(CameraLod { max_error_pixels: 0.0 });
    session.app.insert_resource(RenderOptions {
        sun_depth: config.sun_depth,
        ..RenderOptions::default()
    });
    let mut renderer = Renderer::headless_with_analysis(w, h)?;
    let focus = session.focus().ok_or_else(|| BenchError::NoLight(name.clone()))?;
    renderer.set_focus_light(session.focus_light_index());
    let first = analysis_frame(&mut session, &mut renderer);
    // NOTE: a spot light's shadow exists only inside its view (the analysis "cascade" 0),
    // a point light's within its range (a cube face, "cascade" 0–5); outside, the light is
    // dark and its shadow factor is 1 by definition, so only the points inside are scored. A
    // sun's points are all scored, as before other lights.
    let points = match focus.kind {
        FocusKind::Sun => evaluated_points(&first),
        FocusKind::Spot => evaluated_points_where(&first, |i| first.cascade[i] == 0),
        FocusKind::Point => evaluated_points_where(&first, |i| first.cascade[i] < 6),
    };
    let lights = session.lights();
    let (target, light) = focus
        .reference(lights)
        .zip(focus.scored_light(lights))
        .ok_or_else(|| BenchError::NoLight(name.clone()))?;

    let reference_scene = session.reference_scene();
    let progress = overall.stage(points.reference.len() as u64, format!("reference {}", short(path)));
    let reference = target.visibility(&reference_scene, &points.reference, &config.reference, &|n| {
        progress.set_position(n as u64)
    });
    progress.finish_and_clear();
    overall.advance(config.presets.len().max(1) as u64);
    let reference_values: Vec<f32> = reference.iter().map(|v| v.value).collect();
    let near = near_casters(&reference_scene, &points.reference, CONTACT_BAND);
    let mut shots = gallery
        .is_some()
        .then(|| SceneShots::new(short(path), (w, h), &points.pixels, &reference_values));

    // Stability paths: sub-texel moves of the start camera (within one texel of the scored
    // light's map: cascade 0, or a spot light's map at the camera's target) and small
    // in-place turns.
    let texel = focus.texel(session.lights(), session.camera_target());
    let start = session.start_camera();
    let (right, up) = (start.rotation * Vec3::X, start.rotation * Vec3::Y);
    let steps = config.shimmer_steps.max(2);
    let translations: Vec<(Vec3, f32)> = (0..steps)
        .map(|k| {
            let t = k as f32 / steps as f32 * 0.95 * texel;
            (right * t + up * (0.37 * t), 0.0)
        })
        .collect();
    let rotations: Vec<(Vec3, f32)> = (0..steps)
        .map(|k| (Vec3::ZERO, (k as f32 * 0.1).to_radians()))
        .collect();
    let stride = points.probes.len().div_ceil(config.max_probes.max(1)).max(1);
    let followed: Vec<ProbeGpu> = points.probes.iter().step_by(stride).copied().collect();

    let mut scores = SceneScores {
        light,
        points: points.pixels.len(),
        texel,
        presets: Vec::new(),
    };
    let progress = overall.stage(config.presets.len() as u64, format!("presets {}", short(path)));
    let thresholds = Thresholds::default();
    for preset in &config.presets {
        session.apply_settings(preset.apply);
        let image = analysis_frame(&mut session, &mut renderer);
        let technique = renderer.evaluate_probes(&FrameInputs::from_world(session.app.world(), 0), &points.probes);
        // NOTE: a point light's faces are reported together, as its one view.
        let cascade: Vec<u8> = points
            .pixels
            .iter()
            .map(|&i| match focus.kind {
                FocusKind::Point => u8::from(image.cascade[i] >= 6) * 255,
                _ => image.cascade[i],
            })
            .collect();
        // NOTE: the probes filter the shadow maps at the points; contact shadows exist only in
        // the image, which is scored on its own.
        let shaded: Vec<f32> = points.pixels.iter().map(|&i| image.shadow[i]).collect();
        if let Some(shots) = shots.as_mut() {
            shots.take(preset.name, &renderer.read_image(), &shaded);
        }
        let all = |_: usize| true;
        let errors = error_metrics(&technique, &reference_values, all, &thresholds);
        let per_cascade = per_cascade(&technique, &reference_values, &cascade, all, &thresholds);
        let moved = path_values(&mut session, &mut renderer, &followed, &translations);
        let turned = path_values(&mut session, &mut renderer, &followed, &rotations);
        scores.presets.push(PresetScore {
            errors,
            per_cascade,
            shimmer_translation: shimmer(&moved),
            shimmer_rotation: shimmer(&turned),
            edges: edge_split(&technique, &reference_values, &points.pixels, (w, h), &thresholds),
            image: error_metrics(&shaded, &reference_values, all, &thresholds),
            contact_band: error_metrics(&shaded, &reference_values, |k| near[k], &thresholds),
        });
        progress.inc(1);
        overall.advance(1);
    }
    progress.finish_and_clear();
    if let (Some(gallery), Some(shots)) = (gallery, shots) {
        gallery.push(shots);
    }
    Ok(scores)
}
