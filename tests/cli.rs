//! The command line as a user meets it (values it refuses: `cli_values.rs`): sizes and output
//! paths are checked before any work, every failed write is a non-zero exit with the reason,
//! nothing half-written is left, and `check` loads everything `render` would.

// NOTE: each test binary uses its own share of the helpers.
#[allow(dead_code)]
#[path = "common/cli_run.rs"]
mod cli_run;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use cli_run::{penumbra, stderr};

/// The arguments of `penumbra render` of the default scene at 48×32, one frame.
const SMALL_RENDER: [&str; 8] = [
    "render",
    "assets/scenes/default.ron",
    "--width",
    "48",
    "--height",
    "32",
    "--frames",
    "1",
];

/// `penumbra render` of the default scene at 48×32, one frame, with `extra` arguments.
fn small_render(extra: &[&str]) -> Output {
    let mut args = SMALL_RENDER.to_vec();
    args.extend_from_slice(extra);
    penumbra(&args)
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A fresh scratch folder for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn bad_output_paths_fail_before_rendering_and_leave_nothing() {
    let dir = scratch("paths");
    let jpg = dir.join("out.jpg");
    let out = penumbra(&["render", "assets/scenes/default.ron", "--out", jpg.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        stderr(&out).trim_end(),
        format!("error: {}: unknown image type, expected a .png path", jpg.display())
    );
    assert!(stdout(&out).is_empty(), "nothing rendered: {}", stdout(&out));
    let shadow = dir.join("shadow.exr");
    let png = dir.join("out.png");
    let out = penumbra(&[
        "render",
        "assets/scenes/default.ron",
        "--out",
        png.to_str().unwrap(),
        "--shadow-out",
        shadow.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("expected a .png (16-bit greyscale) or .pfm (32-bit float) path"),
        "{}",
        stderr(&out)
    );
    // A folder where the image's folder should be.
    std::fs::write(dir.join("file"), b"x").unwrap();
    let under_file = dir.join("file/out.png");
    let out = penumbra(&[
        "render",
        "assets/scenes/default.ron",
        "--out",
        under_file.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("cannot create its folder"), "{}", stderr(&out));
    assert_eq!(files_in(&dir), ["file"], "no file left behind");
}

/// Linux's always-full device stands in for a full disk.
#[cfg(target_os = "linux")]
#[test]
fn a_write_that_fails_is_a_non_zero_exit() {
    let out = small_render(&["--out", "/dev/full"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    // NOTE: a Vulkan driver may print its own lines on stderr first.
    assert!(err.lines().any(|l| l.starts_with("error: /dev/full: ")), "{err}");
    assert!(err.to_lowercase().contains("no space left"), "{err}");
}

#[test]
fn a_render_writes_its_image_and_nothing_else() {
    let dir = scratch("render");
    let png = dir.join("sub/out.png");
    let pfm = dir.join("sub/shadow.pfm");
    let out = small_render(&["--out", png.to_str().unwrap(), "--shadow-out", pfm.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let image = image::open(&png).expect("a PNG was written").to_rgba8();
    assert_eq!(image.dimensions(), (48, 32));
    let header = "Pf\n48 32\n-1.0\n".len() as u64;
    assert_eq!(std::fs::metadata(&pfm).unwrap().len(), header + 48 * 32 * 4);
    assert_eq!(files_in(&dir.join("sub")), ["out.png", "shadow.pfm"]);
}

#[test]
fn check_loads_models_and_textures_like_render() {
    let out = penumbra(&["check", "assets/scenes/garden.ron", "assets/scenes/default.ron"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("garden.ron: ok ("), "{text}");
    assert!(text.contains(" mesh entities)"), "{text}");
    // A model whose buffer is cut short: the scene text is fine, the model is not.
    let dir = scratch("check");
    for name in ["fern.gltf", "fern_leaf.png"] {
        std::fs::copy(Path::new("assets/models").join(name), dir.join(name)).unwrap();
    }
    let bin = std::fs::read("assets/models/fern.bin").unwrap();
    std::fs::write(dir.join("fern.bin"), &bin[..bin.len() / 2]).unwrap();
    let scene = r#"Scene(
    camera: (position: (0, 2, 5), target: (0, 0, 0), fov: 60, near: 0.1, far: 100),
    sun: (direction: (0, -1, 0)),
    materials: { "m": () },
    objects: [(shape: Gltf(path: "fern.gltf"), material: "m")],
)"#;
    std::fs::write(dir.join("scene.ron"), scene).unwrap();
    let out = penumbra(&["check", dir.join("scene.ron").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("scene.ron: object 0: "), "{err}");
    assert!(err.contains("is truncated"), "{err}");
    assert!(err.contains("error: 1 of 1 scene files have errors"), "{err}");
}

#[test]
fn the_asset_root_is_the_scene_folder_unless_given() {
    let dir = scratch("root");
    std::fs::create_dir_all(dir.join("scenes")).unwrap();
    std::fs::copy("assets/textures/foliage.png", dir.join("leaf.png")).unwrap();
    let scene = r#"Scene(
    camera: (position: (0, 2, 5), target: (0, 0, 0), fov: 60, near: 0.1, far: 100),
    sun: (direction: (0, -1, 0)),
    materials: { "m": (texture: "../leaf.png") },
    objects: [(shape: Cuboid(size: (1, 1, 1)), material: "m")],
)"#;
    let path = dir.join("scenes/scene.ron");
    std::fs::write(&path, scene).unwrap();
    let out = penumbra(&["check", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("outside the asset folder"), "{}", stderr(&out));
    let out = penumbra(&["check", "--asset-root", dir.to_str().unwrap(), path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("scene.ron: ok (1 instances, 1 mesh entities)"),
        "{}",
        stdout(&out)
    );
}

/// The largest texture side of the adapter the tests run on.
fn max_texture_side() -> u32 {
    penumbra::render::GpuContext::headless()
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)")
        .limits
        .max_texture_side
}

#[test]
fn sizes_past_the_adapter_are_errors_and_textures_past_it_are_downscaled() {
    let max = max_texture_side();
    let wide = (max + 1).to_string();
    let out = penumbra(&["render", "assets/scenes/default.ron", "--width", &wide, "--height", "8"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let expected = format!("error: the render target width is {wide}; this GPU allows 1 to {max}");
    assert!(stderr(&out).lines().any(|l| l == expected), "{}", stderr(&out));

    // A texture one texel wider than the adapter allows (a PNG of a few hundred bytes).
    let dir = scratch("wide-texture");
    image::RgbaImage::from_pixel(max + 1, 1, image::Rgba([200, 180, 90, 255]))
        .save(dir.join("wide.png"))
        .unwrap();
    let scene = r#"Scene(
    camera: (position: (0, 2, 5), target: (0, 0, 0), fov: 60, near: 0.1, far: 100),
    sun: (direction: (0.3, -1, 0.2)),
    materials: { "m": (texture: "wide.png") },
    objects: [(shape: Plane(size: (10, 10)), material: "m"), (shape: Cuboid(size: (1, 1, 1)), material: "m")],
)"#;
    std::fs::write(dir.join("scene.ron"), scene).unwrap();
    let png = dir.join("out.png");
    let out = penumbra(&[
        "render",
        dir.join("scene.ron").to_str().unwrap(),
        "--width",
        "32",
        "--height",
        "24",
        "--frames",
        "1",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let warning = format!(
        "warning    image 0: {}×1 is larger than this GPU's largest texture ({max}); downscaled to {max}×1",
        max + 1
    );
    assert!(stdout(&out).lines().any(|l| l == warning), "{}", stdout(&out));
    assert!(png.is_file());
}

#[test]
fn the_instance_budget_is_set_on_the_command_line() {
    let out = penumbra(&["check", "assets/scenes/garden.ron"]);
    assert!(out.status.success(), "{}", stderr(&out));
    // Fewer than the scene's 12 instances: a located error at the grid that passes it.
    let out = penumbra(&["check", "--max-instances", "10", "assets/scenes/garden.ron"]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.starts_with("assets/scenes/garden.ron:28:24: expected at most 10 instances in all"),
        "{err}"
    );
    // More than its instances, fewer than the entities its ferns' primitives make.
    let out = penumbra(&["check", "--max-instances", "20", "assets/scenes/garden.ron"]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.starts_with("assets/scenes/garden.ron: the scene would spawn 111 mesh entities"),
        "{err}"
    );
}

#[test]
fn a_render_prints_its_summary_as_json_when_asked() {
    let dir = scratch("json");
    let image = dir.join("out.png");
    // The commit is the one the binary was built from, whatever the environment says.
    let out = Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(SMALL_RENDER)
        .args(["--json", "--mode", "msm", "--out", image.to_str().unwrap()])
        .env("PENUMBRA_COMMIT", "not-this-one")
        .output()
        .expect("the penumbra binary runs");
    assert!(out.status.success(), "{}", stderr(&out));
    let summary: serde_json::Value =
        serde_json::from_str(&stdout(&out)).unwrap_or_else(|e| panic!("{e}: {}", stdout(&out)));
    assert_eq!(summary["commit"], penumbra::BUILD_COMMIT);
    let hash = penumbra::BUILD_COMMIT.trim_end_matches("-dirty");
    assert!(
        penumbra::BUILD_COMMIT == "unknown" || (hash.len() == 12 && hash.chars().all(|c| c.is_ascii_hexdigit())),
        "{}",
        penumbra::BUILD_COMMIT
    );
    assert_eq!(summary["image"]["width"], 48);
    assert_eq!(summary["image"]["height"], 32);
    assert_eq!(summary["sun"]["mode"], "Msm");
    assert_eq!(summary["shadow_views"], 4);
    assert_eq!(summary["casters_per_view"].as_array().map(Vec::len), Some(4));
    assert!(summary["shadow_memory_bytes"].as_u64().unwrap() > 0);
    // lavapipe has timestamp queries: every pass is timed and the total is their sum.
    let passes = summary["gpu_ms"]["passes"].as_array().expect("passes");
    let names: Vec<&str> = passes.iter().filter_map(|p| p["pass"].as_str()).collect();
    assert!(names.contains(&"forward"), "{names:?}");
    let sum: f64 = passes.iter().filter_map(|p| p["ms"].as_f64()).sum();
    let total = summary["gpu_ms"]["total"].as_f64().expect("total");
    assert!((sum - total).abs() < 1e-9, "{sum} against {total}");
    assert!(image.is_file());
    std::fs::remove_dir_all(&dir).ok();
}

/// A scene with two problems on lines 2 and 5: a `far` before `near`, a misspelt material.
const BAD_SCENE: &str = r#"Scene(
    camera: (position: (0, 2, 5), target: (0, 0, 0), fov: 60, near: 0.1, far: 0.01),
    sun: (direction: (0, -1, 0)),
    materials: { "leaf": () },
    objects: [(shape: Cuboid(size: (1, 1, 1)), material: "leef")],
)
"#;

#[test]
fn errors_print_short_or_rich_as_asked() {
    let dir = scratch("error-format");
    let path = dir.join("bad.ron");
    std::fs::write(&path, BAD_SCENE).unwrap();
    let file = path.to_str().unwrap();
    // Short: one line per problem, then the summary; also the default when stderr is not a
    // terminal (as here).
    let out = penumbra(&["check", file, "--error-format", "short"]);
    assert_eq!(out.status.code(), Some(1));
    let short = stderr(&out);
    let lines: Vec<&str> = short.lines().collect();
    assert_eq!(lines.len(), 3, "{short}");
    assert!(lines[0].starts_with(&format!("{file}:2:79: expected a distance greater than `near`")));
    assert!(lines[1].starts_with(&format!("{file}:5:58: expected a material defined in `materials`")));
    assert!(lines[1].ends_with("found \"leef\"; did you mean \"leaf\"?"), "{short}");
    assert_eq!(lines[2], "error: 1 of 1 scene files have errors");
    assert_eq!(stderr(&penumbra(&["check", file])), short);
    // Rich: each problem with its line and a caret under the value; no colour off a terminal,
    // so the output is the same on every run. The flag may come before the command.
    let out = penumbra(&["--error-format", "rich", "check", file]);
    assert_eq!(out.status.code(), Some(1));
    let rich = stderr(&out);
    assert!(!rich.contains('\u{1b}'), "{rich:?}");
    let expected = format!(
        "error: expected a material defined in `materials` (\"leaf\") for `objects[0].material`, found \"leef\"
  --> {file}:5:58
  |
5 |     objects: [(shape: Cuboid(size: (1, 1, 1)), material: \"leef\")],
  |                                                          ^^^^^^
  |
  = help: did you mean \"leaf\"?
error: 1 of 1 scene files have errors
"
    );
    assert!(rich.ends_with(&expected), "{rich}");
    assert!(rich.starts_with("error: expected a distance greater than `near` (0.1) for `camera.far`, found 0.01\n"));
    assert_eq!(stderr(&penumbra(&["check", file, "--error-format", "rich"])), rich);
    // `render` fails on the scene before it needs a GPU, and prints it the same way.
    let image = dir.join("out.png");
    let out = penumbra(&[
        "render",
        file,
        "--out",
        image.to_str().unwrap(),
        "--error-format",
        "rich",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let rendered = stderr(&out);
    assert!(rendered.contains(&format!("  --> {file}:5:58\n")), "{rendered}");
    assert!(rendered.ends_with("  = help: did you mean \"leaf\"?\n"), "{rendered}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_broken_model_shows_its_json_line_under_the_scene_that_names_it() {
    let dir = scratch("model-json");
    std::fs::write(
        dir.join("broken.gltf"),
        "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [{} {}]\n}\n",
    )
    .unwrap();
    let scene = r#"Scene(
    camera: (position: (0, 2, 5), target: (0, 0, 0), fov: 60, near: 0.1, far: 100),
    sun: (direction: (0, -1, 0)),
    materials: { "m": () },
    objects: [(shape: Gltf(path: "broken.gltf"), material: "m")],
)"#;
    let path = dir.join("scene.ron");
    std::fs::write(&path, scene).unwrap();
    let scene = path.to_str().unwrap();
    let out = penumbra(&["check", scene, "--error-format", "short"]);
    let short = stderr(&out);
    assert!(short.starts_with(&format!("{scene}: object 0: ")), "{short}");
    assert!(
        short.contains("not valid glTF: expected `,` or `]` at line 3 column 16"),
        "{short}"
    );
    let out = penumbra(&["check", scene, "--error-format", "rich"]);
    let rich = stderr(&out);
    let model = std::fs::canonicalize(dir.join("broken.gltf")).unwrap();
    let expected = format!(
        "error: not valid glTF: expected `,` or `]`
  --> {}:3:16
  |
3 |   \"nodes\": [{{}} {{}}]
  |                ^
  |
  = note: while loading {scene}: object 0
error: 1 of 1 scene files have errors
",
        model.display()
    );
    assert_eq!(rich, expected);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn check_and_render_print_the_shadow_memory_and_fit_it_to_the_budget() {
    // The sun's three 1024² cascades in 16-bit depth (the renderer's default) take 6 MiB.
    let out = penumbra(&["check", "assets/scenes/night.ron"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(
        text.contains("  shadow memory 206.0 MiB of a 2048.0 MiB budget"),
        "{text}"
    );
    assert!(text.contains("    directional light sun: 3 × 1024², 6.0 MiB"), "{text}");
    assert!(text.contains("    point light lights[0]: 6 × 512², 30.0 MiB"), "{text}");
    let out = penumbra(&["check", "--shadow-budget", "100", "assets/scenes/night.ron"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(
        text.contains("warning: the shadow maps would take 206.0 MiB but the shadow-memory budget is 100.0 MiB: lowered point light lights[1] 512² to 256²"),
        "{text}"
    );
    let out = penumbra(&["check", "--shadow-budget", "3", "assets/scenes/night.ron"]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("night.ron: the shadow-memory budget of 3.0 MiB cannot hold the shadows of point light lights[0] (13.5 MiB at 256²)"),
        "{err}"
    );
    // The default scene's four 2048² cascades take 32 MiB (16-bit depth); 1 MiB holds four
    // of 256² (0.5 MiB), not of 512² (2 MiB).
    let out = small_render(&[
        "--shadow-budget",
        "1",
        "--out",
        scratch("budget").join("o.png").to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("with 256² texels per cascade, 0.5 MiB"), "{text}");
    assert!(text.contains("memory     0.5 MiB of a 1.0 MiB budget"), "{text}");
    assert!(
        text.contains("directional light sun: 4 × 256² (asked 2048²), 0.5 MiB"),
        "{text}"
    );
}

#[test]
fn contact_shadows_on_the_command_line_say_what_they_expect() {
    let out = small_render(&["--contact-shadows", "0.3,16"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains(
            "expected `length,steps,thickness,intensity` (metres 0.01-5, 0-64, metres 0.001-2, 0-1), found `0.3,16`"
        ),
        "{err}"
    );
    let out = small_render(&["--contact-shadows", "0.3,100,0.05,1"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("`contact_shadows.steps` is 100, expected an integer from 0 (off) to 64"),
        "{err}"
    );
    let png = scratch("contact").join("contact.png");
    let out = small_render(&["--contact-shadows", "--debug-contact", "--out", png.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(png.is_file(), "no image written");
}
