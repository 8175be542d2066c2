//! Build script: embeds the commit the crate is built from, so that the bench's reports and
//! `render --json` name the code they measured. `PENUMBRA_BUILD_COMMIT` is the short hash of
//! `HEAD`, with `-dirty` when the files the binary is built from (`src`, `shaders`,
//! `Cargo.toml`, `Cargo.lock`, `build.rs`) differ from it, or `unknown` outside a git
//! checkout (a crate built from a registry).

use std::path::Path;
use std::process::Command;

/// What the binary is built from: a change here rebuilds it and may make it dirty.
const SOURCES: [&str; 5] = ["src", "shaders", "Cargo.toml", "Cargo.lock", "build.rs"];

/// `git args…` in the crate's folder, its trimmed stdout when it succeeds.
fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .args(args)
        .current_dir(manifest_dir())
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    for source in SOURCES {
        println!("cargo:rerun-if-changed={source}");
    }
    let commit = match git(&["rev-parse", "--short=12", "HEAD"]) {
        Some(hash) => {
            // HEAD, the branch it names and the index move on a commit, a checkout or a
            // `git add`; the sources above cover edits.
            for name in ["HEAD", "index", "packed-refs"] {
                if let Some(path) = git(&["rev-parse", "--git-path", name]) {
                    watch(&path);
                }
            }
            if let Some(branch) = git(&["symbolic-ref", "-q", "HEAD"])
                && let Some(path) = git(&["rev-parse", "--git-path", &branch])
            {
                watch(&path);
            }
            let mut status = vec!["status", "--porcelain", "--"];
            status.extend(SOURCES);
            let dirty = git(&status).is_none_or(|s| !s.is_empty());
            if dirty { format!("{hash}-dirty") } else { hash }
        }
        None => "unknown".to_string(),
    };
    println!("cargo:rustc-env=PENUMBRA_BUILD_COMMIT={commit}");
}

/// Reruns this script when `path` (relative to the crate, or absolute) changes, if it exists.
fn watch(path: &str) {
    let full = Path::new(&manifest_dir()).join(path);
    if full.exists() {
        println!("cargo:rerun-if-changed={}", full.display());
    }
}

/// The crate's folder (cargo runs build scripts with `CARGO_MANIFEST_DIR` set).
fn manifest_dir() -> String {
    std::env::var("CARGO_MANIFEST_DIR").unwrap_or_else(|_| ".".to_string())
}
