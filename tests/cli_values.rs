//! Command-line values the parser refuses: image sizes, the camera LOD, deferred lighting, the
//! offscreen viewer's frame count and walk, and the cascade fit, each error naming what was
//! expected.

#[allow(dead_code)]
#[path = "common/cli_run.rs"]
mod cli_run;

use cli_run::refused;

#[test]
fn image_sizes_are_checked_when_the_command_line_is_parsed() {
    for (flag, value) in [
        ("--width", "0"),
        ("--height", "0"),
        ("--width", "40000"),
        ("--height", "-3"),
    ] {
        let arg = format!("{flag}={value}");
        let err = refused(&["render", "assets/scenes/default.ron", &arg]);
        assert!(
            err.contains(&format!("invalid value '{value}' for '{flag} <")),
            "{flag} {value}: {err}"
        );
    }
}

#[test]
fn camera_lod_and_deferred_lighting_say_what_they_expect() {
    for value in ["-1", "17", "nan"] {
        let arg = format!("--camera-lod={value}");
        let err = refused(&["render", "assets/scenes/default.ron", &arg]);
        assert!(
            err.contains(&format!(
                "invalid value '{value}' for '--camera-lod <CAMERA_LOD>': expected pixels from 0 to 16, found `{value}`"
            )),
            "{value}: {err}"
        );
    }
    let err = refused(&["render", "assets/scenes/default.ron", "--deferred-lighting", "maybe"]);
    assert!(
        err.contains("invalid value 'maybe' for '--deferred-lighting <DEFERRED_LIGHTING>'")
            && err.contains("[possible values: auto, on, off]"),
        "{err}"
    );
}

#[test]
#[cfg(feature = "viewer")]
fn the_offscreen_viewer_needs_a_frame_count_and_a_sane_walk() {
    let err = refused(&["view", "assets/scenes/default.ron", "--offscreen"]);
    assert!(
        err.contains("the following required arguments were not provided") && err.contains("--exit-after <EXIT_AFTER>"),
        "{err}"
    );
    for value in ["0", "-1", "2000", "x"] {
        let arg = format!("--walk={value}");
        let err = refused(&["view", "assets/scenes/default.ron", &arg]);
        assert!(
            err.contains(&format!(
                "invalid value '{value}' for '--walk <WALK>': expected metres from 0.001 to 1000, found `{value}`"
            )),
            "{value}: {err}"
        );
    }
}

#[test]
fn an_unknown_cascade_fit_names_the_fits_there_are() {
    for command in ["render", "bench"] {
        let mut args = vec![command];
        if command == "render" {
            args.push("assets/scenes/default.ron");
        }
        args.extend(["--fit", "loose"]);
        let err = refused(&args);
        assert!(
            err.contains("invalid value 'loose' for '--fit <FIT>'")
                && err.contains("[possible values: tight, stable, depth-bounds]"),
            "{command}: {err}"
        );
    }
}
