//! Errors rendered with their source line: the rich form of scene, settings and glTF errors
//! (`--> file:line:column`, the line, a caret under the offending token, `= help: did you
//! mean ...?`), and "did you mean" in the one-line form.

use penumbra::diagnostic::{ErrorStyle, render_error};
use penumbra::scene::{SceneDesc, SceneError, settings_from_str};

/// A valid scene; tests break one thing in it.
const BASE: &str = r#"Scene(
    camera: (position: (0, 2, 10), target: (0, 1, 0), fov: 60, near: 0.1, far: 500),
    sun: (direction: (-1, -1, 0)),
    shadows: (mode: Pcss, cascade_count: 4),
    materials: { "ground": (), "leaf": (alpha: Mask(0.5)), "bark": () },
    objects: [
        (shape: Plane(size: (100, 100)), material: "ground"),
        (shape: Sphere(radius: 0.5), material: "leaf"),
    ],
)
"#;

const RICH: ErrorStyle = ErrorStyle::Rich { color: false };

/// The error of `BASE` with each `(from, to)` replacement made.
fn scene_error(edits: &[(&str, &str)]) -> SceneError {
    let mut text = BASE.to_owned();
    for (from, to) in edits {
        assert_eq!(text.matches(from).count(), 1, "`{from}` must occur once");
        text = text.replace(from, to);
    }
    SceneDesc::from_str(&text, "scene.ron").expect_err("the edited scene must not load")
}

/// Each source line a rich rendering shows, with the text its carets underline:
/// `(line number, line, underlined text)`.
fn underlined(rendered: &str) -> Vec<(usize, String, String)> {
    let lines: Vec<&str> = rendered.lines().collect();
    let mut found = Vec::new();
    for pair in lines.windows(2) {
        let (Some((number, source)), Some((_, carets))) = (pair[0].split_once(" | "), pair[1].split_once(" | ")) else {
            continue;
        };
        let Ok(number) = number.trim().parse::<usize>() else {
            continue;
        };
        let start = carets.chars().take_while(|&c| c == ' ').count();
        let len = carets.chars().skip(start).take_while(|&c| c == '^').count();
        let under: String = source.chars().skip(start).take(len).collect();
        found.push((number, source.to_owned(), under));
    }
    found
}

#[test]
fn a_parse_error_shows_its_line_with_a_caret_under_the_token() {
    let err = scene_error(&[("fov: 60", "fov: \"wide\"")]);
    let short = render_error(&err, ErrorStyle::Short);
    assert_eq!(
        short,
        "scene.ron:2:60: expected a number for `camera.fov`, found `\"wide\"`"
    );
    assert_eq!(short, err.to_string());
    let rich = render_error(&err, RICH);
    let line = "    camera: (position: (0, 2, 10), target: (0, 1, 0), fov: \"wide\", near: 0.1, far: 500),";
    let expected = format!(
        "error: expected a number for `camera.fov`, found `\"wide\"`\n  --> scene.ron:2:60\n  |\n2 | {line}\n  | {}^^^^^^",
        " ".repeat(59)
    );
    assert_eq!(rich, expected);
}

#[test]
fn an_invalid_scene_shows_every_problem_with_its_line() {
    let err = scene_error(&[("far: 500", "far: 0.01"), ("(-1, -1, 0)", "(0, 0, 0)")]);
    assert_eq!(err.to_string().lines().count(), 2);
    let rich = render_error(&err, RICH);
    let expected = "\
error: expected a distance greater than `near` (0.1) for `camera.far`, found 0.01
  --> scene.ron:2:80
  |
2 |     camera: (position: (0, 2, 10), target: (0, 1, 0), fov: 60, near: 0.1, far: 0.01),
  |                                                                                ^^^^

error: expected a finite, non-zero direction (the way the light travels) for `sun.direction`, found (0, 0, 0)
  --> scene.ron:3:22
  |
3 |     sun: (direction: (0, 0, 0)),
  |                      ^^^^^^^^^";
    assert_eq!(rich, expected);
}

