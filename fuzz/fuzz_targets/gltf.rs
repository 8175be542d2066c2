//! glTF models: `penumbra::gltf::load` on any bytes (as `.gltf` JSON or a `.glb` container)
//! must not panic, and an error must name the file. The loader reads a path, so each input
//! is written to a scratch directory that also holds the sample model's buffer and image, so
//! that mutated URIs can still find them.

#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

/// The scratch directory, made once per process.
fn scratch() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("penumbra-fuzz-gltf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("scratch directory");
        let models = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/models");
        for file in ["fern.bin", "fern_leaf.png"] {
            std::fs::copy(models.join(file), dir.join(file)).expect("sample model files");
        }
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let path = scratch().join("model.gltf");
    std::fs::write(&path, data).expect("write the input");
    if let Err(err) = penumbra::gltf::load(&path) {
        let message = err.to_string();
        assert!(message.starts_with(&path.display().to_string()), "{message}");
    }
});
