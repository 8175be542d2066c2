//! The regression corpus of hostile inputs (`tests/regressions/`, plus inputs too big to
//! check in, generated here): each gives its exact error, within a bounded amount of
//! memory and output. Memory is measured with a counting allocator (per thread, so tests
//! running in parallel do not disturb each other); time only with generous ceilings that
//! the old quadratic code passed by orders of magnitude.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use penumbra::scene::{SceneDesc, SceneError, SceneLimits};

/// The system allocator, counting this thread's live bytes and their peak.
struct Counting;

thread_local! {
    static LIVE: Cell<usize> = const { Cell::new(0) };
    static PEAK: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: every call is forwarded to the system allocator unchanged; the counters are
// const-initialised thread locals without destructors, so updating them never allocates.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = LIVE.try_with(|live| {
            live.set(live.get() + layout.size());
            PEAK.with(|peak| peak.set(peak.get().max(live.get())));
        });
        // SAFETY: same layout, forwarded.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        let _ = LIVE.try_with(|live| live.set(live.get().saturating_sub(layout.size())));
        // SAFETY: `ptr` came from `alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Runs `f`, returning its result and the most bytes it had allocated at once on this thread.
fn peak_bytes<R>(f: impl FnOnce() -> R) -> (R, usize) {
    let base = LIVE.with(Cell::get);
    PEAK.with(|peak| peak.set(base));
    let result = f();
    (result, PEAK.with(Cell::get) - base)
}

fn corpus(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/regressions")
        .join(file)
}

fn scene_error(file: &str) -> String {
    let path = corpus(file);
    match SceneDesc::load(&path) {
        Ok(_) => panic!("{file} loaded"),
        Err(e) => e
            .to_string()
            .replace(&format!("{}:", path.display()), &format!("{file}:")),
    }
}

fn gltf_error(file: &str) -> String {
    let path = corpus(file);
    match penumbra::gltf::load(&path) {
        Ok(_) => panic!("{file} loaded"),
        Err(e) => e
            .to_string()
            .replace(&format!("{}:", path.display()), &format!("{file}:")),
    }
}

/// A scene text with the given materials and objects (`objects` is the list's inside).
fn scene_with(materials: &str, objects: &str) -> String {
    format!(
        "Scene(camera: (position: (0, 2, 10), target: (0, 0, 0), fov: 60, near: 0.1, far: 100), \
         sun: (direction: (0, -1, 0)), materials: {{{materials}}}, objects: [{objects}])"
    )
}

#[test]
fn grids_over_the_instance_budget_in_all() {
    assert_eq!(
        scene_error("budget_grids.ron"),
        "budget_grids.ron:9:81: expected at most 1000000 instances in all objects and grids for \
         `objects[1].grid.count`, found 3000001 instances in all, the limit passed at this grid of \
         (1000, 1000, 1) = 1000000 copies"
    );
    // The budget is configurable; the instances are not made until iterated.
    let limits = SceneLimits {
        max_instances: 4_000_000,
        ..SceneLimits::default()
    };
    let ((), bytes) = peak_bytes(|| {
        let scene = SceneDesc::load_with(corpus("budget_grids.ron"), &limits).unwrap();
        assert_eq!(scene.instance_count(), 3_000_001);
    });
    assert!(bytes < 1 << 20, "{bytes} bytes to load three million instances");
}

#[test]
fn one_grid_over_the_instance_budget() {
    assert_eq!(
        scene_error("budget_one_grid.ron"),
        "budget_one_grid.ron:8:71: expected at most 1000000 copies in one grid for \
         `objects[0].grid.count`, found (10000, 1000, 1) = 10000000 copies"
    );
    let text = std::fs::read_to_string(corpus("budget_one_grid.ron")).unwrap();
    let limits = SceneLimits {
        max_instances: 1 << 40,
        ..SceneLimits::default()
    };
    assert_eq!(
        SceneDesc::from_str_with(&text, "g.ron", &limits)
            .unwrap()
            .instance_count(),
        10_000_000
    );
    // One grid never holds more than MAX_GRID_INSTANCES, whatever the budget.
    let text = text.replace("10000, 1000, 1", "10000, 1000, 2");
    let msg = SceneDesc::from_str_with(&text, "g.ron", &limits)
        .unwrap_err()
        .to_string();
    assert!(
        msg.starts_with("g.ron:8:71: expected at most 10000000 copies in one grid"),
        "{msg}"
    );
}

#[test]
fn thousands_of_grids_list_fifty_problems() {
    // Once reported as `ok (20000000000 instances)`.
    let grid = "(shape: Sphere(radius: 1), material: \"m\", grid: (count: (10000, 1000, 1), spacing: (1, 1, 1))),\n";
    let text = scene_with("\"m\": ()", &grid.repeat(2000));
    let msg = SceneDesc::from_str(&text, "many.ron").unwrap_err().to_string();
    let lines: Vec<&str> = msg.lines().collect();
    assert_eq!(lines.len(), 51, "{msg}");
    assert!(lines[0].starts_with("many.ron:1:"), "{}", lines[0]);
    assert!(lines[49].contains("`objects[49].grid.count`"), "{}", lines[49]);
    assert_eq!(lines[50], "many.ron: and 1950 more problems");
    match SceneDesc::from_str(&text, "many.ron") {
        Err(SceneError::Invalid { problems, .. }) => assert_eq!(problems.len(), 2000),
        other => panic!("{other:?}"),
    }
}