#[test]
fn an_unknown_field_suggests_the_nearest_one() {
    let err = scene_error(&[("cascade_count: 4", "cascade_cont: 4")]);
    let short = err.to_string();
    assert!(
        short.starts_with("scene.ron:4:27: expected one of the fields `mode`, "),
        "{short}"
    );
    assert!(
        short.ends_with("found unknown field `cascade_cont`; did you mean `cascade_count`?"),
        "{short}"
    );
    let rich = render_error(&err, RICH);
    assert!(rich.contains("  --> scene.ron:4:27\n"), "{rich}");
    assert!(
        rich.ends_with("\n  |\n  = help: did you mean `cascade_count`?"),
        "{rich}"
    );
    assert_eq!(underlined(&rich)[0].2, "cascade_cont");
    // Far from every field: no suggestion.
    let err = scene_error(&[("cascade_count: 4", "tilt: 4")]);
    assert!(!err.to_string().contains("did you mean"), "{err}");
    assert!(!render_error(&err, RICH).contains("help:"));
}

#[test]
fn an_unknown_variant_suggests_the_nearest_one_in_scenes_and_settings() {
    let err = scene_error(&[("mode: Pcss", "mode: Pcsss")]);
    let short = err.to_string();
    assert!(
        short.starts_with("scene.ron:4:21: expected one of `Pcf`, `Pcss`"),
        "{short}"
    );
    assert!(
        short.ends_with("found unknown variant `Pcsss`; did you mean `Pcss`?"),
        "{short}"
    );
    let rich = render_error(&err, RICH);
    assert!(rich.contains("= help: did you mean `Pcss`?"), "{rich}");
    assert_eq!(underlined(&rich)[0].2, "Pcsss");

    let err = settings_from_str("ShadowSettings(\n    mode: pcf,\n)\n", "s.ron").unwrap_err();
    assert!(err.to_string().ends_with("; did you mean `Pcf`?"), "{err}");
    let rich = render_error(&err, RICH);
    assert!(rich.contains("  --> s.ron:2:11\n"), "{rich}");
    assert_eq!(underlined(&rich), [(2, "    mode: pcf,".to_owned(), "pcf".to_owned())]);
    let err = settings_from_str("ShadowSettings(resolutoin: 512)", "s.ron").unwrap_err();
    assert!(err.to_string().ends_with("; did you mean `resolution`?"), "{err}");
}

#[test]
fn a_misspelt_material_suggests_the_defined_name() {
    let err = scene_error(&[("material: \"leaf\"", "material: \"bakr\"")]);
    let short = err.to_string();
    assert!(
        short.ends_with("for `objects[1].material`, found \"bakr\"; did you mean \"bark\"?"),
        "{short}"
    );
    let rich = render_error(&err, RICH);
    assert!(rich.contains("= help: did you mean \"bark\"?"), "{rich}");
    assert_eq!(underlined(&rich)[0].2, "\"bakr\"");
    let err = scene_error(&[("material: \"leaf\"", "material: \"stone\"")]);
    assert!(!err.to_string().contains("did you mean"), "{err}");
}

#[test]
fn multi_byte_characters_before_the_error_keep_the_caret_in_place() {
    let materials = r#"materials: { "ground": (), "leaf": (alpha: Mask(0.5)), "bark": () },"#;
    let accented = r#"materials: { "gröünd": (), "léaf": (base_color: (1, 1, x, 1)) },"#;
    let err = scene_error(&[(materials, accented)]);
    // `x` is the 60th character of the line (the 63rd byte).
    assert!(err.to_string().starts_with("scene.ron:5:60: expected "), "{err}");
    let rich = render_error(&err, RICH);
    assert!(rich.contains("  --> scene.ron:5:60\n"), "{rich}");
    assert_eq!(underlined(&rich)[0].2, "x");
    // Invalid values too (the validator locates them in characters).
    let accented = r#"materials: { "gröünd": (), "léaf": (base_color: (1, 1, -1, 1)) },"#;
    let err = scene_error(&[(materials, accented)]);
    let rich = render_error(&err, RICH);
    assert_eq!(underlined(&rich)[0].2, "(1, 1, -1, 1)", "{rich}");
}

#[test]
fn a_long_line_is_shown_around_the_error_only() {
    // One line of a megabyte: the error keeps, and shows, the part around the problem.
    let padding = format!("/* {} */", "x".repeat(1 << 20));
    let flat = BASE
        .replace('\n', " ")
        .replace("fov: 60", &format!("{padding} fov: -60"));
    let err = SceneDesc::from_str(&flat, "flat.ron").unwrap_err();
    let rich = render_error(&err, RICH);
    assert!(rich.len() < 1000, "{} bytes", rich.len());
    let shown = underlined(&rich);
    assert_eq!(shown.len(), 1, "{rich}");
    let (line, text, under) = &shown[0];
    assert_eq!((*line, under.as_str()), (1, "-60"));
    assert!(text.starts_with("...xxx") && text.ends_with("..."), "{text}");
}

