//! What a headless render prints besides its summary: nothing on stderr on a healthy machine
//! (even without `XDG_RUNTIME_DIR`, as under ssh or in a container), and the `tracing`
//! events of the crates below (naga_oil's shader composition) in the log when `RUST_LOG`
//! asks for them.

use std::process::{Command, Output};

/// `penumbra render` of the default scene at 48×32, one frame, into a scratch PNG, with
/// `env` set and `unset` removed.
fn small_render(name: &str, env: &[(&str, &str)], unset: &[&str]) -> Output {
    let out = std::env::temp_dir().join(format!("penumbra-logging-{name}-{}.png", std::process::id()));
    let mut command = Command::new(env!("CARGO_BIN_EXE_penumbra"));
    command.args([
        "render",
        "assets/scenes/default.ron",
        "--width",
        "48",
        "--height",
        "32",
        "--frames",
        "1",
    ]);
    command.arg("--out").arg(&out);
    command.env_remove("RUST_LOG");
    for (key, value) in env {
        command.env(key, value);
    }
    for key in unset {
        command.env_remove(key);
    }
    let output = command.output().expect("the penumbra binary runs");
    let _ = std::fs::remove_file(&out);
    assert!(
        output.status.success(),
        "render failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

#[test]
fn a_headless_render_without_a_session_prints_nothing_on_stderr() {
    let output = small_render("quiet", &[], &["XDG_RUNTIME_DIR", "NODEVICE_SELECT"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(stderr, "", "a healthy headless render printed on stderr");
    // It did render: the summary names the adapter.
    assert!(String::from_utf8_lossy(&output.stdout).contains("adapter"));
}

#[test]
fn tracing_events_of_naga_oil_reach_the_log() {
    let output = small_render("tracing", &[("RUST_LOG", "naga_oil=debug")], &[]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let composed = stderr
        .lines()
        .filter(|l| l.contains("naga_oil") && l.contains("creating IR for"))
        .count();
    assert!(composed >= 1, "no naga_oil tracing event in the log:\n{stderr}");
}
