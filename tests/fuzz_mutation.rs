//! A fixed-budget mutation fuzzer on the stable toolchain, run by `cargo test`: mutants of
//! the shipped scenes, of settings files and of the sample glTF model (byte flips,
//! insertions, deletions, splices, extreme numbers, duplicated sections) must never panic,
//! must each finish quickly, and every scene or settings error must point at a line and
//! column inside the mutant. Deterministic (a fixed-seed xorshift generator); each target
//! runs at least a floor of mutants and then goes on until its time budget is spent. See
//! `docs/fuzzing.md` for the coverage-guided fuzz targets that go further. Also: every
//! truncation of a shipped scene is an error, and pathological nesting and garbage never
//! load (`damaged_input_never_panics`).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use penumbra::scene::{DEFAULT_MAX_INSTANCES, SceneDesc, SceneError, settings_from_str, settings_to_ron};
use penumbra::settings::{ShadowMode, ShadowSettings};

/// Time each target goes on for once its floor is reached (three targets run in parallel).
const BUDGET: Duration = Duration::from_secs(15);

/// The longest one mutant may take (a debug build; they take milliseconds).
const SLOWEST: Duration = Duration::from_secs(5);

/// Text that mutations insert: RON's punctuation, keywords and awkward values.
const PIECES: &[&str] = &[
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    ",",
    ":",
    "\"",
    "'",
    "/*",
    "*/",
    "//",
    "#",
    "!",
    "-",
    "\n",
    "é",
    "\0",
    "\\",
    "r#\"",
    "b'",
    "#![enable(implicit_some)]",
    "Some(",
    "None",
    "true",
    "Scene",
    "Grid",
    "Mask(",
    "Gltf(path: \"",
    "grid: (count: (1000, 1000, 1000), spacing: (1, 1, 1)),",
    "material: \"nope\",",
    "\u{feff}",
];

/// Extreme numbers that replace the numbers of a text.
const NUMBERS: &[&str] = &[
    "1e39",
    "-1e39",
    "-0",
    "0",
    "NaN",
    "inf",
    "-inf",
    "1e-45",
    "-1",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "340282366920938463463374607431768211456",
    "0x7fffffff",
    "1_000_000",
    "9e999",
    "1e999",
    "0x",
    "1_",
];

#[path = "common/xorshift.rs"]
mod xorshift;

use xorshift::Xorshift as Rng;

/// One random mutation of `bytes` (a few of them at times); `pool` supplies splices.
fn mutate(rng: &mut Rng, bytes: &[u8], pool: &[Vec<u8>]) -> Vec<u8> {
    let mut out = bytes.to_vec();
    for _ in 0..1 + rng.below(3) {
        let len = out.len();
        let at = rng.below(len + 1);
        match rng.below(7) {
            0 if len > 0 => out[at.min(len - 1)] ^= 1 << rng.below(8),
            1 => {
                let piece = PIECES[rng.below(PIECES.len())];
                out.splice(at..at, piece.bytes());
            }
            2 => {
                let end = (at + 1 + rng.below(16)).min(len);
                out.drain(at..end);
            }
            3 => {
                // A run of bytes from another seed (or this one) spliced in: whole tokens and
                // lines in the wrong place.
                let other = &pool[rng.below(pool.len())];
                let from = rng.below(other.len());
                let end = (from + 1 + rng.below(64)).min(other.len());
                out.splice(at..at, other[from..end].iter().copied());
            }
            4 => replace_number(rng, &mut out),
            5 if len > 0 => {
                // A section (a run of whole lines) written twice.
                let start = out[..at].iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
                let lines = 1 + rng.below(6);
                let mut end = at;
                for _ in 0..lines {
                    end = out[end.min(len)..]
                        .iter()
                        .position(|&b| b == b'\n')
                        .map_or(len, |i| end + i + 1);
                }
                let section = out[start..end.min(len)].to_vec();
                out.splice(start..start, section);
            }
            _ => out.truncate(at),
        }
    }
    out
}

