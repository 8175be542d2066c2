//! A PNG scatter plot of GPU time (x) against penumbra MAE (y), one labelled point per preset
//! (means over the scenes), with the Pareto front drawn as a step line.
//!
//! Drawn directly into an `image::RgbImage` with anti-aliased discs and Xiaolin Wu lines, and
//! text from fonts embedded in the binary (Ubuntu Light and Hack, from `epaint_default_fonts`).
//! Axis ranges snap to 1-2-5 tick steps; labels move away from points, the front line, other
//! labels and the legend when they would overlap, with a leader line when moved far.

use std::path::{Path, PathBuf};

use ab_glyph::InvalidFont;
use image::{ImageFormat, Rgb, RgbImage};

use crate::analysis::axis::Axis;
use crate::analysis::font::{Fonts, Style, blit, measure, render, text};
use crate::analysis::pareto::pareto_front;
use crate::analysis::raster::{Rect, disc, fill_rect, wu_line};
use crate::analysis::report::BenchReport;
use crate::export::write_file;

/// Image width in pixels.
pub(crate) const WIDTH: u32 = 1200;
/// Image height in pixels.
pub(crate) const HEIGHT: u32 = 800;
/// The plot area, in pixels.
pub(crate) const AREA: Rect = Rect::new(110.0, 90.0, 1160.0, 720.0);

pub(crate) const BACKGROUND: Rgb<u8> = Rgb([255, 255, 255]);
pub(crate) const FRONT: Rgb<u8> = Rgb([222, 96, 32]);
pub(crate) const DOMINATED: Rgb<u8> = Rgb([66, 118, 180]);
const OUTLINE: Rgb<u8> = Rgb([70, 40, 20]);
const GRID: Rgb<u8> = Rgb([228, 228, 232]);
const AXIS: Rgb<u8> = Rgb([90, 90, 96]);
pub(crate) const INK: Rgb<u8> = Rgb([25, 25, 30]);
const MUTED: Rgb<u8> = Rgb([100, 100, 108]);
/// Label text size in pixels.
const LABEL_PX: f32 = 17.0;

/// Why the plot could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// An embedded font did not parse (a build problem, not a run-time one).
    #[error("the embedded plot font cannot be read: {0}")]
    Font(#[from] InvalidFont),
    /// Encoding or writing the PNG failed.
    #[error("cannot write the plot `{}`: {message}", path.display())]
    Write {
        /// Where it was to be written.
        path: PathBuf,
        /// What failed.
        message: String,
    },
}

/// Writes the plot of `report` as a 1200 × 800 PNG to `path`.
pub fn plot_png(report: &BenchReport, path: &Path) -> Result<(), PlotError> {
    let img = draw(report, &Fonts::load()?);
    let write_error = |message: String| PlotError::Write {
        path: path.to_owned(),
        message,
    };
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), ImageFormat::Png)
        .map_err(|e| write_error(e.to_string()))?;
    write_file(path, &png).map_err(|e| write_error(e.to_string()))
}

/// The data ranges of the plot and their mapping to pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Frame {
    pub x: Axis,
    pub y: Axis,
}

impl Frame {
    /// Axes that hold every finite point.
    pub fn fit(points: &[(f64, f64)]) -> Self {
        let finite = || points.iter().filter(|p| p.0.is_finite() && p.1.is_finite());
        Self {
            x: Axis::fit(finite().map(|p| p.0)),
            y: Axis::fit(finite().map(|p| p.1)),
        }
    }

    /// The pixel position (continuous: pixel `i` spans `[i, i + 1)`) of the data point `(x, y)`.
    pub fn pixel(&self, x: f64, y: f64) -> (f32, f32) {
        let px = AREA.x0 + self.x.fraction(x) * (AREA.x1 - AREA.x0);
        let py = AREA.y1 - self.y.fraction(y) * (AREA.y1 - AREA.y0);
        (px, py)
    }
}

/// Each preset's (mean GPU ms, mean penumbra MAE): the plotted data.
pub(crate) fn preset_points(report: &BenchReport) -> Vec<(f64, f64)> {
    report
        .presets
        .iter()
        .map(|p| (p.mean_gpu_ms(), p.mean_penumbra_mae()))
        .collect()
}

