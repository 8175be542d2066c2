//! Regenerates the procedural sample models in `assets/models/` (`fern.gltf`, `fern.bin`,
//! `fern_leaf.png` from `penumbra::gltf::sample`; the skinned, animated `walker.gltf`,
//! `walker.bin` from `penumbra::gltf::sample::walker`), then loads them back as a check.
//!
//! Run with `cargo run --example make_sample_gltf`. The files are committed; the `gltf`
//! integration test fails when they differ from what this writes.

use std::fs;
use std::path::Path;

use penumbra::gltf::sample::walker::{WALKER_BIN, WALKER_GLTF, build_walker};
use penumbra::gltf::sample::{self, SAMPLE_BIN, SAMPLE_DIR, SAMPLE_GLTF, SAMPLE_PNG};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(SAMPLE_DIR);
    fs::create_dir_all(&dir)?;
    let files = sample::build();
    fs::write(dir.join(SAMPLE_GLTF), &files.gltf)?;
    fs::write(dir.join(SAMPLE_BIN), &files.bin)?;
    fs::write(dir.join(SAMPLE_PNG), &files.png)?;

    let model = penumbra::gltf::load(&dir.join(SAMPLE_GLTF))?;
    let triangles: usize = model
        .meshes
        .iter()
        .flat_map(|m| &m.primitives)
        .map(|p| p.mesh.triangle_count())
        .sum();
    println!(
        "wrote {SAMPLE_DIR}/{{{SAMPLE_GLTF}, {SAMPLE_BIN}, {SAMPLE_PNG}}}: {} meshes, {} materials, {} nodes, {triangles} triangles",
        model.meshes.len(),
        model.materials.len(),
        model.nodes.len(),
    );
    for warning in &model.warnings {
        println!("warning: {warning}");
    }

    let walker = build_walker();
    fs::write(dir.join(WALKER_GLTF), &walker.gltf)?;
    fs::write(dir.join(WALKER_BIN), &walker.bin)?;
    let model = penumbra::gltf::load(&dir.join(WALKER_GLTF))?;
    println!(
        "wrote {SAMPLE_DIR}/{{{WALKER_GLTF}, {WALKER_BIN}}}: {} skin of {} joints, {} animation of {:.1} s",
        model.skins.len(),
        model.skins.first().map_or(0, |s| s.joints.len()),
        model.animations.len(),
        model.animations.first().map_or(0.0, |a| a.duration()),
    );
    for warning in &model.warnings {
        println!("warning: {warning}");
    }
    Ok(())
}
