//! Several lights on a real wgpu device (lavapipe in CI), judged against rays cast on the CPU:
//! two suns each cast their own shadow, a spot light's shadow lands where a ray to the light
//! is blocked, a spot light's PCSS penumbra widens with the gap between caster and receiver
//! as the perspective estimate says, and `penumbra bench` scores the spot-light scene against
//! the sphere-light reference.

mod common;

use common::rays::Aabb;
use glam::Vec3;
use image::RgbaImage;
use penumbra::analysis::ScoredLight;
use penumbra::bench::run_bench;
use penumbra::bench::session::SceneSession;
use penumbra::render::Renderer;
use penumbra::render::frame::FrameInputs;
use penumbra::render::probe::ProbeGpu;
use penumbra::render::target::AnalysisImage;
use penumbra::scene::SceneDesc;

fn scene(text: &str) -> SceneDesc {
    SceneDesc::from_str(text, "test.ron").unwrap_or_else(|e| panic!("{e}"))
}

/// Renders `desc` with analysis targets, reporting light `focus`.
fn render(desc: &SceneDesc, focus: usize, (w, h): (u32, u32)) -> (AnalysisImage, RgbaImage) {
    let mut session = SceneSession::new(desc, w, h).unwrap_or_else(|e| panic!("{e}"));
    let mut renderer = Renderer::headless_with_analysis(w, h).unwrap_or_else(|e| panic!("{e}"));
    renderer.set_focus_light(focus);
    session.update();
    renderer.render(&FrameInputs::from_world(session.app.world(), 0));
    assert!(renderer.take_errors().is_empty());
    (
        renderer.read_analysis().expect("analysis targets"),
        renderer.read_image(),
    )
}

/// Ground pixels the light's shadow was evaluated at, with what a ray says: (rendered
/// visibility, blocked). Pixels whose ray grazes a box (blocked from one end of a 3 cm
/// neighbourhood and not the other) are left out: the filter blurs them by design.
fn judged(a: &AnalysisImage, boxes: &[Aabb], to_light: impl Fn(Vec3) -> Vec3) -> Vec<(f32, bool)> {
    let mut out = Vec::new();
    for i in 0..a.shadow.len() {
        let p = a.position[i];
        if !a.evaluated[i] || !p.is_finite() || p.y.abs() > 1e-3 {
            continue;
        }
        let blocked_at = |q: Vec3| boxes.iter().any(|b| b.blocks(q + Vec3::Y * 1e-3, to_light(q)));
        let here = blocked_at(p);
        let edge = [Vec3::X, Vec3::Z, -Vec3::X, -Vec3::Z]
            .iter()
            .any(|&o| blocked_at(p + o * 0.03) != here);
        if !edge {
            out.push((a.shadow[i], here));
        }
    }
    out
}

/// Share of judged pixels whose rendered visibility disagrees with the ray (shadowed where a
/// ray is free, lit where it is blocked), and how many were shadowed.
fn disagreement(judged: &[(f32, bool)]) -> (f64, usize) {
    let wrong = judged.iter().filter(|(v, blocked)| (*v < 0.5) != *blocked).count();
    let shadowed = judged.iter().filter(|(_, b)| *b).count();
    (wrong as f64 / judged.len().max(1) as f64, shadowed)
}

const TWO_SUNS: &str = r#"Scene(
    camera: (position: (0, 14, 9), target: (0, 0, 0), fov: 50, near: 0.1, far: 100),
    sun: (direction: (1, -1, 0.2), illuminance: 1.0),
    shadows: (mode: Pcf, pcf_radius: 1, cascade_count: 2, resolution: 1024, max_distance: 40),
    lights: [
        Directional(direction: (-1, -1.2, -0.3), illuminance: 1.0,
            shadows: (mode: Pcf, pcf_radius: 1, cascade_count: 3, resolution: 512, max_distance: 40)),
    ],
    materials: { "m": (base_color: (0.7, 0.7, 0.7, 1)) },
    objects: [
        (shape: Plane(size: (40, 40)), material: "m", cast_shadows: false),
        (shape: Cuboid(size: (0.6, 4, 0.6)), material: "m", translation: (0, 2, 0)),
    ],
)"#;

