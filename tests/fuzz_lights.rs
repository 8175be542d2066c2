//! A structured mutation fuzzer for light lists and per-light shadow settings, run by
//! `cargo test` on a fixed budget: scenes with 0 to 300 lights of every kind, each field drawn
//! from valid values, values at the edges of their ranges and values past them (tiny and huge
//! numbers, directions too short to normalise, ranges inside the shadow near plane, unknown
//! filters), and `shadows` with random fields. Each mutant is loaded as `check` loads it; one
//! that loads runs a frame of the shadow systems (no GPU) under the software-Vulkan memory
//! budget. Judged: nothing panics; an error points into the file and is at most a few hundred
//! bytes; a scene `check` accepts is never repaired by the frame (no "out of range", no
//! "clamped", every shadowed light gets its view) and its shadow storages fit the budget, or
//! the budget's error names the lights it could not hold. Deterministic (a fixed-seed
//! generator).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::{Duration, Instant};

use bevy_app::App;
use penumbra::app::PreparedScene;
use penumbra::ecs::ShadowDiagnostics;
use penumbra::ecs::ShadowPlugin;
use penumbra::ecs::components::ViewportSize;
use penumbra::ecs::shadow_memory::{SOFTWARE_BUDGET, ShadowMemory, ShadowMemoryBudget};
use penumbra::scene::SceneDesc;

/// Time the fuzzer goes on for once its floor of mutants is judged.
const BUDGET: Duration = Duration::from_secs(10);
/// Mutants judged at least.
const FLOOR: usize = 300;
/// The longest one mutant may take (a debug build).
const SLOWEST: Duration = Duration::from_secs(5);

/// Numbers for any field: valid ones, the edges of the ranges, and past them.
const NUMBERS: &[&str] = &[
    "0",
    "1",
    "0.5",
    "2",
    "5",
    "30",
    "89",
    "89.0001",
    "90",
    "-1",
    "0.05",
    "0.0500001",
    "1e-45",
    "1e-30",
    "3e38",
    "1e39",
    "-3e38",
    "NaN",
    "inf",
    "256",
    "4096",
    "100000",
];

/// Ranges of positional lights: valid ones first (the last just past the shadow near plane),
/// then ones inside it or out of range.
const RANGES: &[&str] = &[
    "1",
    "2",
    "5",
    "12",
    "0.0500001",
    "0",
    "0.05",
    "1e-30",
    "-1",
    "NaN",
    "3e38",
];

/// Spot half-angles in degrees: valid ones first.
const ANGLES: &[&str] = &["1", "30", "45", "89", "0", "89.0001", "90", "1e-45", "-1", "NaN"];

/// Directions: valid ones, and ones too short or too long to normalise.
const DIRECTIONS: &[&str] = &[
    "(0, -1, 0)",
    "(0.3, -1, 0.2)",
    "(0, 0, 0)",
    "(0, -1e-30, 0)",
    "(1e-20, 0, 0)",
    "(3e38, 3e38, 0)",
    "(0, -1, NaN)",
];

/// Filters: every mode and an unknown one.
const MODES: &[&str] = &["Pcf", "Pcss", "Vsm", "Evsm", "Evsm4", "Msm", "Area"];

/// Shadow-setting fields, each with its own values (the first `valid` of them valid).
const SETTINGS: &[(&str, &[&str], usize)] = &[
    ("resolution", &["256", "1024", "4096", "4097", "255", "0", "100000"], 3),
    ("cascade_count", &["1", "4", "0", "5"], 2),
    ("pcf_radius", &["0", "5", "6"], 2),
    ("vsm_blur", &["0", "2", "8", "9"], 3),
    ("moment_blur", &["0", "0.03", "1", "1.5", "-1"], 3),
    ("max_distance", &["0.1", "120", "1e6", "0.01", "1e39"], 3),
    ("normal_offset", &["0", "5", "6"], 2),
    ("moment_contact_hardening", &["true", "false"], 2),
];

#[path = "common/xorshift.rs"]
mod xorshift;

use xorshift::Xorshift;

/// The generator, and whether this scene draws valid values only (so that long light lists
/// load too).
struct Rng(Xorshift, bool);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0.below(n)
    }

    /// An entry of `list`: one of the first `valid` (valid) entries seven times in eight.
    fn pick<'a>(&mut self, list: &[&'a str], valid: usize) -> &'a str {
        match self.below(8) {
            0 if !self.1 => list[self.below(list.len())],
            _ => list[self.below(valid.min(list.len()))],
        }
    }
}

/// A random `shadows: (...)` with a few fields.
fn shadows(rng: &mut Rng) -> String {
    let mut fields = vec![format!("mode: {}", rng.pick(MODES, 6))];
    for _ in 0..rng.below(4) {
        let (name, values, valid) = SETTINGS[rng.below(SETTINGS.len())];
        fields.push(format!("{name}: {}", rng.pick(values, valid)));
    }
    format!("shadows: ({})", fields.join(", "))
}

