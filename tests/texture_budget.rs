//! The texture budget: a scene's decoded images together (RGBA8 with their mip chains) stay
//! under it — an image that would pass it is downscaled, with a warning naming it and both
//! sizes; one that cannot fit even at 1×1 is refused with the budget in the message — and
//! `check` reports the total.

use std::path::{Path, PathBuf};
use std::process::Command;

use penumbra::app::PreparedScene;
use penumbra::asset_io::{DEFAULT_MAX_TEXTURE_BYTES, mip_chain_bytes};
use penumbra::scene::{SceneDesc, SceneLimits};

/// A fresh folder holding two different 512² PNGs and a scene naming both.
fn scene_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-textures-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (file, shade) in [("a.png", 40u8), ("b.png", 200u8)] {
        let image = image::RgbaImage::from_fn(512, 512, |x, y| {
            image::Rgba([shade, (x % 256) as u8, (y % 256) as u8, 255])
        });
        image.save(dir.join(file)).unwrap();
    }
    let scene = r#"Scene(
    camera: (position: (0, 2, 5), target: (0, 0, 0), fov: 60, near: 0.1, far: 100),
    sun: (direction: (0, -1, 0)),
    materials: { "a": (texture: "a.png"), "b": (texture: "b.png") },
    objects: [
        (shape: Plane(size: (4, 4)), material: "a"),
        (shape: Cuboid(size: (1, 1, 1)), material: "b", translation: (0, 0.5, 0)),
    ],
)"#;
    std::fs::write(dir.join("scene.ron"), scene).unwrap();
    dir
}

fn load(dir: &Path, max_texture_bytes: u64) -> Result<PreparedScene, String> {
    let limits = SceneLimits {
        max_texture_bytes,
        ..SceneLimits::default()
    };
    let desc = SceneDesc::load_with(dir.join("scene.ron"), &limits).map_err(|e| e.to_string())?;
    PreparedScene::new(&desc).map_err(|e| e.to_string())
}

#[test]
fn images_past_the_budget_are_downscaled_with_a_warning() {
    let dir = scene_dir("fit");
    let full = load(&dir, DEFAULT_MAX_TEXTURE_BYTES).unwrap();
    assert_eq!(full.texture_bytes(), 2 * mip_chain_bytes(512, 512));
    assert!(full.warnings().is_empty(), "{:?}", full.warnings());
    // 1 MiB holds neither 512² chain (1.33 MiB): both are halved, in load order.
    let fitted = load(&dir, 1 << 20).unwrap();
    assert_eq!(fitted.texture_bytes(), 2 * mip_chain_bytes(256, 256));
    let warnings = fitted.warnings();
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    assert!(
        warnings[0].starts_with("texture `a.png`") && warnings[0].contains("downscaled from 512×512 to 256×256"),
        "{warnings:?}"
    );
    assert!(warnings[1].contains("over the 1.0 MiB texture budget"), "{warnings:?}");
    // 1.5 MiB keeps the first at 512² and halves the second.
    let fitted = load(&dir, 3 << 19).unwrap();
    assert_eq!(
        fitted.texture_bytes(),
        mip_chain_bytes(512, 512) + mip_chain_bytes(128, 128)
    );
    assert_eq!(fitted.warnings().len(), 1);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_budget_without_room_for_a_texel_refuses_the_image() {
    let dir = scene_dir("full");
    let error = load(&dir, 0).err().unwrap();
    assert!(error.contains("not even 1×1 texels fit"), "{error}");
    assert!(error.contains("of the 0.0 MiB texture budget"), "{error}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn two_images_at_the_per_image_limit_are_halved_to_fit_the_default_budget() {
    // The reported case: two 8192² images (each at the per-image decode limit) took render
    // past 2 GiB. Each is now halved once.
    assert!(mip_chain_bytes(8192, 8192) > DEFAULT_MAX_TEXTURE_BYTES);
    assert!(2 * mip_chain_bytes(4096, 4096) <= DEFAULT_MAX_TEXTURE_BYTES);
}

#[test]
fn check_reports_the_texture_total_and_the_downscaled_images() {
    let dir = scene_dir("check");
    let scene = dir.join("scene.ron");
    let out = Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(["check", "--texture-budget", "1", scene.to_str().unwrap()])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        text.contains("  textures 2 images, 0.7 MiB with their mips of a 1.0 MiB budget"),
        "{text}"
    );
    assert!(
        text.contains("  warning: texture `b.png` downscaled from 512×512 to 256×256"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(dir);
}
