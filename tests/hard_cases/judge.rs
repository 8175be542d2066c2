//! Scoring one hard case: render it with PCF and with PCSS (default settings otherwise), cast
//! the ray-traced reference at every pixel where the shadow was evaluated, and split the
//! pixels into the surfaces that can show each artefact — the ground (a receiver that casts
//! nothing) and the casters' own lit faces — so a rate is never diluted by pixels that cannot
//! fail it. Every count a case judges is returned, so the tests can assert floors on them.

use std::path::Path;

use glam::Vec3;
use penumbra::analysis::edges::{EdgeSplit, edge_split};
use penumbra::analysis::metrics::{ErrorMetrics, Thresholds, error_metrics};
use penumbra::bench::run::{Points, evaluated_points};
use penumbra::bench::session::SceneSession;
use penumbra::ecs::RenderOrigin;
use penumbra::export::write_scalar_image;
use penumbra::reference::{ReferenceSettings, sun_visibility};
use penumbra::render::frame::FrameInputs;
use penumbra::render::target::AnalysisImage;
use penumbra::render::{RenderOptions, Renderer};
use penumbra::scene::SceneDesc;
use penumbra::settings::ShadowMode;

/// Most lit pixels (reference fully lit) a filter may darken below 0.9, as a fraction of the
/// lit pixels of one surface class (ground or casters): the target on every case.
pub const ACNE_LIMIT: f64 = 0.0005;
/// Most umbra pixels (reference fully shadowed) a filter may brighten above 0.1, as a fraction
/// of the umbra pixels judged: the target on every case.
pub const LEAK_LIMIT: f64 = 0.01;

/// The rates a case may reach, with PCF and with PCSS.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Acne rate on the ground.
    pub ground_acne: f64,
    /// Acne rate on the casters' lit faces.
    pub caster_acne: f64,
    /// Leak rate over every judged pixel.
    pub leak: f64,
}

/// The target limits, met by every case that does not state its own.
pub const TARGET: Limits = Limits {
    ground_acne: ACNE_LIMIT,
    caster_acne: ACNE_LIMIT,
    leak: LEAK_LIMIT,
};

/// Height of the ground plane every hard-case scene stands on.
pub const GROUND_Y: f32 = 0.0;
/// A pixel within this distance (metres) of the ground's height, with an upward normal, is
/// ground; the thinnest caster in the hard cases stands 9.5 mm above it.
const GROUND_TOLERANCE: f32 = 1.0e-3;

/// The fewest pixels a case must judge; each case states its own (about half to two thirds
/// of what it judges today), so a change that empties a case fails instead of passing
/// vacuously.
#[derive(Clone, Copy, Debug, Default)]
pub struct Floors {
    /// Pixels where the shadow was evaluated and is scored (inside the shadow distance).
    pub judged: u64,
    /// Ground pixels the reference sees fully lit (the denominator of the ground's acne rate).
    pub ground_lit: u64,
    /// Caster pixels the reference sees fully lit (the denominator of the casters' acne rate).
    pub caster_lit: u64,
    /// Pixels the reference sees fully shadowed (the denominator of the leak rate).
    pub umbra: u64,
}

/// One filter's error on one case.
#[derive(Clone, Copy, Debug, Default)]
pub struct FilterScore {
    /// Every judged pixel.
    pub all: ErrorMetrics,
    /// Judged ground pixels.
    pub ground: ErrorMetrics,
    /// Judged pixels on the casters.
    pub casters: ErrorMetrics,
    /// Acne and leaks by their distance to a shadow edge, as the bench reports them.
    pub edges: EdgeSplit,
}

/// A case rendered with both filters and scored.
pub struct Judged {
    /// Name printed with every figure.
    pub name: String,
    /// Pixels where anything was drawn.
    pub drawn: u64,
    /// Pixels where the shadow was evaluated (a receiver facing the sun), scored or not.
    pub evaluated: u64,
    /// Scores with PCF, then with PCSS.
    pub filters: [(ShadowMode, FilterScore); 2],
    /// The PCF frame's analysis image (positions, normals, shadow factors).
    pub analysis: AnalysisImage,
    /// World size of a shadow texel in each cascade.
    pub texels: Vec<f32>,
}

