//! 16-bit sun depth (lavapipe): the default scene's cascades drawn into `Depth16Unorm` hold the
//! depths of the same cascades drawn into `Depth32Float`, every depth a whole step 0–1 step
//! behind the float's (drawn half a step back, then rounded), in the same texels and half the
//! memory; no pixel of the image changes by more than 8/255; and
//! switching the depth between frames draws what a renderer started with it draws; a sun
//! whose 16-bit depth steps more coarsely than its texels is warned about (not with floats,
//! not in the default scene).

mod common;

use bevy_app::App;
use common::{renderer, scene_with};
use penumbra::ecs::ShadowDiagnostics;
use penumbra::layout::ShadowStorage;
use penumbra::render::shadows::casters::UNORM16_STEPS;
use penumbra::render::{RenderOptions, SunDepth};

/// One step of `Depth16Unorm`.
const STEP: f32 = 1.0 / UNORM16_STEPS;

/// The default scene rendered once (two frames) with the suns' layers in `depth`.
fn rendered(depth: SunDepth) -> App {
    let mut app = scene_with(
        "assets/scenes/default.ron",
        RenderOptions {
            sun_depth: depth,
            ..RenderOptions::default()
        },
    );
    app.update();
    app.update();
    app
}

/// Every cascade layer of `app`, read back as 0–1 depths.
fn cascades(app: &App) -> Vec<Vec<f32>> {
    (0..)
        .map_while(|layer| renderer(app).read_shadow_map(ShadowStorage::Cascades, layer))
        .collect()
}

#[test]
fn sixteen_bit_cascades_hold_the_float_depths_to_a_step_in_half_the_memory() {
    let (float, unorm) = (rendered(SunDepth::Float32), rendered(SunDepth::Unorm16));
    let (a, b) = (cascades(&float), cascades(&unorm));
    assert_eq!(a.len(), b.len(), "layers");
    let (mut judged, mut off_step, mut coverage) = (0usize, 0usize, 0usize);
    let (mut nearest, mut farthest) = (f32::INFINITY, f32::NEG_INFINITY);
    for (x, y) in a.iter().zip(&b) {
        for (&f, &u) in x.iter().zip(y) {
            let steps = u / STEP;
            off_step += usize::from((steps - steps.round()).abs() > 1e-3);
            coverage += usize::from((f > 0.0) != (u > 0.0));
            if f > 0.0 && u > 0.0 {
                judged += 1;
                // Reverse-Z: a 16-bit caster lies further from the light (smaller depth).
                let shift = (f - u) / STEP;
                nearest = nearest.min(shift);
                farthest = farthest.max(shift);
            }
        }
    }
    eprintln!(
        "{judged} caster texels: 16-bit depth {nearest:.3}–{farthest:.3} steps behind the float; \
         {coverage} texels covered in one only; {off_step} off a step"
    );
    assert!(judged > 20_000, "only {judged} caster texels judged");
    assert_eq!(off_step, 0, "{off_step} 16-bit depths between steps");
    // Drawn half a step back and rounded to the nearest step: 0–1 step behind, never nearer
    // the light (the float's own rounding to f32 is far below a hundredth of a step).
    assert!(
        nearest >= -0.01 && farthest <= 1.01,
        "16-bit depths {nearest:.3}–{farthest:.3} steps behind the float's"
    );
    assert_eq!(coverage, 0, "{coverage} texels covered by one format only");
    let memory = |app: &App| renderer(app).last_report.shadow_memory;
    assert_eq!(memory(&unorm) * 2, memory(&float), "shadow memory");
    let (x, y) = (renderer(&float).read_image(), renderer(&unorm).read_image());
    let differ = x
        .pixels()
        .zip(y.pixels())
        .filter(|(p, q)| p.0.iter().zip(q.0).any(|(a, b)| a.abs_diff(b) > 8))
        .count();
    eprintln!("{differ} of {} pixels differ by more than 8/255", x.pixels().count());
    // Measured: none at 160×90.
    assert_eq!(differ, 0, "{differ} pixels differ by more than 8/255");
}