#[test]
fn undefined_material_lists_the_nearest_names() {
    assert_eq!(
        scene_error("undefined_material.ron"),
        "undefined_material.ron:10:52: expected a material defined in `materials` (\"stone\", \
         \"slate\", \"moss\", \"bark\", \"leaf\", and 4 more) for `objects[0].material`, \
         found \"stoen\"; did you mean \"stone\"?"
    );
}

#[test]
fn undefined_materials_give_bounded_output() {
    // Once a 468 KB file wrote 2 GB of errors, every object's error listing every name.
    let n = 20_000;
    let materials: String = (0..n).map(|i| format!("\"material{i}\": (), ")).collect();
    let objects: String = (0..n)
        .map(|i| format!("(shape: Sphere(radius: 1), material: \"x{i}\"), "))
        .collect();
    let text = scene_with(&materials, &objects);
    let (msg, bytes) = peak_bytes(|| SceneDesc::from_str(&text, "m.ron").unwrap_err().to_string());
    let lines: Vec<&str> = msg.lines().collect();
    assert_eq!(lines.len(), 51);
    assert_eq!(lines[50], "m.ron: and 19950 more problems");
    for line in &lines[..50] {
        assert_eq!(line.matches('"').count(), 2 * 6, "five names and the one found: {line}");
        assert!(line.contains(", and 19995 more) for `objects["), "{line}");
    }
    assert!(msg.len() < 16 * 1024, "{} bytes of errors", msg.len());
    assert!(
        bytes < 64 * text.len(),
        "{bytes} bytes for {} bytes of text",
        text.len()
    );
}

#[test]
fn locating_an_error_in_megabytes_of_nuls_costs_nothing() {
    // Once 56 bytes per character: 50 MB of NULs took 3 GB to report an error at 1:1.
    let text = "\0".repeat(8 << 20);
    let (msg, bytes) = peak_bytes(|| SceneDesc::from_str(&text, "nul.ron").unwrap_err().to_string());
    assert_eq!(msg, "nul.ron:1:1: expected `(` or `Scene(`, found `\0`");
    assert!(bytes < 64 * 1024, "{bytes} bytes");
    // Stray characters inside brackets make no nodes either.
    let text = format!("Scene(camera: ({}", "# ".repeat(4 << 20));
    let (msg, bytes) = peak_bytes(|| SceneDesc::from_str(&text, "hash.ron").unwrap_err().to_string());
    assert!(msg.starts_with("hash.ron:1:16: "), "{msg}");
    assert!(bytes < 64 * 1024, "{bytes} bytes");
}

#[test]
fn a_long_raw_string_is_scanned_in_linear_time() {
    // A raw string with many quotes, each followed by too few `#`, was scanned once per quote:
    // 1.2 MB took 55 s.
    let n = 600_000;
    let text = format!("Scene(camera: r{}\"{}", "#".repeat(n), "\"".repeat(n));
    let start = Instant::now();
    let (msg, bytes) = peak_bytes(|| SceneDesc::from_str(&text, "raw.ron").unwrap_err().to_string());
    assert_eq!(
        msg,
        "raw.ron:1:15: expected `(` or `Camera(` for `camera`, found `r#######################################...`"
    );
    assert!(bytes < 64 * 1024, "{bytes} bytes");
    assert!(start.elapsed() < Duration::from_secs(20), "{:?}", start.elapsed());
}

#[test]
fn shared_children_are_bounded() {
    // Each of 20 nodes lists the next one twice: 2^20 paths to the last node from a 1 KB file.
    assert_eq!(
        gltf_error("dag_children_drawn.gltf"),
        "dag_children_drawn.gltf: node 20: the scene draws more than 65536 mesh primitives (a node \
         is drawn once per path from the scene root)"
    );
    let (msg, bytes) = peak_bytes(|| gltf_error("dag_children_visits.gltf"));
    assert_eq!(
        msg,
        "dag_children_visits.gltf: node 20: more than 262144 node visits (a node listed as the child \
         of several parents is visited once per path from the scene root)"
    );
    assert!(bytes < 1 << 20, "{bytes} bytes");
}

#[test]
fn huge_accessors_without_storage_are_refused_before_reading() {
    // A sparse POSITION accessor of 2^24 vertices and no buffer view: once allocated in full.
    let (msg, bytes) = peak_bytes(|| gltf_error("sparse_huge_accessor.gltf"));
    assert_eq!(
        msg,
        "sparse_huge_accessor.gltf: mesh 0 primitive 0: 16777216 vertices once read; at most 4194304 \
         vertices per primitive"
    );
    assert!(bytes < 1 << 20, "{bytes} bytes");
    let (msg, bytes) = peak_bytes(|| gltf_error("sparse_model_total.gltf"));
    assert_eq!(
        msg,
        "sparse_model_total.gltf: mesh 0 primitive 2: 12582912 vertices once read; at most 8388608 \
         vertices per model"
    );
    assert!(bytes < 1 << 20, "{bytes} bytes");
}