/// Where a judged pixel lies.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Surface {
    Ground,
    Caster,
}

/// Renders `desc` (its `shadows.mode` replaced by each filter in turn) at `width`×`height`,
/// checks the frames are sane (finite cascades, shadow factors in [0, 1], the same pixels
/// evaluated by both filters) and scores them against the reference.
pub fn judge(name: &str, desc: &SceneDesc, width: u32, height: u32) -> Judged {
    judge_with(name, desc, (width, height), RenderOptions::default())
}

/// [`judge`] rendering with `options`.
pub fn judge_with(name: &str, desc: &SceneDesc, (width, height): (u32, u32), options: RenderOptions) -> Judged {
    let mut frames = Vec::new();
    let mut session = None;
    for mode in [ShadowMode::Pcf, ShadowMode::Pcss] {
        let mut desc = desc.clone();
        desc.shadows.filter.mode = mode;
        let mut s = SceneSession::new(&desc, width, height).unwrap_or_else(|e| panic!("{name}: {e}"));
        s.app.insert_resource(options);
        let mut renderer = Renderer::headless_with_analysis(width, height).unwrap_or_else(|e| panic!("{e}"));
        s.update();
        renderer.render(&FrameInputs::from_world(s.app.world(), 0));
        let analysis = renderer.read_analysis().expect("analysis targets");
        let finite = s
            .lights()
            .sun()
            .is_none_or(|sun| sun.cascades.active().iter().all(|c| c.clip_from_world.is_finite()));
        assert!(finite, "{name} ({mode:?}): non-finite cascade matrix");
        let bad = analysis
            .shadow
            .iter()
            .filter(|v| !(v.is_finite() && (0.0..=1.0).contains(*v)))
            .count();
        assert_eq!(bad, 0, "{name} ({mode:?}): {bad} shadow factors outside [0, 1] or NaN");
        frames.push((mode, analysis));
        session = Some(s);
    }
    let session = session.expect("two sessions");
    let texels: Vec<f32> = session.lights().sun().map_or(Vec::new(), |sun| {
        sun.cascades.active().iter().map(|c| c.texel_world_size).collect()
    });
    let (pcf, pcss) = (&frames[0].1, &frames[1].1);
    assert_eq!(
        pcf.evaluated, pcss.evaluated,
        "{name}: the filters evaluated different pixels"
    );

    let origin = session.app.world().resource::<RenderOrigin>().0;
    let camera = desc.camera.position - origin;
    let forward = (desc.camera.target - desc.camera.position).normalize();
    // NOTE: pixels in the distance-fade band (and past max_distance) are meant to lose their
    // shadow; only pixels where the technique promises full-strength shadows are scored.
    let fade_start = session.lights().sun().map_or(0.0, |s| {
        s.settings.map.max_distance.min(desc.camera.far) * (1.0 - s.settings.filter.distance_fade_width)
    });
    let Points {
        pixels,
        reference: points,
        ..
    } = evaluated_points(pcf);
    let kept: Vec<usize> = (0..pixels.len())
        .filter(|&k| (pcf.position[pixels[k]] - camera).dot(forward) < fade_start && pcf.cascade[pixels[k]] < 4)
        .collect();
    let surface: Vec<Surface> = kept
        .iter()
        .map(|&k| {
            let (p, n) = (pcf.position[pixels[k]], pcf.normal[pixels[k]]);
            if n.y > 0.999 && (p.y - (GROUND_Y - origin.y)).abs() < GROUND_TOLERANCE {
                Surface::Ground
            } else {
                Surface::Caster
            }
        })
        .collect();
    let reference: Vec<f32> = match session.sun_disc() {
        Some(sun) if !kept.is_empty() => {
            let settings = ReferenceSettings {
                max_samples: 64,
                min_samples: 16,
                seed: 7,
            };
            let kept_points: Vec<_> = kept.iter().map(|&k| points[k]).collect();
            let values = sun_visibility(&session.reference_scene(), &sun, &kept_points, &settings, &|_| {});
            values.iter().map(|v| v.value).collect()
        }
        _ => Vec::new(),
    };
    let thresholds = Thresholds::default();
    let mut scores = [(ShadowMode::Pcf, FilterScore::default()); 2];
    // The analysis pixels of the judged points.
    let judged_pixels: Vec<usize> = kept.iter().map(|&k| pixels[k]).collect();
    for ((mode, analysis), score) in frames.iter().zip(&mut scores) {
        let technique: Vec<f32> = kept.iter().map(|&k| analysis.shadow[pixels[k]]).collect();
        if let Some(dir) = std::env::var_os("PENUMBRA_DUMP") {
            let tag = format!("{name}_{mode:?}").replace(|c: char| !c.is_ascii_alphanumeric(), "_");
            dump(Path::new(&dir), &tag, analysis, &judged_pixels, &technique, &reference);
        }
        if std::env::var_os("PENUMBRA_PIXELS").is_some() {
            list_failures(
                &format!("{name} [{mode:?}]"),
                analysis,
                &judged_pixels,
                &technique,
                &reference,
                &thresholds,
            );
        }
        let size = (analysis.width, analysis.height);
        let surface = &surface;
        let on = |s: Surface| move |i: usize| surface[i] == s;
        *score = (
            *mode,
            FilterScore {
                all: error_metrics(&technique, &reference, |_| true, &thresholds),
                ground: error_metrics(&technique, &reference, on(Surface::Ground), &thresholds),
                casters: error_metrics(&technique, &reference, on(Surface::Caster), &thresholds),
                edges: edge_split(&technique, &reference, &judged_pixels, size, &thresholds),
            },
        );
    }
    let judged = Judged {
        name: name.to_owned(),
        drawn: pcf.position.iter().filter(|p| p.is_finite()).count() as u64,
        evaluated: pixels.len() as u64,
        filters: scores,
        analysis: frames.swap_remove(0).1,
        texels,
    };
    judged.print();
    judged
}