#[test]
fn an_error_without_text_is_one_plain_line() {
    let err = SceneDesc::load("/nowhere/scene.ron").unwrap_err();
    let rich = render_error(&err, RICH);
    assert_eq!(rich, format!("error: {err}"));
    assert!(!rich.contains("-->"));
}

/// glTF files (the `gltf` feature).
#[cfg(feature = "gltf")]
mod gltf_files {
    use std::path::{Path, PathBuf};

    use super::{RICH, render_error, underlined};

    /// A fresh folder for the files one test writes.
    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("penumbra-rich-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// The error of loading `bytes` as a glTF file named `name`.
    fn gltf_error(dir: &Path, name: &str, bytes: &[u8]) -> penumbra::gltf::GltfError {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        penumbra::gltf::load(&path).expect_err("the model must not load")
    }

    #[test]
    fn a_gltf_syntax_error_shows_its_line() {
        let dir = scratch("syntax");
        let json =
            "{\n  \"asset\": {\"version\": \"2.0\", \"generator\": \"é\"},\n  \"nodes\": [{\"name\": \"ü\"} {}]\n}\n";
        let err = gltf_error(&dir, "broken.gltf", json.as_bytes());
        let short = err.to_string();
        assert!(
            short.ends_with("not valid glTF: expected `,` or `]` at line 3 column 28"),
            "{short}"
        );
        let rich = render_error(&err, RICH);
        let path = dir.join("broken.gltf");
        // serde_json counts bytes (28); the caret goes under the 27th character.
        assert!(
            rich.starts_with("error: not valid glTF: expected `,` or `]`\n"),
            "{rich}"
        );
        assert!(rich.contains(&format!("  --> {}:3:27\n", path.display())), "{rich}");
        assert_eq!(
            underlined(&rich),
            [(3, "  \"nodes\": [{\"name\": \"ü\"} {}]".to_owned(), "{".to_owned())]
        );
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn a_gltf_rule_error_shows_the_line_of_its_json_path() {
        let dir = scratch("rules");
        let json = r#"{
  "asset": {"version": "2.0"},
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 7}]}],
  "accessors": [{"componentType": 5126, "count": 3, "type": "VEC3"}]
}"#;
        let err = gltf_error(&dir, "rules.gltf", json.as_bytes());
        assert!(
            err.to_string().ends_with(
                "not valid glTF: accessors[0].bufferView: Missing data; \
                 meshes[0].primitives[0].indices: Index out of bounds"
            ),
            "{err}"
        );
        let rich = render_error(&err, RICH);
        assert!(
            rich.starts_with("error: not valid glTF: accessors[0].bufferView: Missing data\n"),
            "{rich}"
        );
        assert!(
            rich.contains("\nerror: not valid glTF: meshes[0].primitives[0].indices: Index out of bounds\n"),
            "{rich}"
        );
        assert!(
            rich.contains("rules.gltf:4:17\n") && rich.contains("rules.gltf:3:73\n"),
            "{rich}"
        );
        // A missing property points at the object that lacks it.
        let under: Vec<(usize, String)> = underlined(&rich).into_iter().map(|(n, _, u)| (n, u)).collect();
        assert_eq!(under, [(4, "{".to_owned()), (3, "7".to_owned())]);
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn a_glb_file_shows_no_snippet() {
        let dir = scratch("glb");
        let json = b"{ bad }\n";
        let mut glb = Vec::new();
        glb.extend_from_slice(b"glTF");
        glb.extend_from_slice(&2u32.to_le_bytes());
        glb.extend_from_slice(&(20 + json.len() as u32).to_le_bytes());
        glb.extend_from_slice(&(json.len() as u32).to_le_bytes());
        glb.extend_from_slice(b"JSON");
        glb.extend_from_slice(json);
        let err = gltf_error(&dir, "model.glb", &glb);
        let rich = render_error(&err, RICH);
        assert_eq!(rich, format!("error: {err}"));
        std::fs::remove_dir_all(dir).ok();
    }
}