/// Draws the whole plot.
fn draw(report: &BenchReport, fonts: &Fonts) -> RgbImage {
    let mut img = RgbImage::from_pixel(WIDTH, HEIGHT, BACKGROUND);
    let points = preset_points(report);
    let front = pareto_front(&points);
    let frame = Frame::fit(&points);
    draw_titles(&mut img, fonts, report);
    draw_axes(
        &mut img,
        fonts,
        &frame,
        ("GPU time per frame (ms)", "Penumbra MAE (shadow factor)"),
    );

    let muted = |px| Style {
        font: &fonts.sans,
        px,
        color: MUTED,
        bold: false,
    };
    let (shown, hidden): (Vec<usize>, Vec<usize>) =
        (0..points.len()).partition(|&i| points[i].0.is_finite() && points[i].1.is_finite());
    if !hidden.is_empty() {
        let names: Vec<&str> = hidden.iter().map(|&i| report.presets[i].preset.as_str()).collect();
        let note = format!("Not shown (no finite GPU time or error): {}", names.join(", "));
        text(&mut img, muted(14.0), &note, (12.0, HEIGHT as f32 - 8.0), (0.0, 1.0));
    }
    if shown.is_empty() {
        let centre = ((AREA.x0 + AREA.x1) / 2.0, (AREA.y0 + AREA.y1) / 2.0);
        text(
            &mut img,
            muted(20.0),
            "no preset has a finite GPU time and penumbra error",
            centre,
            (0.5, 0.5),
        );
        return img;
    }

    let pixels: Vec<(f32, f32)> = points.iter().map(|&(x, y)| frame.pixel(x, y)).collect();
    let stairs = draw_front_line(&mut img, &points, &pixels, &front);
    let markers: Vec<Rect> = shown
        .iter()
        .map(|&i| Rect::around(pixels[i].0, pixels[i].1, 10.0))
        .collect();
    let legend = draw_legend(&mut img, fonts, &markers);
    // Front markers last, so that they stay on top.
    let (on, off): (Vec<usize>, Vec<usize>) = shown.iter().partition(|&&i| front[i]);
    for &i in &off {
        disc(&mut img, pixels[i].0, pixels[i].1, 6.5, BACKGROUND);
        disc(&mut img, pixels[i].0, pixels[i].1, 5.0, DOMINATED);
    }
    for &i in &on {
        disc(&mut img, pixels[i].0, pixels[i].1, 7.5, OUTLINE);
        disc(&mut img, pixels[i].0, pixels[i].1, 5.5, FRONT);
    }

    // Labels, front first, each at the first free place among its candidates.
    let mut taken = markers;
    taken.push(legend);
    taken.extend(stairs.iter().map(|s| s.grow(2.0)));
    for i in on.into_iter().chain(off) {
        let name = &report.presets[i].preset;
        let place = place_label(pixels[i], measure(&fonts.sans, LABEL_PX, name), &taken);
        let (distance, nearest) = place.nearest(pixels[i].0, pixels[i].1);
        if distance > 16.0 {
            let (x, y) = pixels[i];
            let start = (
                x + (nearest.0 - x) / distance * 9.0,
                y + (nearest.1 - y) / distance * 9.0,
            );
            wu_line(&mut img, start, nearest, MUTED);
        }
        let style = Style {
            font: &fonts.sans,
            px: LABEL_PX,
            color: if front[i] { INK } else { MUTED },
            bold: front[i],
        };
        text(&mut img, style, name, (place.x0, place.y0), (0.0, 0.0));
        taken.push(place);
    }
    img
}

/// The title (with the adapter) and a subtitle with the settings.
fn draw_titles(img: &mut RgbImage, fonts: &Fonts, r: &BenchReport) {
    let centre = WIDTH as f32 / 2.0;
    let title_style = Style {
        font: &fonts.sans,
        px: 26.0,
        color: INK,
        bold: true,
    };
    let subtitle_style = Style {
        font: &fonts.sans,
        px: 16.0,
        color: MUTED,
        bold: false,
    };
    let title = format!("GPU time vs penumbra error — {}", r.adapter);
    text(img, title_style, &title, (centre, 16.0), (0.5, 0.0));
    let scenes = r.presets.iter().map(|p| p.scenes.len()).max().unwrap_or(0);
    let subtitle = format!(
        "{}, {}×{}, means over {scenes} scene(s); error at {}×{} against the reference ({})",
        r.backend, r.width, r.height, r.analysis_width, r.analysis_height, r.reference_samples
    );
    text(img, subtitle_style, &subtitle, (centre, 52.0), (0.5, 0.0));
}

/// The front as a staircase through its points in order of cost: right along each point's
/// error, then down to the next point. Returns the drawn segments.
fn draw_front_line(img: &mut RgbImage, points: &[(f64, f64)], pixels: &[(f32, f32)], front: &[bool]) -> Vec<Rect> {
    let mut stairs: Vec<usize> = (0..points.len()).filter(|&i| front[i]).collect();
    stairs.sort_by(|&a, &b| {
        points[a]
            .0
            .total_cmp(&points[b].0)
            .then(points[a].1.total_cmp(&points[b].1))
    });
    let mut segments = Vec::new();
    for pair in stairs.windows(2) {
        let ((ax, ay), (bx, by)) = (pixels[pair[0]], pixels[pair[1]]);
        segments.push(Rect::new(ax, ay - 1.0, bx + 1.0, ay + 1.0));
        segments.push(Rect::new(bx - 1.0, ay.min(by) - 1.0, bx + 1.0, ay.max(by) + 1.0));
    }
    for &segment in &segments {
        fill_rect(img, segment, FRONT);
    }
    segments
}

