//! A sweep of the sun's angular diameter: the same benchmark run at several penumbra widths,
//! written as a Markdown table (GPU time and penumbra error of each preset at each diameter)
//! and a PNG of GPU time against the diameter, one line per preset. It shows what a filter's
//! cost does as penumbrae widen: PCSS searches and filters over a wider region, a moment
//! technique fetches once whatever the width (its bake does not depend on the width either).

use std::fmt::Write;
use std::path::Path;

use image::{ImageFormat, Rgb, RgbImage};

use crate::analysis::axis::Axis;
use crate::analysis::font::{Fonts, Style, text};
use crate::analysis::plot::{AREA, BACKGROUND, Frame, HEIGHT, INK, PlotError, WIDTH, draw_axes};
use crate::analysis::raster::{Rect, disc, fill_rect, wu_line};
use crate::analysis::results::BenchReport;
use crate::export::write_file;

/// One run of the sweep: the sun's angular diameter in degrees and the report at it.
pub type SweepRun = (f32, BenchReport);

/// Line colours, one per preset in order (repeating).
const PALETTE: [Rgb<u8>; 8] = [
    Rgb([222, 96, 32]),
    Rgb([66, 118, 180]),
    Rgb([46, 150, 80]),
    Rgb([170, 60, 160]),
    Rgb([200, 160, 20]),
    Rgb([40, 170, 180]),
    Rgb([120, 120, 120]),
    Rgb([150, 80, 40]),
];

/// The presets of the sweep, in the order of its first run.
fn preset_names(runs: &[SweepRun]) -> Vec<&str> {
    runs.first()
        .map(|(_, r)| r.presets.iter().map(|p| p.preset.as_str()).collect())
        .unwrap_or_default()
}

/// `(mean GPU ms, mean penumbra MAE)` of `preset` in `report` (NaN where it did not run).
fn cell(report: &BenchReport, preset: &str) -> (f64, f64) {
    report
        .presets
        .iter()
        .find(|p| p.preset == preset)
        .map_or((f64::NAN, f64::NAN), |p| (p.mean_gpu_ms(), p.mean_penumbra_mae()))
}

/// The sweep as Markdown: a table of GPU ms per frame and penumbra MAE for every preset
/// (rows) at every diameter (columns), then `plot` as an image when given.
pub fn sweep_markdown(runs: &[SweepRun], plot: Option<&str>) -> String {
    let mut out = String::new();
    let adapter = runs.first().map_or("", |(_, r)| r.adapter.as_str());
    // NOTE: writing to a String cannot fail.
    let _ = writeln!(out, "# Cost against the sun's angular diameter\n");
    let _ = writeln!(
        out,
        "Each cell: GPU ms per frame (every shadow map drawn, and a moment technique's moments baked, each frame: the moving case) / penumbra MAE, means over the scenes; {adapter}.\n"
    );
    let mut header = "| Preset |".to_string();
    let mut rule = "|---|".to_string();
    for (d, _) in runs {
        let _ = write!(header, " {d}° |");
        rule.push_str("---|");
    }
    let _ = writeln!(out, "{header}\n{rule}");
    for name in preset_names(runs) {
        let _ = write!(out, "| {name} |");
        for (_, report) in runs {
            let (ms, mae) = cell(report, name);
            let _ = write!(out, " {ms:.3} / {mae:.3} |");
        }
        out.push('\n');
    }
    if let Some(plot) = plot {
        let _ = writeln!(out, "\n![GPU time against the sun's angular diameter]({plot})");
    }
    out
}

/// Writes the plot of GPU time (y) against the sun's angular diameter (x), one line per
/// preset, as a 1200 × 800 PNG to `path`.
pub fn sweep_png(runs: &[SweepRun], path: &Path) -> Result<(), PlotError> {
    let fonts = Fonts::load()?;
    let mut img = RgbImage::from_pixel(WIDTH, HEIGHT, BACKGROUND);
    let names = preset_names(runs);
    let points: Vec<(f64, f64)> = runs
        .iter()
        .flat_map(|(d, r)| names.iter().map(move |n| (f64::from(*d), cell(r, n).0)))
        .collect();
    let frame = Frame {
        x: Axis::fit(points.iter().map(|p| p.0)),
        y: Axis::fit(points.iter().map(|p| p.1)),
    };
    let title = Style {
        font: &fonts.sans,
        px: 26.0,
        color: INK,
        bold: true,
    };
    let adapter = runs.first().map_or("", |(_, r)| r.adapter.as_str());
    let heading = format!("GPU time against the sun's angular diameter — {adapter}");
    text(&mut img, title, &heading, (WIDTH as f32 / 2.0, 16.0), (0.5, 0.0));
    draw_axes(
        &mut img,
        &fonts,
        &frame,
        ("Sun angular diameter (degrees)", "GPU time per frame (ms)"),
    );
    let label = Style {
        font: &fonts.sans,
        px: 16.0,
        color: INK,
        bold: false,
    };
    for (k, name) in names.iter().enumerate() {
        let color = PALETTE[k % PALETTE.len()];
        let line: Vec<(f32, f32)> = runs
            .iter()
            .map(|(d, r)| (f64::from(*d), cell(r, name).0))
            .filter(|p| p.1.is_finite())
            .map(|(x, y)| frame.pixel(x, y))
            .collect();
        for pair in line.windows(2) {
            wu_line(&mut img, pair[0], pair[1], color);
        }
        for &(x, y) in &line {
            disc(&mut img, x, y, 4.0, color);
        }
        // The legend: one swatch and name per preset, down the plot's top-left corner.
        let y = AREA.y0 + 14.0 + 22.0 * k as f32;
        fill_rect(
            &mut img,
            Rect::new(AREA.x0 + 12.0, y - 2.0, AREA.x0 + 36.0, y + 2.0),
            color,
        );
        text(&mut img, label, name, (AREA.x0 + 44.0, y), (0.0, 0.5));
    }
    let mut png = Vec::new();
    let write_error = |message: String| PlotError::Write {
        path: path.to_owned(),
        message,
    };
    img.write_to(&mut std::io::Cursor::new(&mut png), ImageFormat::Png)
        .map_err(|e| write_error(e.to_string()))?;
    write_file(path, &png).map_err(|e| write_error(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::report::tests::sample_report;

    #[test]
    fn the_table_has_a_cell_per_preset_and_diameter_and_the_plot_is_written() {
        let runs: Vec<SweepRun> = vec![(0.5, sample_report()), (2.0, sample_report())];
        let md = sweep_markdown(&runs, Some("sweep.png"));
        assert!(md.contains("| 0.5° | 2° |"), "{md}");
        let presets = runs[0].1.presets.len();
        let rows = md.lines().filter(|l| l.starts_with("| ") && l.contains(" / ")).count();
        assert_eq!(rows, presets, "{md}");
        let dir = std::env::temp_dir().join(format!("penumbra-sweep-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("sweep.png");
        sweep_png(&runs, &path).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (WIDTH, HEIGHT));
        // The first preset's line colour is drawn.
        assert!(img.pixels().any(|p| *p == PALETTE[0]));
        std::fs::remove_dir_all(&dir).ok();
    }
}