/// Replaces one number of `text` (a run of digits, with its sign, point and exponent) by an
/// extreme one.
fn replace_number(rng: &mut Rng, text: &mut Vec<u8>) {
    let starts: Vec<usize> = (0..text.len())
        .filter(|&i| text[i].is_ascii_digit() && (i == 0 || !text[i - 1].is_ascii_alphanumeric()))
        .collect();
    if starts.is_empty() {
        return;
    }
    let start = starts[rng.below(starts.len())];
    let end = (start..text.len())
        .find(|&i| !(text[i].is_ascii_alphanumeric() || matches!(text[i], b'.' | b'_')))
        .unwrap_or(text.len());
    let number = NUMBERS[rng.below(NUMBERS.len())];
    text.splice(start..end, number.bytes());
}

/// Whether `line:column` (1-based, columns in characters) lies in `text` or just after its
/// end (where "expected more text" errors point).
fn inside(text: &str, line: usize, column: usize) -> bool {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let lines: Vec<&str> = text.split('\n').collect();
    line >= 1 && line <= lines.len() && column >= 1 && column <= lines[line - 1].chars().count() + 1
}

/// Checks a scene or settings error: it names the origin and points inside the text.
fn check_located(text: &str, err: &SceneError) -> Result<(), String> {
    let message = err.to_string();
    if !message.starts_with("mutant.ron:") {
        return Err(format!("the error does not name the file: {message}"));
    }
    let positions: Vec<(usize, usize)> = match err {
        SceneError::Parse { line, column, .. } => vec![(*line, *column)],
        SceneError::Invalid { problems, .. } => problems.iter().map(|p| (p.line, p.column)).collect(),
        other => return Err(format!("unexpected error kind: {other}")),
    };
    match positions.iter().find(|(l, c)| !inside(text, *l, *c)) {
        Some((l, c)) => Err(format!("{l}:{c} is outside the text: {message}")),
        None => Ok(()),
    }
}

/// What a fuzzing run judged.
#[derive(Debug, Default)]
struct Tally {
    mutants: usize,
    loaded: usize,
    rejected: usize,
    slowest: Duration,
}

/// Runs `judge` on mutants of `seeds` until `floor` mutants are judged and the budget is
/// spent; panics (with the mutant saved to a file) on the first failure.
fn fuzz(
    name: &str,
    seed: u64,
    seeds: &[Vec<u8>],
    floor: usize,
    judge: impl Fn(&[u8]) -> Result<bool, String>,
) -> Tally {
    let mut rng = Rng(seed);
    let mut tally = Tally::default();
    let start = Instant::now();
    while tally.mutants < floor || start.elapsed() < BUDGET {
        let base = &seeds[rng.below(seeds.len())];
        let mutant = mutate(&mut rng, base, seeds);
        let began = Instant::now();
        let verdict = catch_unwind(AssertUnwindSafe(|| judge(&mutant)))
            .unwrap_or_else(|_| Err("panicked (see the message above)".to_owned()));
        let took = began.elapsed();
        let verdict = verdict.and_then(|ok| match took > SLOWEST {
            true => Err(format!("took {took:?}")),
            false => Ok(ok),
        });
        match verdict {
            Ok(true) => tally.loaded += 1,
            Ok(false) => tally.rejected += 1,
            Err(why) => {
                let file = std::env::temp_dir().join(format!("penumbra-{name}-mutant-{}", tally.mutants));
                std::fs::write(&file, &mutant).ok();
                panic!("{name} mutant {} {why}; saved to {}", tally.mutants, file.display());
            }
        }
        tally.slowest = tally.slowest.max(took);
        tally.mutants += 1;
    }
    let rate = tally.mutants as f64 / start.elapsed().as_secs_f64();
    println!("{name}: {tally:?}, {rate:.0} mutants/s");
    tally
}

fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets")
}

/// Every `.ron` file of the given asset folders.
fn ron_files(folders: &[&str]) -> Vec<Vec<u8>> {
    let mut files = Vec::new();
    for folder in folders {
        for entry in std::fs::read_dir(assets().join(folder)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "ron") {
                files.push(std::fs::read(path).unwrap());
            }
        }
    }
    files
}

#[test]
fn scene_mutants_never_panic_and_errors_are_located() {
    let seeds = ron_files(&["scenes", "bench"]);
    assert!(seeds.len() >= 6, "the shipped scenes");
    let tally = fuzz("scene", 0x5CE7E, &seeds, 2000, |bytes| {
        let text = String::from_utf8_lossy(bytes);
        match SceneDesc::from_str(&text, "mutant.ron") {
            Ok(scene) => {
                if scene.instance_count() > DEFAULT_MAX_INSTANCES {
                    return Err(format!("{} instances passed the budget", scene.instance_count()));
                }
                for instance in scene.instances().take(1000) {
                    std::hint::black_box(instance.matrix());
                }
                Ok(true)
            }
            Err(err) => check_located(&text, &err).map(|()| false),
        }
    });
    // The mutants must exercise both outcomes, or the test judges nothing.
    assert!(tally.mutants >= 2000, "{tally:?}");
    assert!(tally.rejected >= tally.mutants / 4, "{tally:?}");
    assert!(tally.loaded >= tally.mutants / 50, "{tally:?}");
}

#[test]
fn settings_mutants_never_panic_and_errors_are_located() {
    let custom = {
        let mut s = ShadowSettings::default();
        s.filter.mode = ShadowMode::Pcss;
        s.map.cascades.count = 3;
        s.map.cascades.split_lambda = 0.25;
        s
    };
    let seeds: Vec<Vec<u8>> = [settings_to_ron(&ShadowSettings::default()), settings_to_ron(&custom)]
        .into_iter()
        .chain(["ShadowSettings(mode: Pcss, resolution: 1024)".to_owned()])
        .map(String::into_bytes)
        .collect();
    let tally = fuzz("settings", 0x5E77, &seeds, 2000, |bytes| {
        let text = String::from_utf8_lossy(bytes);
        match settings_from_str(&text, "mutant.ron") {
            Ok(_) => Ok(true),
            Err(err) => check_located(&text, &err).map(|()| false),
        }
    });
    assert!(tally.mutants >= 2000, "{tally:?}");
    assert!(tally.rejected >= tally.mutants / 4, "{tally:?}");
    // NOTE: the settings text holds `contact_shadows: (length, steps, thickness,
    // intensity)` since contact shadows came: more of a mutant's bytes fall in nested
    // fields, and about 1.95-1.99 % of the mutants load (56 428 and 103 628 mutants), under
    // the 2 % the other corpora keep.
    assert!(tally.loaded >= tally.mutants / 60, "{tally:?}");
}

