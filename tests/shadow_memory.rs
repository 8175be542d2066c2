//! The shadow-memory budget: the account the shadow systems fit before allocating is what
//! the renderer then allocates, with 32- or 16-bit sun depth (on a real wgpu device: lavapipe
//! in CI), the lights smallest on
//! screen are lowered first with one warning naming them, and a budget that cannot hold a
//! light is an error naming it and its bytes. The scenes of the hostile-input report (two
//! point lights with 4096² VSM; a sun with four 4096² MSM cascades and eight 4096² VSM spot
//! lights) are checked by the budget arithmetic alone, without allocating gigabytes. A paged
//! sun's page pool is taken from the budget before the other maps share it.

mod common;

use common::INSTALL;
use penumbra::app::{PreparedScene, RenderError, RenderRequest, render_scene_with, shadow_memory_of};
use penumbra::ecs::shadow_memory::{MIB, SOFTWARE_BUDGET, ShadowMemory, ShadowMemoryBudget};
use penumbra::render::{RenderOptions, SunDepth};
use penumbra::scene::SceneDesc;

/// A sun with `sun` shadows, then `lights` (RON entries), over a 40 m ground with a box.
fn scene(sun: &str, lights: &[String]) -> SceneDesc {
    let text = format!(
        r#"Scene(
            camera: (position: (0, 12, 18), target: (0, 0, 0), fov: 50, near: 0.1, far: 200),
            sun: (direction: (-0.4, -1, -0.3)),
            shadows: ({sun}),
            lights: [{}],
            materials: {{ "m": (base_color: (0.8, 0.8, 0.8, 1)) }},
            objects: [
                (shape: Plane(size: (40, 40)), material: "m"),
                (shape: Cuboid(size: (1, 2, 1)), material: "m", translation: (0, 1, 0)),
            ],
        )"#,
        lights.join(",\n")
    );
    SceneDesc::from_str(&text, "memory.ron").unwrap_or_else(|e| panic!("{e}"))
}

/// A spot light at `x` over the ground, with `shadows`.
fn spot(x: f32, shadows: &str) -> String {
    format!("Spot(position: ({x}, 6, 0), direction: (0, -1, 0), range: 12, outer_angle: 40, shadows: ({shadows}))")
}

/// A point light at `x`, `y` with `shadows`.
fn point(x: f32, y: f32, shadows: &str) -> String {
    format!("Point(position: ({x}, {y}, 0), range: 10, shadows: ({shadows}))")
}

/// The account of `desc`'s first frame in a 1280×720 view under `bytes`, without a GPU.
fn account(desc: &SceneDesc, bytes: u64) -> ShadowMemory {
    let budget = ShadowMemoryBudget {
        bytes,
        ..ShadowMemoryBudget::default()
    };
    shadow_memory_of(PreparedScene::new(desc).unwrap(), (1280, 720), budget)
}

#[test]
fn the_reported_scenes_that_ran_out_of_memory_are_lowered_to_the_budget() {
    // Two point lights with 4096² VSM: 1.9 GiB of faces and moments each, and a 1.5 GiB
    // scratch cube for the blur; the sun's one 1024² cascade in 16-bit depth: 2 MiB.
    let vsm = "mode: Vsm, resolution: 4096";
    let desc = scene(
        "resolution: 1024, cascade_count: 1",
        &[point(-5.0, 3.0, vsm), point(5.0, 3.0, vsm)],
    );
    let asked = account(&desc, u64::MAX);
    assert_eq!(
        asked.total(),
        2 * MIB + 2 * 6 * 4096 * 4096 * (4 + 16) + 6 * 4096 * 4096 * 16
    );
    let fitted = account(&desc, SOFTWARE_BUDGET);
    assert!(fitted.total() <= SOFTWARE_BUDGET, "{}", fitted.total());
    let sides: Vec<u32> = fitted.lights.iter().map(|l| l.granted).collect();
    // The two cubes share a face size: halved together until they fit (4096 → 1024).
    assert_eq!(sides, [1024, 1024, 1024], "{:?}", fitted.lines());
    let warning = fitted.warning.as_deref().unwrap();
    assert!(
        warning.contains("point light lights[0] 4096² to 1024²")
            && warning.contains("point light lights[1] 4096² to 1024²")
            && !warning.contains("directional"),
        "{warning}"
    );
    assert!(fitted.error.is_none());

    // A sun with four MSM cascades at 4096² and eight VSM spot lights at 4096².
    let spots: Vec<String> = (0..8)
        .map(|i| spot(-14.0 + 4.0 * i as f32, "mode: Vsm, resolution: 4096"))
        .collect();
    let desc = scene("mode: Msm, resolution: 4096", &spots);
    let asked = account(&desc, u64::MAX);
    assert!(asked.total() > 3 << 30, "{:?}", asked.lines());
    let fitted = account(&desc, SOFTWARE_BUDGET);
    assert!(fitted.total() <= SOFTWARE_BUDGET, "{:?}", fitted.lines());
    // The spot lights (smaller on screen than the sun) are lowered before the cascades.
    let sun = fitted.lights[0].granted;
    assert!(
        fitted.lights[1..].iter().all(|l| l.granted < sun || l.granted == 256),
        "{:?}",
        fitted.lines()
    );
}