impl Judged {
    /// Prints every figure the limits are checked against.
    fn print(&self) {
        eprintln!("{}: shadow texels {:?} m", self.name, self.texels);
        for (mode, s) in &self.filters {
            eprintln!(
                "{} [{mode:?}]: {} drawn, {} evaluated, {} judged; acne ground {:.5} of {}, casters {:.5} of {}; \
                 leaks {:.5} of {} umbra; MAE {:.4}, penumbra MAE {:.4} over {}, p95 {:.4}; \
                 acne near edges {:.5}, away {:.5}; leaks near edges {:.5}, away {:.5}",
                self.name,
                self.drawn,
                self.evaluated,
                s.all.pixels,
                s.ground.acne_rate,
                s.ground.lit_pixels,
                s.casters.acne_rate,
                s.casters.lit_pixels,
                s.all.leak_rate,
                s.all.shadowed_pixels,
                s.all.mae,
                s.all.penumbra_mae,
                s.all.penumbra_pixels,
                s.all.p95,
                s.edges.acne_near_edges,
                s.edges.acne_away_from_edges,
                s.edges.leak_near_edges,
                s.edges.leak_away_from_edges
            );
        }
    }

    /// Asserts that both filters judged at least `floors` and stay within [`TARGET`].
    pub fn assert_judged(&self, floors: &Floors) {
        self.assert_within(floors, &TARGET);
    }

    /// Like [`assert_judged`](Self::assert_judged) with the given limits.
    pub fn assert_within(&self, floors: &Floors, limits: &Limits) {
        let name = &self.name;
        for (mode, s) in &self.filters {
            let counts = [
                ("judged pixels", s.all.pixels, floors.judged),
                ("lit ground pixels", s.ground.lit_pixels, floors.ground_lit),
                ("lit caster pixels", s.casters.lit_pixels, floors.caster_lit),
                ("umbra pixels", s.all.shadowed_pixels, floors.umbra),
            ];
            for (what, count, floor) in counts {
                assert!(
                    count >= floor,
                    "{name} [{mode:?}]: {count} {what}, fewer than the floor {floor}"
                );
            }
            for (surface, m, limit) in [
                ("ground", &s.ground, limits.ground_acne),
                ("casters", &s.casters, limits.caster_acne),
            ] {
                assert!(
                    m.acne_rate <= limit,
                    "{name} [{mode:?}]: acne on the {surface} {:.5} > {limit}: {m:?}",
                    m.acne_rate
                );
            }
            assert!(
                s.all.leak_rate <= limits.leak,
                "{name} [{mode:?}]: leaks {:.5} > {}: {:?}",
                s.all.leak_rate,
                limits.leak,
                s.all
            );
        }
    }