#[test]
fn switching_the_sun_depth_between_frames_draws_what_a_fresh_renderer_draws() {
    // A still camera keeps its maps: the switch must replace the array and draw every layer.
    for (from, to) in [
        (SunDepth::Float32, SunDepth::Unorm16),
        (SunDepth::Unorm16, SunDepth::Float32),
    ] {
        let mut switched = rendered(from);
        switched.insert_resource(RenderOptions {
            sun_depth: to,
            ..RenderOptions::default()
        });
        switched.update();
        let fresh = rendered(to);
        let (a, b) = (cascades(&switched), cascades(&fresh));
        let covered: usize = b.iter().map(|l| l.iter().filter(|&&d| d > 0.0).count()).sum();
        assert!(covered > 20_000, "{to:?}: only {covered} caster texels judged");
        assert!(a == b, "{from:?} → {to:?}: the layers differ from a fresh renderer's");
        let memory = |app: &App| renderer(app).last_report.shadow_memory;
        assert_eq!(memory(&switched), memory(&fresh), "{from:?} → {to:?}: shadow memory");
        assert!(
            renderer(&switched).read_image() == renderer(&fresh).read_image(),
            "{from:?} → {to:?}: the images differ"
        );
    }
}

/// A sun 1.1° above the horizon over boxes spread 2 km along its light: its near cascade spans
/// about 2 km of depth, a 16-bit step of about two of its 1.6 cm texels.
const GRAZING: &str = r#"Scene(
    camera: (position: (0, 1.7, 0), target: (0, 1.4, -30), fov: 60, near: 0.1, far: 600),
    sun: (direction: (0.0, -0.02, -1.0), illuminance: 3.0),
    materials: { "grey": (base_color: (0.5, 0.5, 0.5, 1)) },
    shadows: (mode: Pcf, cascade_count: 4, resolution: 2048, max_distance: 150),
    objects: [
        (shape: Plane(size: (4000, 4000)), material: "grey", cast_shadows: false),
        (
            shape: Cuboid(size: (1, 4, 1)),
            material: "grey",
            translation: (0, 2, 0),
            grid: (count: (3, 1, 40), spacing: (10, 0, 50)),
        ),
    ],
)"#;

/// The warnings of `scene`'s first frame with the suns' layers in `depth`.
fn first_frame_warnings(scene: &str, depth: SunDepth) -> Vec<String> {
    let mut app = scene_with(
        scene,
        RenderOptions {
            sun_depth: depth,
            ..RenderOptions::default()
        },
    );
    app.update();
    app.world().resource::<ShadowDiagnostics>().current.clone()
}

#[test]
fn a_sun_whose_16_bit_steps_pass_its_texels_is_warned_about() {
    let path = std::env::temp_dir().join(format!("penumbra-grazing-{}.ron", std::process::id()));
    std::fs::write(&path, GRAZING).expect("the scene file is written");
    let scene = path.to_str().expect("a UTF-8 path");
    let coarse = |warnings: &[String]| {
        let about = |m: &&String| m.contains("a step of 16-bit depth is coarser than a shadow texel");
        warnings.iter().filter(about).count()
    };
    let sixteen = first_frame_warnings(scene, SunDepth::Unorm16);
    assert_eq!(coarse(&sixteen), 1, "{sixteen:?}");
    assert!(sixteen.iter().any(|m| m.contains("--sun-depth 32")), "{sixteen:?}");
    let float = first_frame_warnings(scene, SunDepth::Float32);
    assert_eq!(coarse(&float), 0, "{float:?}");
    let default = first_frame_warnings("assets/scenes/default.ron", SunDepth::Unorm16);
    assert_eq!(coarse(&default), 0, "{default:?}");
    std::fs::remove_file(&path).ok();
}
