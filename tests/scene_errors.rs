//! The text of scene-loading errors: file name, `line:column`, and what was expected; plus
//! every shipped scene loading cleanly and nothing panicking on damaged input.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use penumbra::scene::{SceneDesc, SceneError};

/// A valid scene; tests break one thing in it. Line numbers are noted for the asserts.
const BASE: &str = r#"Scene(
    camera: (position: (0, 2, 10), target: (0, 1, 0), fov: 60, near: 0.1, far: 500),
    sun: (direction: (-1, -1, 0)),
    shadows: (cascade_count: 4, resolution: 2048),
    materials: {
        "ground": (base_color: (0.5, 0.5, 0.5, 1)),
        "leaf": (alpha: Mask(0.5)),
    },
    objects: [
        (shape: Plane(size: (100, 100)), material: "ground"),
        (shape: Cuboid(size: (1, 2, 1)), material: "ground", translation: (0, 1, 0)),
        (shape: Sphere(radius: 0.5), material: "leaf", translation: (2, 0.5, 0)),
    ],
)
"#;

const ORIGIN: &str = "scenes/test.ron";

/// `BASE` with each `(from, to)` replacement made; each `from` must occur exactly once.
fn edited(edits: &[(&str, &str)]) -> String {
    let mut text = BASE.to_owned();
    for (from, to) in edits {
        assert_eq!(text.matches(from).count(), 1, "`{from}` must occur once");
        text = text.replace(from, to);
    }
    text
}

/// The error message for `BASE` with the edits made.
fn error(edits: &[(&str, &str)]) -> String {
    match SceneDesc::from_str(&edited(edits), ORIGIN) {
        Ok(_) => panic!("the edited scene loaded: {edits:?}"),
        Err(e) => e.to_string(),
    }
}

fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets")
}

/// A fresh directory for files a test writes.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-scene-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn base_scene_is_valid() {
    let scene = SceneDesc::from_str(BASE, ORIGIN).unwrap();
    assert_eq!(scene.objects.len(), 3);
    assert_eq!(scene.instances().count(), 3);
}

#[test]
fn syntax_error_names_file_line_column_and_expected_token() {
    // The comma after the sun is missing: ron notices at the next field, line 4.
    let msg = error(&[("sun: (direction: (-1, -1, 0)),", "sun: (direction: (-1, -1, 0))")]);
    assert_eq!(msg, "scenes/test.ron:4:5: expected `,`, found `shadows`");

    let msg = error(&[("fov: 60,", "fov: 60 near: 1,")]);
    assert_eq!(msg, "scenes/test.ron:2:63: expected `,`, found `near`");

    let msg = error(&[("    ],\n)\n", "    ],\n")]);
    assert!(msg.starts_with("scenes/test.ron:13:7: expected more text"), "{msg}");
}

#[test]
fn type_mismatch_says_what_was_expected_for_which_field() {
    let msg = error(&[("fov: 60", "fov: \"wide\"")]);
    assert_eq!(
        msg,
        "scenes/test.ron:2:60: expected a number for `camera.fov`, found `\"wide\"`"
    );

    let msg = error(&[("(1, 2, 1)", "(1, 2)")]);
    assert_eq!(
        msg,
        "scenes/test.ron:11:30: expected 3 numbers in parentheses, like `(1, 2, 3)` for \
         `objects[1].shape.size`, found 2 elements"
    );
}

#[test]
fn a_float_where_an_integer_belongs() {
    let msg = error(&[("cascade_count: 4", "cascade_count: 2.5")]);
    assert_eq!(
        msg,
        "scenes/test.ron:4:30: expected an integer for `shadows.cascade_count`, found `2.5`"
    );
    let msg = error(&[("cascade_count: 4", "cascade_count: -1")]);
    assert_eq!(
        msg,
        "scenes/test.ron:4:30: expected a non-negative integer small enough for its type for \
         `shadows.cascade_count`, found `-1`"
    );
}

