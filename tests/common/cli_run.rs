//! Running the `penumbra` binary in tests: its output, and command lines it refuses.

use std::process::{Command, Output};

/// Runs `penumbra args` and waits for it.
pub fn penumbra(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(args)
        .output()
        .expect("the penumbra binary runs")
}

/// What `out` printed to stderr.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Runs `penumbra args`, checks that the command line was refused (exit code 2), and returns
/// what it printed to stderr.
pub fn refused(args: &[&str]) -> String {
    let out = penumbra(args);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
    stderr(&out)
}
