//! `penumbra bench --gallery DIR`: every preset on every scene beside the ray-traced truth.
//!
//! While a scene is scored, [`SceneShots::take`] keeps, for each preset, the render, the
//! technique's visibility and the error against the reference, cropped to the window with the
//! most penumbra (the same window for every preset of a scene). [`write_gallery`] then writes
//! `DIR/gallery.md` with the report's figures (penumbra error, frame GPU time) and the
//! pictures under `DIR/gallery/`, and a hero picture comparing two presets with the truth.

use std::path::{Path, PathBuf};

use image::{RgbImage, RgbaImage};

use crate::analysis::gallery::{
    Crop, Panel, captioned, crop_render, error_image, penumbra_window, strip, upscale, visibility_image,
};
use crate::analysis::results::{BenchReport, SceneResult};
use crate::bench::ReportError;
use crate::export::{encode_png, write_file};

/// The share of the analysis frame's width and height a crop covers.
const CROP_SHARE: f32 = 1.0 / 3.0;
/// Pixels between the panels of a strip.
const GAP: u32 = 4;
/// How much a strip's panels are enlarged (whole pixels, so nothing is smoothed away).
const STRIP_SCALE: u32 = 2;
/// How much the hero picture's panels are enlarged.
const HERO_SCALE: u32 = 3;

/// One preset's pictures on one scene, each the size of the scene's crop.
pub struct PresetShot {
    /// The preset's name.
    pub preset: String,
    /// The rendered frame.
    pub render: RgbImage,
    /// The technique's visibility at the scored points.
    pub visibility: RgbImage,
    /// Where the technique is too bright or too dark.
    pub error: RgbImage,
}

/// One scene's pictures.
pub struct SceneShots {
    /// The scene's short name (its file stem).
    pub scene: String,
    /// The window shown, in analysis-frame pixels.
    pub crop: Crop,
    /// The analysis frame's size.
    pub frame: (u32, u32),
    /// Penumbra points inside the crop.
    pub penumbra_points: usize,
    /// The reference's visibility.
    pub reference: RgbImage,
    /// Scored pixels and their reference values, kept to draw each preset.
    pixels: Vec<usize>,
    reference_values: Vec<f32>,
    /// Each preset's pictures, in run order.
    pub presets: Vec<PresetShot>,
}

impl SceneShots {
    /// Starts a scene: picks the crop with the most penumbra among `pixels` of a
    /// `width × height` frame and draws the reference there.
    pub fn new(scene: String, (width, height): (u32, u32), pixels: &[usize], reference: &[f32]) -> Self {
        let size = (
            ((width as f32 * CROP_SHARE).round() as u32).max(1),
            ((height as f32 * CROP_SHARE).round() as u32).max(1),
        );
        let (crop, penumbra_points) = penumbra_window((width, height), pixels, reference, size);
        Self {
            scene,
            crop,
            frame: (width, height),
            penumbra_points,
            reference: visibility_image(width, crop, pixels, reference),
            pixels: pixels.to_vec(),
            reference_values: reference.to_vec(),
            presets: Vec::new(),
        }
    }

    /// Keeps one preset's render and its values at the scored points.
    pub fn take(&mut self, preset: &str, render: &RgbaImage, technique: &[f32]) {
        let width = self.frame.0;
        self.presets.push(PresetShot {
            preset: preset.to_owned(),
            render: crop_render(render, self.crop),
            visibility: visibility_image(width, self.crop, &self.pixels, technique),
            error: error_image(width, self.crop, &self.pixels, technique, &self.reference_values),
        });
    }

    fn shot(&self, preset: &str) -> Option<&PresetShot> {
        self.presets.iter().find(|p| p.preset == preset)
    }
}

/// The file names a gallery writes under `DIR/gallery/`, relative to `DIR`.
fn strip_path(scene: &str, preset: &str) -> String {
    format!("gallery/{scene}/{preset}.png")
}

/// The scene result of `preset` on `scene` in the report.
fn result<'r>(report: &'r BenchReport, preset: &str, scene: &str) -> Option<&'r SceneResult> {
    let p = report.presets.iter().find(|p| p.preset == preset)?;
    p.scenes.iter().find(|s| s.scene == scene)
}

/// A preset's penumbra error and frame GPU time on a scene, from the report: empty when the
/// report does not have it.
fn figures(report: &BenchReport, preset: &str, scene: &str) -> Vec<String> {
    result(report, preset, scene).map_or_else(Vec::new, |r| {
        vec![
            format!("penumbra MAE {:.3}", r.errors.penumbra_mae),
            format!("frame GPU {:.2} ms", r.gpu.total_ms),
        ]
    })
}

/// Writes the gallery: `dir/gallery.md`, one strip per scene and preset (render, technique,
/// truth, error) under `dir/gallery/<scene>/`, and `dir/gallery/hero.png` comparing
/// `hero.0` and `hero.1` with the truth on the first scene that ran both. Returns the page's
/// path.
pub fn write_gallery(
    dir: &Path,
    report: &BenchReport,
    scenes: &[SceneShots],
    hero: (&str, &str),
) -> Result<PathBuf, ReportError> {
    let io = |path: &Path, message: String| ReportError::Io {
        path: path.display().to_string(),
        message,
    };
    let write_png = |rel: &str, image: &RgbImage| -> Result<(), ReportError> {
        let path = dir.join(rel);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| io(parent, e.to_string()))?;
        }
        let rgba = image::DynamicImage::ImageRgb8(image.clone()).to_rgba8();
        let bytes = encode_png(&rgba).map_err(|e| io(&path, e.to_string()))?;
        write_file(&path, &bytes).map_err(|e| io(&path, e.to_string()))
    };
    let hero_path = write_hero(scenes, report, hero)
        .map(|image| write_png("gallery/hero.png", &image).map(|()| "gallery/hero.png"))
        .transpose()?;
    for scene in scenes {
        for shot in &scene.presets {
            let panels =
                [&shot.render, &shot.visibility, &scene.reference, &shot.error].map(|p| upscale(p, STRIP_SCALE));
            write_png(&strip_path(&scene.scene, &shot.preset), &strip(&panels, GAP))?;
        }
    }
    let path = dir.join("gallery.md");
    write_file(&path, gallery_markdown(report, scenes, hero_path, hero).as_bytes())
        .map_err(|e| io(&path, e.to_string()))?;
    Ok(path)
}