#[test]
fn unknown_field_lists_the_allowed_fields() {
    let msg = error(&[("radius: 0.5", "radius: 0.5, height: 2")]);
    assert_eq!(
        msg,
        "scenes/test.ron:12:37: expected one of the fields `radius` of `Sphere`, \
         found unknown field `height`"
    );

    let msg = error(&[("fov: 60", "fov_y: 60")]);
    assert_eq!(
        msg,
        "scenes/test.ron:2:55: expected one of the fields `position`, `target`, `up`, `fov`, \
         `near`, `far` of `Camera`, found unknown field `fov_y`"
    );

    let msg = error(&[("cascade_count: 4", "cascades: 4")]);
    assert!(
        msg.starts_with("scenes/test.ron:4:15: expected one of the fields `mode`, "),
        "{msg}"
    );
    assert!(msg.contains("`cascade_count`") && msg.ends_with("found unknown field `cascades`"));
}

#[test]
fn unknown_variant_lists_the_allowed_variants() {
    let msg = error(&[("Sphere(radius", "Ball(radius")]);
    assert_eq!(
        msg,
        "scenes/test.ron:12:17: expected one of `Plane`, `Cuboid`, `Sphere`, `Gltf` for \
         `objects[2].shape`, found unknown variant `Ball`"
    );
}

#[test]
fn missing_required_field() {
    let msg = error(&[("near: 0.1, ", "")]);
    assert_eq!(
        msg,
        "scenes/test.ron:2:72: expected the required field `near` in `camera`, found none"
    );
}

#[test]
fn zero_sun_direction() {
    let msg = error(&[("(-1, -1, 0)", "(0, 0, 0)")]);
    assert_eq!(
        msg,
        "scenes/test.ron:3:22: expected a finite, non-zero direction (the way the light \
         travels) for `sun.direction`, found (0, 0, 0)"
    );
}

#[test]
fn nan_sun_direction() {
    let msg = error(&[("(-1, -1, 0)", "(NaN, -1, 0)")]);
    assert_eq!(
        msg,
        "scenes/test.ron:3:22: expected a finite, non-zero direction (the way the light \
         travels) for `sun.direction`, found (NaN, -1, 0)"
    );
    let msg = error(&[("(-1, -1, 0)", "(-1, inf, 0)")]);
    assert!(msg.starts_with("scenes/test.ron:3:22: expected a finite, non-zero direction"));
}

#[test]
fn cascade_count_zero() {
    let msg = error(&[("cascade_count: 4", "cascade_count: 0")]);
    assert_eq!(
        msg,
        "scenes/test.ron:4:30: expected an integer from 1 to 4 for `shadows.cascade_count`, found 0"
    );
}

#[test]
fn cascade_count_five() {
    let msg = error(&[("cascade_count: 4", "cascade_count: 5")]);
    assert_eq!(
        msg,
        "scenes/test.ron:4:30: expected an integer from 1 to 4 for `shadows.cascade_count`, found 5"
    );
}

#[test]
fn clipmap_levels_and_extent_out_of_range() {
    let msg = error(&[("cascade_count: 4", "layout: Clipmap(levels: 9, level0_extent: 0.1)")]);
    let lines: Vec<&str> = msg.lines().collect();
    assert_eq!(
        lines[..2],
        [
            "scenes/test.ron:4:39: expected an integer from 1 to 8 for `shadows.layout.levels`, found 9",
            "scenes/test.ron:4:57: expected metres from 0.5 to 1e5 for `shadows.layout.level0_extent`, found 0.1",
        ],
        "{msg}"
    );
    let msg = error(&[("cascade_count: 4", "layout: Clipmap(levels: 6, level0_extnt: 32)")]);
    assert!(msg.contains("level0_extnt") && msg.contains("level0_extent"), "{msg}");
}

#[test]
fn resolution_out_of_range() {
    let msg = error(&[("resolution: 2048", "resolution: 100")]);
    assert_eq!(
        msg,
        "scenes/test.ron:4:45: expected texels per side from 256 to 4096 for \
         `shadows.resolution`, found 100"
    );
}