/// One random light entry.
fn light(rng: &mut Rng) -> String {
    let mut fields = Vec::new();
    let kind = ["Directional", "Spot", "Point"][rng.below(3)];
    if kind != "Point" {
        fields.push(format!("direction: {}", rng.pick(DIRECTIONS, 2)));
    }
    if kind != "Directional" {
        let (x, z) = (rng.below(21) as f32 - 10.0, rng.below(21) as f32 - 10.0);
        fields.push(format!("position: ({x}, {}, {z})", rng.pick(&["3", "0.5", "1e39"], 2)));
        fields.push(format!("range: {}", rng.pick(RANGES, 5)));
        if rng.below(2) == 0 {
            fields.push(format!("radius: {}", rng.pick(NUMBERS, 3)));
        }
    }
    if kind == "Spot" {
        fields.push(format!("outer_angle: {}", rng.pick(ANGLES, 4)));
        if rng.below(2) == 0 {
            fields.push(format!("inner_angle: {}", rng.pick(&["0", "0.5", "45", "-1"], 2)));
        }
    }
    if kind == "Directional" && rng.below(2) == 0 {
        fields.push(format!("angular_diameter: {}", rng.pick(NUMBERS, 4)));
    }
    if rng.below(3) == 0 {
        fields.push(format!("intensity: {}", rng.pick(NUMBERS, 5)));
    }
    if rng.below(4) == 0 {
        fields.push("shadows_enabled: false".to_owned());
    }
    if rng.below(2) == 0 {
        fields.push(shadows(rng));
    }
    format!("{kind}({})", fields.join(", "))
}

/// A scene with a random list of lights, and sometimes a sun with random `shadows`.
fn scene(rng: &mut Rng) -> String {
    rng.1 = rng.below(4) == 0;
    let count = [0, 1, 2, 5, 9, 20, 300][rng.below(7)];
    let lights: Vec<String> = (0..count).map(|_| light(rng)).collect();
    let sun = match rng.below(3) {
        0 => String::new(),
        _ => format!("sun: (direction: {}), {},", rng.pick(DIRECTIONS, 2), shadows(rng)),
    };
    format!(
        r#"Scene(
    camera: (position: (0, 6, 12), target: (0, 0, 0), fov: 60, near: 0.1, far: 200),
    {sun}
    lights: [
        {}
    ],
    materials: {{ "m": () }},
    objects: [
        (shape: Plane(size: (30, 30)), material: "m"),
        (shape: Cuboid(size: (1, 2, 1)), material: "m", translation: (0, 1, 0)),
    ],
)"#,
        lights.join(",\n        ")
    )
}

/// Warnings that mean the frame repaired or dropped something `check` accepted.
const REPAIRS: &[&str] = &[
    "out of range",
    "clamped",
    "no shadow view can be made",
    "degenerate transform",
];

/// Loads `text` as `check` does and, when it loads, runs one frame of the shadow systems;
/// Ok(Some(lights in the list)) for a scene that loads, Ok(None) for one refused with a good
/// error.
fn judge(text: &str) -> Result<Option<usize>, String> {
    let desc = match SceneDesc::from_str(text, "lights.ron") {
        Ok(desc) => desc,
        Err(e) => {
            let message = e.to_string();
            if !message.starts_with("lights.ron:") {
                return Err(format!("an error without a location: {message}"));
            }
            // NOTE: a long light list may have a problem in every light; each is one line.
            if message.lines().any(|l| l.len() > 600) {
                return Err(format!("an error line over 600 bytes: {message}"));
            }
            return Ok(None);
        }
    };
    let listed = desc.lights.len();
    let prepared = PreparedScene::new(&desc).map_err(|e| format!("does not spawn: {e}"))?;
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    app.insert_resource(ViewportSize {
        width: 640,
        height: 360,
    });
    app.insert_resource(ShadowMemoryBudget {
        bytes: SOFTWARE_BUDGET,
        ..ShadowMemoryBudget::default()
    });
    prepared.spawn(app.world_mut());
    app.update();
    let world = app.world();
    for warning in &world.resource::<ShadowDiagnostics>().current {
        if REPAIRS.iter().any(|r| warning.contains(r)) {
            return Err(format!("check accepted what the frame repaired: {warning}"));
        }
    }
    let memory = world.resource::<ShadowMemory>();
    if memory.total() > SOFTWARE_BUDGET {
        return Err(format!("over the budget: {:?}", memory.lines()));
    }
    if let Some(error) = &memory.error
        && !error.contains(" light ")
    {
        return Err(format!("a budget error that names no light: {error}"));
    }
    Ok(Some(listed))
}

#[test]
fn light_list_mutants_load_as_check_says_and_fit_the_memory_budget() {
    let mut rng = Rng(Xorshift(0x11_6475), false);
    let (mut mutants, mut loaded, mut with_lights, mut lights_loaded) = (0usize, 0usize, 0usize, 0usize);
    let start = Instant::now();
    while mutants < FLOOR || start.elapsed() < BUDGET {
        let text = scene(&mut rng);
        let began = Instant::now();
        let verdict = catch_unwind(AssertUnwindSafe(|| judge(&text)))
            .unwrap_or_else(|_| Err("panicked (see the message above)".to_owned()))
            .and_then(|ok| match began.elapsed() > SLOWEST {
                true => Err(format!("took {:?}", began.elapsed())),
                false => Ok(ok),
            });
        match verdict {
            Ok(Some(lights)) => {
                loaded += 1;
                with_lights += usize::from(lights > 0);
                lights_loaded += lights;
            }
            Ok(None) => {}
            Err(why) => {
                let file = std::env::temp_dir().join(format!("penumbra-lights-mutant-{mutants}.ron"));
                std::fs::write(&file, &text).ok();
                panic!("light mutant {mutants}: {why}; saved to {}", file.display());
            }
        }
        mutants += 1;
    }
    println!("lights: {mutants} mutants, {loaded} loaded ({with_lights} with lights, {lights_loaded} lights in all)");
    // Both outcomes must be exercised, or the test judges nothing.
    assert!(mutants >= FLOOR, "{mutants} mutants");
    assert!(loaded >= mutants / 10, "only {loaded} of {mutants} mutants loaded");
    assert!(
        mutants - loaded >= mutants / 4,
        "only {} of {mutants} refused",
        mutants - loaded
    );
    assert!(
        with_lights >= loaded / 3,
        "only {with_lights} of {loaded} loaded mutants had lights"
    );
}