/// The hero picture: `hero.0`'s and `hero.1`'s visibility beside the truth, twice the crop's
/// size, captioned with their penumbra error and frame GPU time; None when no scene ran both.
fn write_hero(scenes: &[SceneShots], report: &BenchReport, hero: (&str, &str)) -> Option<RgbImage> {
    let scene = scenes
        .iter()
        .find(|s| s.shot(hero.0).is_some() && s.shot(hero.1).is_some())?;
    let (a, b) = (scene.shot(hero.0)?, scene.shot(hero.1)?);
    let [va, vb, truth] = [&a.visibility, &b.visibility, &scene.reference].map(|p| upscale(p, HERO_SCALE));
    let (fa, fb) = (
        figures(report, hero.0, &scene.scene),
        figures(report, hero.1, &scene.scene),
    );
    let truth_lines = [format!("scene {}", scene.scene)];
    Some(captioned(&[
        Panel {
            image: &va,
            title: hero.0,
            lines: &fa,
        },
        Panel {
            image: &vb,
            title: hero.1,
            lines: &fb,
        },
        Panel {
            image: &truth,
            title: "ray-traced truth",
            lines: &truth_lines,
        },
    ]))
}

/// The gallery page.
fn gallery_markdown(report: &BenchReport, scenes: &[SceneShots], hero: Option<&str>, names: (&str, &str)) -> String {
    let mut md = String::from("# Gallery: every preset against the ray-traced truth\n\n");
    md += &format!(
        "Made by `penumbra bench --gallery` on {} ({}, {}), commit `{}`, {}. Each strip shows, \
         left to right, the render, the technique's shadow (white is lit), the ray-traced truth \
         and the error: orange where the technique is too bright (light leaks, shadows too \
         narrow), blue where it is too dark (acne, shadows too wide), brighter for larger \
         errors; dark blue-grey pixels are not scored. Each scene shows the same window for \
         every preset: the window a third of the width and height of its {}×{} analysis frame with the most penumbra. \
         The figures are the scene's penumbra MAE and the frame's GPU time at {}×{}.\n\n",
        report.adapter,
        report.backend,
        report.driver,
        report.commit,
        report.date,
        report.analysis_width,
        report.analysis_height,
        report.width,
        report.height,
    );
    if let Some(hero) = hero {
        md += &format!("![{} and {} beside the ray-traced truth]({hero})\n\n", names.0, names.1);
    }
    for scene in scenes {
        md += &format!(
            "## {}\n\nWindow at ({}, {}), {}×{} pixels, {} penumbra points.\n\n",
            scene.scene, scene.crop.x, scene.crop.y, scene.crop.width, scene.crop.height, scene.penumbra_points
        );
        for shot in &scene.presets {
            md += &format!(
                "**{}** — {}\n\n![{} on {}]({})\n\n",
                shot.preset,
                figures(report, &shot.preset, &scene.scene).join(", "),
                shot.preset,
                scene.scene,
                strip_path(&scene.scene, &shot.preset)
            );
        }
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::report::tests::sample_report;

    #[test]
    fn a_gallery_writes_a_strip_per_preset_a_hero_and_its_page() {
        let report = sample_report();
        let scene = report.presets[0].scenes[0].scene.clone();
        let (w, h) = (16, 8);
        let pixels: Vec<usize> = (0..(w * h) as usize).collect();
        let reference: Vec<f32> = pixels.iter().map(|&p| (p % 16) as f32 / 15.0).collect();
        let mut shots = SceneShots::new(scene.clone(), (w, h), &pixels, &reference);
        assert_eq!((shots.crop.width, shots.crop.height), (5, 3));
        let render = RgbaImage::from_pixel(w, h, image::Rgba([10, 20, 30, 255]));
        let names: Vec<String> = report.presets.iter().map(|p| p.preset.clone()).collect();
        for name in &names {
            shots.take(name, &render, &reference);
        }
        let dir = std::env::temp_dir().join(format!("penumbra-gallery-{}", std::process::id()));
        let page = write_gallery(&dir, &report, &[shots], (&names[0], &names[1])).unwrap();
        let md = std::fs::read_to_string(&page).unwrap();
        for name in &names {
            let rel = strip_path(&scene, name);
            let strip = image::open(dir.join(&rel)).unwrap();
            // Four enlarged crops and three gaps.
            assert_eq!(strip.width(), 4 * 5 * STRIP_SCALE + 3 * GAP, "{rel}");
            assert!(md.contains(&format!("({rel})")), "{md}");
        }
        assert!(dir.join("gallery/hero.png").is_file());
        assert!(md.contains("](gallery/hero.png)"));
        assert!(md.contains("penumbra MAE"), "{md}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