#[test]
fn a_budget_too_small_for_a_light_at_256_is_an_error_naming_it_and_its_bytes() {
    let desc = scene("resolution: 1024", &[point(0.0, 3.0, "mode: Vsm, vsm_blur: 0")]);
    let memory = account(&desc, 2 * MIB);
    let error = memory.error.as_deref().unwrap();
    // 256² faces: 6 × 256² × (4 + 16) bytes.
    assert!(
        error.contains(
            "the shadow-memory budget of 2.0 MiB cannot hold the shadows of point light lights[0] (7.5 MiB at 256²)"
        ),
        "{error}"
    );
    assert_eq!(memory.lights[1].granted, 0);
    assert!(memory.total() <= 2 * MIB);
}

/// Renders `desc` for one 64×36 frame under `budget` bytes.
fn render(desc: &SceneDesc, budget: Option<u64>) -> Result<penumbra::app::HeadlessFrame, RenderError> {
    render_with(desc, budget, SunDepth::default())
}

/// [`render`] with the suns' layers in `depth`.
fn render_with(
    desc: &SceneDesc,
    budget: Option<u64>,
    depth: SunDepth,
) -> Result<penumbra::app::HeadlessFrame, RenderError> {
    render_scene_with(
        desc,
        &RenderRequest {
            width: 64,
            height: 36,
            frames: 1,
            tweak: None,
            analysis: false,
            options: RenderOptions {
                sun_depth: depth,
                ..RenderOptions::default()
            },
            shadow_budget: budget,
            count_fragments: false,
            camera_lod: None,
            camera_motion: Default::default(),
        },
    )
}

#[test]
fn the_renderer_allocates_what_the_account_says() {
    let spots = [
        spot(-4.0, "mode: Vsm, resolution: 1024"),
        spot(4.0, "mode: Pcf, resolution: 512"),
        point(0.0, 4.0, "mode: Vsm, resolution: 512, vsm_blur: 1"),
        point(8.0, 2.0, "mode: Pcss, resolution: 256"),
    ];
    let mut judged = 0;
    for sun in [
        "mode: Pcf, resolution: 1024",
        "mode: Msm, resolution: 1024",
        "mode: Evsm, resolution: 512, moment_contact_hardening: false, moment_blur: 0.1",
        "mode: Pcss, resolution: 1024, layout: Clipmap(levels: 5, level0_extent: 8)",
    ] {
        let desc = scene(sun, &spots);
        let runs = [None, Some(64 * MIB), Some(40 * MIB)]
            .into_iter()
            .flat_map(|b| [SunDepth::Float32, SunDepth::Unorm16].map(|d| (b, d)));
        for (budget, depth) in runs {
            let frame = render_with(&desc, budget, depth).expect(INSTALL);
            let memory = &frame.memory;
            assert_eq!(
                frame.report.shadow_memory,
                memory.total(),
                "{sun}, budget {budget:?}, {depth:?}: allocated {} bytes, the account says {:?}",
                frame.report.shadow_memory,
                memory.lines()
            );
            assert!(memory.total() <= memory.budget, "{:?}", memory.lines());
            let lowered = memory.lights.iter().filter(|l| l.granted < l.asked).count();
            assert_eq!(memory.warning.is_some(), lowered > 0, "{:?}", memory.lines());
            if budget.is_some() {
                assert!(
                    lowered > 0,
                    "{sun}, budget {budget:?}: nothing lowered: {:?}",
                    memory.lines()
                );
            }
            judged += 1;
        }
    }
    assert_eq!(judged, 24);
}