    /// The mean absolute error of each filter.
    pub fn mae(&self) -> [f64; 2] {
        self.filters.map(|(_, s)| s.all.mae)
    }
}

/// Prints every acne and leak pixel (debugging aid: `PENUMBRA_PIXELS=1`): where it is, its
/// cascade, both values, and how far (in pixels, Chebyshev, and in metres) the nearest judged
/// pixel of another class lies, which tells shadow-edge blur (1 pixel away) from
/// self-shadowing inside a lit surface.
fn list_failures(tag: &str, a: &AnalysisImage, pixels: &[usize], technique: &[f32], reference: &[f32], t: &Thresholds) {
    let w = a.width as usize;
    let xy = |i: usize| ((i % w) as i64, (i / w) as i64);
    for (k, (&value, &truth)) in technique.iter().zip(reference).enumerate() {
        let acne = truth >= t.lit && value < t.acne_below;
        if !(acne || (truth <= t.shadowed && value > t.leak_above)) {
            continue;
        }
        let (i, (x, y)) = (pixels[k], xy(pixels[k]));
        let other = |r: f32| if acne { r < t.lit } else { r > t.shadowed };
        let nearest = pixels
            .iter()
            .zip(reference)
            .filter(|&(_, &r)| other(r))
            .map(|(&j, _)| {
                let (xj, yj) = xy(j);
                (
                    (xj - x).abs().max((yj - y).abs()),
                    (a.position[j] - a.position[i]).length(),
                )
            })
            .min_by(|p, q| p.0.cmp(&q.0).then(p.1.total_cmp(&q.1)));
        eprintln!(
            "{tag} {} at ({x}, {y}), cascade {}, position {}, normal {}: technique {value:.3}, reference \
             {truth:.3}; other class {nearest:?} (pixels, metres) away",
            if acne { "acne" } else { "leak" },
            a.cascade[i],
            a.position[i],
            a.normal[i],
        );
    }
}

/// Writes the technique beside the reference, four times enlarged (debugging aid:
/// `PENUMBRA_DUMP=dir`); pixels not judged are mid-grey.
fn dump(dir: &Path, tag: &str, a: &AnalysisImage, pixels: &[usize], technique: &[f32], reference: &[f32]) {
    const SCALE: usize = 4;
    let (w, h) = (a.width as usize, a.height as usize);
    let mut side_by_side = vec![0.5f32; 2 * w * h];
    for (k, &i) in pixels.iter().enumerate() {
        let (x, y) = (i % w, i / w);
        side_by_side[y * 2 * w + x] = technique[k];
        side_by_side[y * 2 * w + w + x] = reference.get(k).copied().unwrap_or(0.5);
    }
    let big: Vec<f32> = (0..2 * w * h * SCALE * SCALE)
        .map(|i| side_by_side[(i / (2 * w * SCALE) / SCALE) * 2 * w + (i % (2 * w * SCALE)) / SCALE])
        .collect();
    std::fs::create_dir_all(dir).expect("dump folder");
    let (bw, bh) = ((2 * w * SCALE) as u32, (h * SCALE) as u32);
    write_scalar_image(&dir.join(format!("{tag}.png")), bw, bh, &big).expect("dump");
}

/// A unit direction `elevation` degrees above the horizon, travelling towards +x (and a
/// little towards +z).
pub fn sun_at_elevation(elevation: f32) -> Vec3 {
    let e = elevation.to_radians();
    Vec3::new(e.cos(), -e.sin(), 0.2).normalize()
}