#[test]
fn two_suns_each_cast_their_own_shadow() {
    let desc = scene(TWO_SUNS);
    let pillar = [Aabb::cuboid(Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.6, 4.0, 0.6))];
    let size = (160, 120);
    let mut regions = Vec::new();
    let mut images = Vec::new();
    let mut analyses = Vec::new();
    for (focus, direction) in [(0, Vec3::new(1.0, -1.0, 0.2)), (1, Vec3::new(-1.0, -1.2, -0.3))] {
        let (a, image) = render(&desc, focus, size);
        let to_sun = -direction.normalize();
        let judged = judged(&a, &pillar, |p| p + to_sun * 100.0);
        let (wrong, shadowed) = disagreement(&judged);
        assert!(judged.len() >= 5000, "sun {focus}: only {} pixels judged", judged.len());
        assert!(shadowed >= 100, "sun {focus}: only {shadowed} shadowed pixels judged");
        assert!(
            wrong <= 0.01,
            "sun {focus}: {:.2} % of pixels disagree with the rays",
            wrong * 100.0
        );
        let mine: Vec<usize> = (0..a.shadow.len())
            .filter(|&i| a.evaluated[i] && a.shadow[i] < 0.2)
            .collect();
        regions.push(mine);
        images.push(image);
        analyses.push(a);
    }
    // The two shadows fall on opposite sides of the pillar: one sun's umbra is lit by the other.
    let overlap = regions[0].iter().filter(|i| regions[1].contains(i)).count();
    assert!(
        overlap * 20 < regions[0].len().min(regions[1].len()),
        "{overlap} pixels in both umbrae"
    );
    // In the final image each sun's shadow is darker than open ground but still lit by the
    // other sun.
    let luma = |p: &image::Rgba<u8>| 0.2126 * p[0] as f32 + 0.7152 * p[1] as f32 + 0.0722 * p[2] as f32;
    let mean = |idx: &[usize]| {
        idx.iter()
            .map(|&i| luma(images[0].get_pixel(i as u32 % size.0, i as u32 / size.0)))
            .sum::<f32>()
            / idx.len() as f32
    };
    let a = &analyses[0];
    let open: Vec<usize> = (0..a.shadow.len())
        .filter(|&i| a.evaluated[i] && a.shadow[i] > 0.99 && !regions[1].contains(&i))
        .take(2000)
        .collect();
    let (in_0, in_1, lit) = (mean(&regions[0]), mean(&regions[1]), mean(&open));
    assert!(
        in_0 < lit - 20.0 && in_1 < lit - 20.0,
        "shadows {in_0}, {in_1} vs open {lit}"
    );
    assert!(
        in_0 > 30.0 && in_1 > 30.0,
        "each umbra is lit by the other sun: {in_0}, {in_1}"
    );
}

const SPOT: &str = r#"Scene(
    camera: (position: (0, 9, 7), target: (0, 0, 0), fov: 50, near: 0.1, far: 100),
    ambient: (0.05, 0.05, 0.05),
    lights: [
        Spot(position: (1.5, 5, 1), direction: (-0.2, -1, -0.1), intensity: 40, range: 15,
            inner_angle: 40, outer_angle: 50, shadows: (mode: Pcf, pcf_radius: 1, resolution: 1024)),
    ],
    materials: { "m": (base_color: (0.7, 0.7, 0.7, 1)) },
    objects: [
        (shape: Plane(size: (40, 40)), material: "m", cast_shadows: false),
        (shape: Cuboid(size: (1, 1, 1)), material: "m", translation: (0, 0.5, 0)),
        (shape: Cuboid(size: (0.4, 2, 0.4)), material: "m", translation: (-1.5, 1.0, 1.0)),
    ],
)"#;

