//! Scene files: `SceneDesc::from_str` on any UTF-8 text must not panic, and an error must
//! name the origin and a `line:column` inside the text.

#![no_main]

use std::hint::black_box;

use libfuzzer_sys::fuzz_target;
use penumbra::scene::{SceneDesc, SceneError};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match SceneDesc::from_str(text, "fuzz.ron") {
        Ok(scene) => {
            for instance in scene.instances().take(1000) {
                black_box(instance.matrix());
            }
        }
        Err(err) => check_located(text, &err),
    }
});

/// The error names `fuzz.ron` and, for parse and validation errors, a position in the text.
fn check_located(text: &str, err: &SceneError) {
    let message = err.to_string();
    assert!(message.starts_with("fuzz.ron:"), "{message}");
    let lines = text.lines().count().max(1) + 1;
    match err {
        SceneError::Parse { line, column, .. } => assert!(*line <= lines && *column >= 1, "{message}"),
        SceneError::Invalid { problems, .. } => {
            for p in problems {
                assert!(p.line <= lines && p.column >= 1, "{message}");
            }
        }
        _ => {}
    }
}