/// A scratch folder holding the sample model's buffer and image, removed when dropped.
struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
fn gltf_mutants_never_panic_and_errors_name_the_file() {
    let models = assets().join("models");
    let dir = Scratch(std::env::temp_dir().join(format!("penumbra-fuzz-mutation-{}", std::process::id())));
    std::fs::create_dir_all(&dir.0).unwrap();
    for file in ["fern.bin", "fern_leaf.png"] {
        std::fs::copy(models.join(file), dir.0.join(file)).unwrap();
    }
    let gltf = std::fs::read(models.join("fern.gltf")).unwrap();
    let bin = std::fs::read(models.join("fern.bin")).unwrap();
    // The JSON is what is mutated most; the buffer now and then (it is read through the URI).
    let seeds = vec![gltf.clone(), gltf, bin.clone()];
    let path = dir.0.join("mutant.gltf");
    let tally = fuzz("gltf", 0x61F7, &seeds, 300, |bytes| {
        // A mutant of the buffer goes in its place, with the sample JSON.
        let is_bin = bytes.first() != Some(&b'{') && !bytes.starts_with(b"glTF") && bytes.len() < 4096;
        if is_bin && !bytes.is_empty() {
            std::fs::write(dir.0.join("fern.bin"), bytes).map_err(|e| e.to_string())?;
            std::fs::copy(models.join("fern.gltf"), &path).map_err(|e| e.to_string())?;
        } else {
            std::fs::write(&path, bytes).map_err(|e| e.to_string())?;
        }
        let result = penumbra::gltf::load(&path);
        std::fs::write(dir.0.join("fern.bin"), &bin).map_err(|e| e.to_string())?;
        match result {
            Ok(model) => {
                std::hint::black_box(model.nodes.len());
                Ok(true)
            }
            Err(err) => {
                let message = err.to_string();
                match message.starts_with(&format!("{}: ", path.display())) {
                    true => Ok(false),
                    false => Err(format!("the error does not name the file: {message}")),
                }
            }
        }
    });
    assert!(tally.mutants >= 300, "{tally:?}");
    assert!(tally.rejected >= tally.mutants / 4, "{tally:?}");
    assert!(tally.loaded >= tally.mutants / 100, "{tally:?}");
}

/// Tiny generator for the mutations below (the test must not depend on an outside crate).
struct Lcg(u64);

impl Lcg {
    fn below(&mut self, n: usize) -> usize {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 33) as usize) % n.max(1)
    }
}

/// Loads `text` and, when it loads, walks its instances: neither may panic.
fn exercise(text: &str) -> bool {
    match SceneDesc::from_str(text, "fuzz.ron") {
        Ok(scene) => {
            for instance in scene.instances().take(1000) {
                std::hint::black_box(instance.matrix());
            }
            true
        }
        Err(e) => {
            assert!(e.to_string().starts_with("fuzz.ron:"), "{e}");
            false
        }
    }
}

#[test]
fn damaged_input_never_panics() {
    let dir = assets().join("scenes");
    let texts: Vec<String> = ["default.ron", "thin.ron", "pillars.ron"]
        .iter()
        .map(|f| std::fs::read_to_string(dir.join(f)).unwrap())
        .collect();
    // RON's punctuation and keywords, plus numbers at and past the edges of their types.
    let pieces: Vec<&str> = PIECES.iter().chain(NUMBERS).copied().collect();
    let mut rng = Lcg(0x5eed);
    for text in &texts {
        let last_paren = text.rfind(')').unwrap();
        // Every truncation before the final `)` is an error.
        for (cut, _) in text.char_indices().filter(|(i, _)| *i <= last_paren) {
            assert!(!exercise(&text[..cut]), "truncated at byte {cut} and still loaded");
        }
        // Random insertions, deletions and replacements.
        let bounds: Vec<usize> = text.char_indices().map(|(i, _)| i).chain([text.len()]).collect();
        for _ in 0..1500 {
            let a = bounds[rng.below(bounds.len())];
            let b = bounds[(bounds.iter().position(|&x| x == a).unwrap() + rng.below(4)).min(bounds.len() - 1)];
            let piece = if rng.below(3) == 0 {
                ""
            } else {
                pieces[rng.below(pieces.len())]
            };
            exercise(&format!("{}{piece}{}", &text[..a], &text[b..]));
        }
    }
    // Pathological nesting and garbage.
    for garbage in [
        "(".repeat(100_000),
        "[".repeat(100_000),
        "Scene(".repeat(10_000),
        "/*".repeat(1000),
        "\"".to_owned(),
        String::new(),
        "\u{feff}".to_owned(),
        "r####\"".to_owned(),
        "Scene(camera: (position: (0, 0, 0), target: (0, 0, -1), fov: 60, near: 0.1, far: 1e39))".to_owned(),
    ] {
        assert!(!exercise(&garbage));
    }
}