#[test]
fn undefined_material() {
    let msg = error(&[("material: \"leaf\"", "material: \"leef\"")]);
    assert_eq!(
        msg,
        "scenes/test.ron:12:48: expected a material defined in `materials` (\"leaf\", \
         \"ground\") for `objects[2].material`, found \"leef\"; did you mean \"leaf\"?"
    );
}

#[test]
fn camera_checks() {
    let msg = error(&[("target: (0, 1, 0)", "target: (0, 2, 10)")]);
    assert!(msg.starts_with("scenes/test.ron:2:44: expected a point different from `camera.position`"));
    let msg = error(&[("fov: 60", "fov: 180")]);
    assert!(msg.starts_with("scenes/test.ron:2:60: expected vertical degrees between 0 and 180"));
    let msg = error(&[("near: 0.1", "near: 0")]);
    assert!(
        msg.starts_with("scenes/test.ron:2:70: expected a distance greater than 0"),
        "{msg}"
    );
    let msg = error(&[("far: 500", "far: 0.05")]);
    assert_eq!(
        msg,
        "scenes/test.ron:2:80: expected a distance greater than `near` (0.1) for `camera.far`, \
         found 0.05"
    );
}

#[test]
fn sizes_cutoff_and_grid_checks() {
    let msg = error(&[("(100, 100)", "(100, 0)")]);
    assert!(
        msg.starts_with("scenes/test.ron:10:29: expected sizes greater than 0"),
        "{msg}"
    );
    let msg = error(&[("radius: 0.5", "radius: -0.5")]);
    assert!(
        msg.starts_with("scenes/test.ron:12:32: expected a radius greater than 0"),
        "{msg}"
    );
    let msg = error(&[("Mask(0.5)", "Mask(1.5)")]);
    assert_eq!(
        msg,
        "scenes/test.ron:7:30: expected an alpha cutoff greater than 0 and at most 1 for \
         `materials[\"leaf\"].alpha`, found 1.5"
    );
    let grid = "translation: (0, 1, 0), grid: (count: (10, 0, 10), spacing: (2, 0, 2))";
    let msg = error(&[("translation: (0, 1, 0)", grid)]);
    assert_eq!(
        msg,
        "scenes/test.ron:11:100: expected counts of at least 1 along each axis for \
         `objects[1].grid.count`, found (10, 0, 10)"
    );
    let grid = "grid: (count: (1000, 1000, 11), spacing: (1, 1, 1))";
    let msg = error(&[("translation: (0, 1, 0)", grid)]);
    assert_eq!(
        msg,
        "scenes/test.ron:11:76: expected at most 1000000 copies in one grid for \
         `objects[1].grid.count`, found (1000, 1000, 11) = 11000000 copies"
    );
}

#[test]
fn every_problem_is_listed_in_file_order() {
    let msg = error(&[
        ("far: 500", "far: 0.01"),
        ("(-1, -1, 0)", "(0, 0, 0)"),
        (
            "cascade_count: 4, resolution: 2048",
            "resolution: 100, cascade_count: 5",
        ),
        ("Mask(0.5)", "Mask(0)"),
        ("material: \"leaf\"", "material: \"bark\""),
        ("radius: 0.5", "radius: 0"),
    ]);
    let lines: Vec<&str> = msg.lines().collect();
    let prefixes = [
        "scenes/test.ron:2:80: expected a distance greater than `near` (0.1) for `camera.far`",
        "scenes/test.ron:3:22: expected a finite, non-zero direction",
        "scenes/test.ron:4:27: expected texels per side from 256 to 4096 for `shadows.resolution`",
        "scenes/test.ron:4:47: expected an integer from 1 to 4 for `shadows.cascade_count`",
        "scenes/test.ron:7:30: expected an alpha cutoff greater than 0 and at most 1",
        "scenes/test.ron:12:32: expected a radius greater than 0 (metres) for `objects[2].shape",
        "scenes/test.ron:12:46: expected a material defined in `materials`",
    ];
    assert_eq!(lines.len(), prefixes.len(), "{msg}");
    for (line, prefix) in lines.iter().zip(prefixes) {
        assert!(line.starts_with(prefix), "`{line}` should start with `{prefix}`");
    }
    // The structured form carries the same facts.
    let text = edited(&[("far: 500", "far: 0.01"), ("radius: 0.5", "radius: 0")]);
    match SceneDesc::from_str(&text, ORIGIN) {
        Err(SceneError::Invalid { origin, problems, .. }) => {
            assert_eq!(origin, ORIGIN);
            let fields: Vec<&str> = problems.iter().map(|p| p.field.as_str()).collect();
            assert_eq!(fields, ["camera.far", "objects[2].shape.radius"]);
            assert_eq!((problems[1].line, problems[1].column), (12, 32));
            assert_eq!(problems[1].found, "0");
        }
        other => panic!("expected SceneError::Invalid, got {other:?}"),
    }
}