#[test]
fn a_spot_shadow_lands_where_a_ray_to_the_light_is_blocked() {
    let desc = scene(SPOT);
    let boxes = [
        Aabb::cuboid(Vec3::new(0.0, 0.5, 0.0), Vec3::ONE),
        Aabb::cuboid(Vec3::new(-1.5, 1.0, 1.0), Vec3::new(0.4, 2.0, 0.4)),
    ];
    let light = Vec3::new(1.5, 5.0, 1.0);
    let (a, _) = render(&desc, 0, (160, 120));
    let inside = a.cascade.iter().filter(|&&c| c == 0).count();
    assert!(inside >= 4000, "only {inside} pixels inside the spot light's view");
    let judged = judged(&a, &boxes, |_| light);
    let (wrong, shadowed) = disagreement(&judged);
    assert!(judged.len() >= 4000, "only {} pixels judged", judged.len());
    assert!(shadowed >= 150, "only {shadowed} shadowed pixels judged");
    assert!(wrong <= 0.01, "{:.2} % of pixels disagree with the rays", wrong * 100.0);
}

/// Width of the shadow edge crossed by the probes: the distance between the last probe below
/// 0.1 and the first above 0.9, walking away from the umbra.
fn edge_width(values: &[f32], step: f32) -> f32 {
    let last_dark = values
        .iter()
        .rposition(|&v| v < 0.1)
        .expect("the walk starts in the umbra");
    let first_lit = values
        .iter()
        .position(|&v| v > 0.9)
        .expect("the walk ends in the light");
    assert!(first_lit > last_dark, "{values:?}");
    (first_lit - last_dark) as f32 * step
}

#[test]
fn a_spot_pcss_penumbra_widens_with_the_gap_to_the_caster() {
    assert_penumbra_widens("mode: Pcss, pcss_quality: High");
}

#[test]
fn a_spot_vsm_penumbra_widens_with_the_gap_to_the_caster() {
    // VSM's contact hardening (on by default) sizes the penumbra from the light's radius.
    assert_penumbra_widens("mode: Vsm");
}

/// Walks the ground out of the shadows of two boxes under a spot light filtered with `filter`
/// and checks each penumbra's width against the perspective estimate.
fn assert_penumbra_widens(filter: &str) {
    // A light 6 m up with a 0.15 m radius over two boxes: one 0.1 m above the ground, one
    // 2.5 m. Their outer shadow edges on the ground are at x = −3.06 and x = 6.0.
    let desc = scene(&format!(
        r#"Scene(
        camera: (position: (0, 10, 12), target: (1, 0, 0), fov: 60, near: 0.1, far: 100),
        lights: [
            Spot(position: (0, 6, 0), direction: (0, -1, 0), intensity: 40, range: 20,
                inner_angle: 50, outer_angle: 60, radius: 0.15,
                shadows: ({filter}, temporal_rotation: false, resolution: 2048)),
        ],
        materials: {{ "m": (base_color: (0.7, 0.7, 0.7, 1)) }},
        objects: [
            (shape: Plane(size: (40, 40)), material: "m", cast_shadows: false),
            (shape: Cuboid(size: (1, 1, 1)), material: "m", translation: (-2, 0.6, 0)),
            (shape: Cuboid(size: (1, 1, 1)), material: "m", translation: (2, 3.0, 0)),
        ],
    )"#
    ));
    let (w, h) = (64, 48);
    let mut session = SceneSession::new(&desc, w, h).unwrap_or_else(|e| panic!("{e}"));
    let mut renderer = Renderer::headless_with_analysis(w, h).unwrap_or_else(|e| panic!("{e}"));
    session.update();
    let input = FrameInputs::from_world(session.app.world(), 0);
    renderer.render(&input);
    let step = 0.01;
    let mut walk = |from: f32, to: f32| -> Vec<f32> {
        let n = ((to - from).abs() / step) as usize;
        let dir = (to - from).signum();
        let probes: Vec<ProbeGpu> = (0..=n)
            .map(|k| {
                ProbeGpu::new(
                    Vec3::new(from + dir * step * k as f32, 0.0, 0.0),
                    Vec3::Y,
                    (k as u32, 7),
                )
            })
            .collect();
        renderer.evaluate_probes(&input, &probes)
    };
    let near = edge_width(&walk(-2.6, -3.6), step);
    let far = edge_width(&walk(5.2, 7.0), step);
    // The perspective estimate (d_receiver − d_blocker) · 2r / d_blocker: 0.07 m and 0.42 m.
    assert!(
        far > 3.0 * near,
        "{filter}: penumbra {far} m behind the high box, {near} m behind the low one"
    );
    assert!(
        (0.25..=0.65).contains(&far),
        "{filter}: penumbra {far} m, the estimate is 0.42 m"
    );
    assert!(near <= 0.15, "{filter}: penumbra {near} m, the estimate is 0.07 m");
}