/// Where the label of size `(w, h)` of the point `(x, y)` goes: the first place that stays in
/// the plot area and overlaps nothing `taken`, trying right, left, above, below, then right
/// and left moved up and down in steps; right when none is free.
fn place_label((x, y): (f32, f32), (w, h): (f32, f32), taken: &[Rect]) -> Rect {
    let at = |x0: f32, y0: f32| Rect::new(x0, y0, x0 + w, y0 + h);
    let (right, left, middle) = (x + 11.0, x - 11.0 - w, y - h / 2.0);
    let mut candidates = vec![
        at(right, middle),
        at(left, middle),
        at(x - w / 2.0, y - 11.0 - h),
        at(x - w / 2.0, y + 11.0),
    ];
    for k in 1..=10 {
        for dy in [-0.75 * h * k as f32, 0.75 * h * k as f32] {
            candidates.extend([at(right, middle + dy), at(left, middle + dy)]);
        }
    }
    let inner = AREA.grow(-2.0);
    let free = |r: &Rect| r.inside(&inner) && !taken.iter().any(|t| t.overlaps(r));
    candidates.iter().copied().find(free).unwrap_or(candidates[0])
}

/// Grid, frame, ticks, tick labels and axis titles.
/// The grid, ticks, tick labels and the axis titles `(x, y)`.
pub(crate) fn draw_axes(img: &mut RgbImage, fonts: &Fonts, frame: &Frame, (x_title, y_title): (&str, &str)) {
    let tick = Style {
        font: &fonts.mono,
        px: 14.0,
        color: INK,
        bold: false,
    };
    for v in frame.x.ticks() {
        let x = frame.pixel(v, frame.y.lo).0.round();
        fill_rect(img, Rect::new(x, AREA.y0, x + 1.0, AREA.y1), GRID);
        fill_rect(img, Rect::new(x, AREA.y1, x + 1.0, AREA.y1 + 6.0), AXIS);
        text(img, tick, &frame.x.label(v), (x + 0.5, AREA.y1 + 9.0), (0.5, 0.0));
    }
    for v in frame.y.ticks() {
        let y = frame.pixel(frame.x.lo, v).1.round();
        fill_rect(img, Rect::new(AREA.x0, y, AREA.x1, y + 1.0), GRID);
        fill_rect(img, Rect::new(AREA.x0 - 6.0, y, AREA.x0, y + 1.0), AXIS);
        text(img, tick, &frame.y.label(v), (AREA.x0 - 9.0, y + 0.5), (1.0, 0.5));
    }
    let (l, t, r, b) = (AREA.x0, AREA.y0, AREA.x1, AREA.y1);
    for edge in [Rect::new(l, t, r + 1.0, t + 1.0), Rect::new(l, b, r + 1.0, b + 1.0)] {
        fill_rect(img, edge, AXIS);
    }
    for edge in [Rect::new(l, t, l + 1.0, b), Rect::new(r, t, r + 1.0, b)] {
        fill_rect(img, edge, AXIS);
    }
    let title = Style {
        font: &fonts.sans,
        px: 18.0,
        color: INK,
        bold: true,
    };
    text(img, title, x_title, ((l + r) / 2.0, b + 38.0), (0.5, 0.0));
    let y_title = render(&fonts.sans, 18.0, y_title, true);
    let top = (t + b) / 2.0 - y_title.width as f32 / 2.0;
    blit(img, &y_title, (16, top.round() as i64), INK, true);
}