#[test]
fn a_render_over_any_budget_fails_with_the_accounts_error() {
    let desc = scene("resolution: 1024", &[point(0.0, 3.0, "mode: Vsm, vsm_blur: 0")]);
    // A quarter of a MiB holds neither the point light's cube nor the sun's four cascades
    // at 256² (16-bit depth, the default: 0.5 MiB).
    let error = match render(&desc, Some(MIB / 4)) {
        Err(RenderError::ShadowMemory(e)) => e,
        Err(other) => panic!("{other}"),
        Ok(_) => panic!("a 0.25 MiB budget rendered"),
    };
    assert!(error.contains("point light lights[0] (7.5 MiB at 256²)"), "{error}");
    assert!(error.contains("directional light sun (0.5 MiB at 256²)"), "{error}");
}

#[test]
fn a_paged_suns_pool_is_taken_from_the_budget_before_the_other_maps() {
    let big = "resolution: 4096";
    let desc = scene(
        "layout: VirtualClipmap(pool_pages: 1000)",
        &[spot(-4.0, big), spot(4.0, big)],
    );
    // NOTE: 1000 pages fill an atlas of 32² pages of 128²: 4096² texels of 4 bytes.
    let pool = 4096 * 4096 * 4;
    let asked = account(&desc, u64::MAX);
    let spots = 2 * 4096 * 4096 * 4;
    assert_eq!(
        (asked.pages, asked.total()),
        (pool, pool + spots),
        "{:?}",
        asked.lines()
    );
    assert_eq!(asked.lights[0].bytes, pool, "{:?}", asked.lines());
    assert!(asked.lines()[0].contains("page pool 64.0 MiB"), "{:?}", asked.lines());
    let fitted = account(&desc, pool + spots / 2);
    let sides: Vec<u32> = fitted.lights.iter().map(|l| l.granted).collect();
    assert!(fitted.total() <= pool + spots / 2, "{:?}", fitted.lines());
    assert!(sides[1] < 4096 && sides[2] < 4096, "{:?}", fitted.lines());
    let warning = fitted.warning.as_deref().unwrap_or_default();
    assert!(
        warning.contains("spot light lights[0]") && !warning.contains("page pool"),
        "{warning}"
    );
    let under = account(&desc, pool / 2);
    let warning = under.warning.as_deref().unwrap_or_default();
    assert!(
        warning.contains("the page pool of directional light")
            && warning.contains("(64.0 MiB) is over the shadow-memory budget of 32.0 MiB"),
        "{warning}"
    );
    assert_eq!(under.pages, pool, "the pool is kept: {:?}", under.lines());
    // NOTE: with EVSM the pool holds 32-bit moments (16 bytes a texel) beside its depth, and
    // with contact hardening their mips (4096² down to 64²).
    let evsm = |hardening| {
        let sun = format!(
            "layout: VirtualClipmap(pool_pages: 1000), mode: Evsm, moment_precision: Fp32, moment_contact_hardening: {hardening}"
        );
        account(&scene(&sun, &[]), u64::MAX)
    };
    let fixed = evsm(false);
    assert_eq!(
        (fixed.pages, fixed.total()),
        (pool * 5, pool * 5),
        "{:?}",
        fixed.lines()
    );
    let mips: u64 = (0..7).map(|k| (4096u64 >> k).pow(2) * 16).sum();
    let hardened = evsm(true);
    assert_eq!(hardened.pages, pool + mips, "{:?}", hardened.lines());
}