#[test]
fn the_bench_scores_the_spot_scene_against_the_sphere_light() {
    let wanted = ["hard", "pcf2", "pcf2-no-blend", "pcss-high"];
    let config = common::small_bench("scenes/spot.ron", &wanted);
    let report = run_bench(&config).unwrap_or_else(|e| panic!("{e}"));
    // Every preset runs on every scene, so each preset's means are over the same scenes.
    let names: Vec<&str> = report.presets.iter().map(|p| p.preset.as_str()).collect();
    assert_eq!(names, wanted);
    let notes = report.notes.join("\n");
    assert!(notes.contains("spot light 0, radius 0.25 m"), "{notes}");
    assert!(notes.contains("sphere-light reference"), "{notes}");
    assert!(
        notes.contains("-no-blend presets render as their base presets"),
        "{notes}"
    );
    // Cascade blending means nothing to a spot light: without it, PCF 5×5 scores the same.
    let (pcf2, no_blend) = (&report.presets[1].scenes[0], &report.presets[2].scenes[0]);
    assert_eq!(pcf2.errors, no_blend.errors);
    let mut penumbra_mae = Vec::new();
    for p in &report.presets {
        let [s] = p.scenes.as_slice() else {
            panic!("{}: {} scenes", p.preset, p.scenes.len())
        };
        assert_eq!(s.scene, "spot");
        assert_eq!(s.light, ScoredLight::Spot { index: 0, radius: 0.25 });
        let e = &s.errors;
        // Only points inside the spot light's view are scored: all of them in "cascade" 0.
        assert!(e.pixels >= 4000, "{}: only {} points judged", p.preset, e.pixels);
        assert!(
            e.penumbra_pixels >= 100,
            "{}: only {} penumbra points",
            p.preset,
            e.penumbra_pixels
        );
        assert!(e.lit_pixels >= 2000 && e.shadowed_pixels >= 200, "{}: {e:?}", p.preset);
        assert_eq!(s.per_cascade[0].pixels, e.pixels, "{}", p.preset);
        assert!(s.per_cascade[1..].iter().all(|c| c.pixels == 0), "{}", p.preset);
        assert_eq!(e.skipped_nan, 0);
        for v in [e.mae, e.penumbra_mae, e.p95, e.acne_rate, e.leak_rate] {
            assert!(v.is_finite(), "{}: {e:?}", p.preset);
        }
        assert!(e.acne_rate <= 0.005, "{}: acne {:.2} %", p.preset, e.acne_rate * 100.0);
        assert!(s.shimmer_translation.points > 0 && s.shimmer_translation.mean_spread.is_finite());
        penumbra_mae.push(e.penumbra_mae);
    }
    // Contact hardening matters here: the soft filter follows the sphere light's penumbrae,
    // one hardware comparison cannot.
    let (hard, pcss) = (penumbra_mae[0], penumbra_mae[3]);
    assert!(pcss < 0.5 * hard, "penumbra MAE: PCSS High {pcss:.4}, hard {hard:.4}");
}