/// The legend, in the first corner of the plot area that holds no marker; returns its box.
fn draw_legend(img: &mut RgbImage, fonts: &Fonts, markers: &[Rect]) -> Rect {
    let entries = ["Pareto front", "dominated preset"];
    let text_w = entries
        .iter()
        .map(|e| measure(&fonts.sans, 16.0, e).0)
        .fold(0.0, f32::max);
    let (w, h) = (text_w + 58.0, 62.0);
    let corners = [
        (AREA.x1 - 12.0 - w, AREA.y0 + 12.0),
        (AREA.x0 + 12.0, AREA.y0 + 12.0),
        (AREA.x1 - 12.0 - w, AREA.y1 - 12.0 - h),
    ];
    let boxes = corners.map(|(x0, y0)| Rect::new(x0, y0, x0 + w, y0 + h));
    let b = boxes
        .iter()
        .copied()
        .find(|b| !markers.iter().any(|m| m.overlaps(b)))
        .unwrap_or(boxes[0]);
    fill_rect(img, b, GRID);
    fill_rect(img, b.grow(-1.0), BACKGROUND);
    let (x, row1, row2) = (b.x0 + 24.0, b.y0 + 19.0, b.y0 + 43.0);
    fill_rect(img, Rect::new(x - 14.0, row1 - 1.0, x + 14.0, row1 + 1.0), FRONT);
    disc(img, x, row1, 7.5, OUTLINE);
    disc(img, x, row1, 5.5, FRONT);
    disc(img, x, row2, 5.0, DOMINATED);
    let style = Style {
        font: &fonts.sans,
        px: 16.0,
        color: INK,
        bold: false,
    };
    text(img, style, entries[0], (b.x0 + 46.0, row1), (0.0, 0.5));
    text(img, style, entries[1], (b.x0 + 46.0, row2), (0.0, 0.5));
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::report::tests::sample_report;

    fn near(a: Rgb<u8>, b: Rgb<u8>) -> bool {
        a.0.iter().zip(b.0).all(|(&x, y)| x.abs_diff(y) <= 12)
    }

    #[test]
    fn mapping_puts_the_range_on_the_plot_area() {
        let frame = Frame {
            x: Axis {
                lo: 0.0,
                hi: 4.0,
                step: 1.0,
            },
            y: Axis {
                lo: 0.0,
                hi: 0.2,
                step: 0.05,
            },
        };
        assert_eq!(frame.pixel(0.0, 0.0), (AREA.x0, AREA.y1));
        assert_eq!(frame.pixel(4.0, 0.2), (AREA.x1, AREA.y0));
        assert_eq!(
            frame.pixel(2.0, 0.1),
            ((AREA.x0 + AREA.x1) / 2.0, (AREA.y0 + AREA.y1) / 2.0)
        );
    }

    #[test]
    fn labels_move_away_from_what_is_taken() {
        let free = place_label((500.0, 400.0), (60.0, 20.0), &[]);
        assert_eq!(free, Rect::new(511.0, 390.0, 571.0, 410.0));
        let right_taken = [Rect::new(505.0, 380.0, 600.0, 420.0)];
        let moved = place_label((500.0, 400.0), (60.0, 20.0), &right_taken);
        assert_eq!(moved, Rect::new(429.0, 390.0, 489.0, 410.0));
        // At the right edge of the plot area, the label goes left.
        let edge = place_label((AREA.x1 - 5.0, 400.0), (60.0, 20.0), &[]);
        assert!(edge.x1 < AREA.x1 - 5.0, "{edge:?}");
    }

    #[test]
    fn plot_is_written_with_points_where_the_mapping_says() {
        let report = sample_report();
        let path = std::env::temp_dir().join(format!("penumbra-plot-test-{}.png", std::process::id()));
        plot_png(&report, &path).expect("plot written");
        let img = image::open(&path).expect("PNG readable").to_rgb8();
        std::fs::remove_file(&path).ok();
        assert_eq!(img.dimensions(), (WIDTH, HEIGHT));
        let points = preset_points(&report);
        let frame = Frame::fit(&points);
        let front = pareto_front(&points);
        assert_eq!(front, [true, true, false, true]);
        for ((x, y), on_front) in points.iter().zip(front) {
            let (px, py) = frame.pixel(*x, *y);
            let pixel = *img.get_pixel(px as u32, py as u32);
            let expected = if on_front { FRONT } else { DOMINATED };
            assert!(
                near(pixel, expected),
                "({x}, {y}) at ({px}, {py}) is {pixel:?}, not {expected:?}"
            );
        }
        // Away from the points, the plot area is background.
        let (ex, ey) = frame.pixel(0.5 * frame.x.hi, 0.98 * frame.y.hi);
        assert_eq!(*img.get_pixel(ex as u32 + 3, ey as u32 + 3), BACKGROUND);
        // There is dark text in the title band.
        let ink = (0..WIDTH)
            .flat_map(|x| (10..45).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0[0] < 100);
        assert!(ink.count() > 200);
    }

    #[test]
    fn plot_without_presets_or_to_a_bad_path() {
        let mut report = sample_report();
        report.presets.clear();
        let path = std::env::temp_dir().join(format!("penumbra-plot-empty-{}.png", std::process::id()));
        plot_png(&report, &path).expect("empty plot written");
        let written = image::open(&path).expect("PNG readable");
        std::fs::remove_file(&path).ok();
        assert_eq!((written.width(), written.height()), (WIDTH, HEIGHT));
        let err = plot_png(&report, Path::new("/nonexistent-dir/x/plot.png")).unwrap_err();
        assert!(matches!(err, PlotError::Write { .. }), "{err}");
        assert!(err.to_string().contains("plot.png"), "{err}");
    }
}