#[test]
fn unreadable_file_names_the_path() {
    let dir = scratch("io");
    let path = dir.join("nowhere.ron");
    let err = SceneDesc::load(&path).unwrap_err();
    assert!(matches!(err, SceneError::Io { .. }));
    let msg = err.to_string();
    assert!(
        msg.starts_with(&format!("{}: cannot read the scene file: ", path.display())),
        "{msg}"
    );
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn missing_texture_is_reported_relative_to_the_scene_file() {
    let dir = scratch("texture");
    std::fs::create_dir_all(dir.join("textures")).unwrap();
    std::fs::write(dir.join("textures/leaf.png"), b"not checked").unwrap();
    let good = edited(&[(
        "(alpha: Mask(0.5))",
        "(texture: \"textures/leaf.png\", alpha: Mask(0.5))",
    )]);
    std::fs::write(dir.join("good.ron"), &good).unwrap();
    let scene = SceneDesc::load(dir.join("good.ron")).unwrap();
    let texture = scene.materials[1].texture.as_deref().unwrap();
    let resolved = scene.resolve_path(texture).unwrap();
    assert_eq!(
        resolved.path(),
        std::fs::canonicalize(dir.join("textures/leaf.png")).unwrap()
    );
    let outside = scene.resolve_path(std::path::Path::new("../leaf.png")).unwrap_err();
    assert!(outside.to_string().starts_with("outside the asset folder"), "{outside}");

    let bad = good.replace("leaf.png", "leaves.png");
    std::fs::write(dir.join("bad.ron"), &bad).unwrap();
    let msg = SceneDesc::load(dir.join("bad.ron")).unwrap_err().to_string();
    let file = dir.join("bad.ron");
    let expected = format!(
        "{}:7:27: expected an image file inside the asset folder (the path is relative to the \
         scene file) for `materials[\"leaf\"].texture`, found \"textures/leaves.png\" (no file at `",
        file.display()
    );
    assert!(msg.starts_with(&expected), "{msg}");
    // from_str does not look at the file system.
    SceneDesc::from_str(&bad, "bad.ron").unwrap();

    // Outside the asset folder (the scene's, here): the same words whether or not the file
    // exists, and nothing is read.
    std::fs::write(dir.with_extension("png"), b"outside").unwrap();
    let outside_name = format!(
        "../{}",
        dir.with_extension("png").file_name().unwrap().to_string_lossy()
    );
    let messages: Vec<String> = [outside_name.as_str(), "../absent.png"]
        .iter()
        .map(|name| {
            std::fs::write(dir.join("out.ron"), good.replace("textures/leaf.png", name)).unwrap();
            let msg = SceneDesc::load(dir.join("out.ron")).unwrap_err().to_string();
            msg.replace(name, "NAME")
        })
        .collect();
    assert_eq!(messages[0], messages[1]);
    let root = std::fs::canonicalize(&dir).unwrap();
    assert!(
        messages[0].ends_with(&format!(
            "found \"NAME\" (outside the asset folder `{}` (only relative paths inside it are read))",
            root.display()
        )),
        "{}",
        messages[0]
    );
    std::fs::remove_file(dir.with_extension("png")).ok();
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn every_shipped_scene_loads() {
    let dir = assets().join("scenes");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "ron") {
            let scene = SceneDesc::load(&path).unwrap_or_else(|e| panic!("{e}"));
            assert!(scene.instance_count() > 0, "{}", path.display());
            count += 1;
        }
    }
    assert!(count >= 4, "expected the four shipped scenes in {}", dir.display());
}

#[test]
fn shipped_scenes_have_what_they_promise() {
    let load = |name: &str| SceneDesc::load(assets().join("scenes").join(name)).unwrap();
    let default = load("default.ron");
    assert_eq!(default.shadows.map.cascades.count, 4);
    assert_eq!(default.shadows.filter.mode, penumbra::settings::ShadowMode::Pcss);
    assert!(default.materials.iter().any(|m| m.texture.is_some()));
    let field = load("field.ron");
    assert!(field.instance_count() >= 100_000, "{}", field.instance_count());
    let elevation = |s: &SceneDesc| {
        let d = s.sun.expect("the shipped scenes have a sun").direction.normalize();
        (-d.y).asin().to_degrees()
    };
    assert!((elevation(&default) - 35.0).abs() < 1.0);
    assert!((elevation(&load("thin.ron")) - 3.0).abs() < 0.5);
    assert!((elevation(&load("pillars.ron")) - 50.0).abs() < 1.0);
}

#[test]
fn many_materials_load_in_linear_time() {
    // Looking up each object's material by a linear scan took 12 s for 100k materials (in a
    // release build); now about as long as parsing (8 s in a debug build).
    let n = 100_000;
    let materials: String = (0..n).map(|i| format!("\"m{i}\": (), ")).collect();
    let objects: String = (0..n)
        .map(|i| format!("(shape: Sphere(radius: 1), material: \"m{}\"), ", n - 1 - i))
        .collect();
    let text = format!(
        "Scene(camera: (position: (0, 2, 10), target: (0, 0, 0), fov: 60, near: 0.1, far: 100), \
         sun: (direction: (0, -1, 0)), materials: {{{materials}}}, objects: [{objects}])"
    );
    let start = Instant::now();
    let scene = SceneDesc::from_str(&text, "m.ron").unwrap();
    assert_eq!(scene.instances().filter(|i| i.material == n - 1 - i.object).count(), n);
    assert!(start.elapsed() < Duration::from_secs(60), "{:?}", start.elapsed());
}

#[test]
fn scenes_in_the_format_doc_load() {
    let doc = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scene-format.md");
    let doc = std::fs::read_to_string(doc).unwrap();
    let mut count = 0;
    for block in doc.split("```ron\n").skip(1) {
        let code = block.split("```").next().unwrap();
        if code.contains("Scene(") {
            SceneDesc::from_str(code, "scene-format.md").unwrap_or_else(|e| panic!("{e}"));
            count += 1;
        }
    }
    assert!(count >= 1);
}

#[test]
fn contact_shadows_name_their_fields_and_load_with_defaults() {
    let msg = error(&[(
        "resolution: 2048",
        "resolution: 2048, contact_shadows: (steps: 16, depth: 0.1)",
    )]);
    assert!(msg.starts_with("scenes/test.ron:4:"), "{msg}");
    assert!(
        msg.ends_with(
            "expected one of the fields `length`, `steps`, `thickness`, `intensity` of `ContactShadows`, \
             found unknown field `depth`"
        ),
        "{msg}"
    );
    let text = edited(&[("resolution: 2048", "resolution: 2048, contact_shadows: (steps: 8)")]);
    let scene = SceneDesc::from_str(&text, ORIGIN).expect("contact shadows load");
    let c = scene.shadows.filter.contact;
    assert_eq!((c.steps, c.length, c.thickness, c.intensity), (8, 0.3, 0.02, 1.0));
}
