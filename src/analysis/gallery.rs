//! The gallery's pictures, as pure image work: which window of a frame shows the most
//! penumbra, the technique's and the reference's visibility there, where the technique is too
//! bright or too dark, and strips and captioned panels that put them side by side.
//!
//! Every function takes the scored points of one analysis frame: `pixels` (row-major pixel
//! indices of a `width × height` frame) with one value per point. Pixels that were not scored
//! (background, surfaces facing away from the light) are drawn in [`UNSCORED`].

use image::{Rgb, RgbImage, RgbaImage, imageops};

use crate::analysis::font::{Fonts, Style, measure, text};

/// The colour of pixels that were not scored.
pub const UNSCORED: Rgb<u8> = Rgb([28, 30, 48]);
/// The error image's colour where the technique is too bright (light where the truth has
/// shadow: a shadow that leaks or is too narrow).
pub const TOO_BRIGHT: Rgb<u8> = Rgb([255, 150, 30]);
/// The error image's colour where the technique is too dark (shadow where the truth has
/// light: acne, or a shadow too wide).
pub const TOO_DARK: Rgb<u8> = Rgb([40, 150, 255]);

/// A reference value strictly between these is penumbra.
const PENUMBRA: (f32, f32) = (0.02, 0.98);

/// A window of a frame, in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Crop {
    /// Left column.
    pub x: u32,
    /// Top row.
    pub y: u32,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
}

/// The `size` window of a `width × height` frame holding the most penumbra points (reference
/// strictly between 0.02 and 0.98), with how many it holds; the top-left-most of equals. The
/// window is clamped to the frame.
pub fn penumbra_window(
    (width, height): (u32, u32),
    pixels: &[usize],
    reference: &[f32],
    size: (u32, u32),
) -> (Crop, usize) {
    let (w, h) = (width as usize, height as usize);
    let (cw, ch) = (
        size.0.clamp(1, width.max(1)) as usize,
        size.1.clamp(1, height.max(1)) as usize,
    );
    // Summed-area table with a zero row and column in front.
    let mut sat = vec![0u32; (w + 1) * (h + 1)];
    let mut marks = vec![0u32; w * h];
    for (&p, &r) in pixels.iter().zip(reference) {
        if p < marks.len() && r > PENUMBRA.0 && r < PENUMBRA.1 {
            marks[p] = 1;
        }
    }
    for y in 0..h {
        let mut row = 0;
        for x in 0..w {
            row += marks[y * w + x];
            sat[(y + 1) * (w + 1) + x + 1] = sat[y * (w + 1) + x + 1] + row;
        }
    }
    let count = |x: usize, y: usize| {
        let at = |x: usize, y: usize| sat[y * (w + 1) + x] as i64;
        (at(x + cw, y + ch) - at(x, y + ch) - at(x + cw, y) + at(x, y)) as usize
    };
    let mut best = (0, 0, 0);
    for y in 0..=h.saturating_sub(ch) {
        for x in 0..=w.saturating_sub(cw) {
            let n = count(x, y);
            if n > best.2 {
                best = (x, y, n);
            }
        }
    }
    let crop = Crop {
        x: best.0 as u32,
        y: best.1 as u32,
        width: cw as u32,
        height: ch as u32,
    };
    (crop, best.2)
}

/// Per-pixel values of the scored points of a `width`-wide frame inside `crop`: None where
/// not scored.
fn cropped_values(width: u32, crop: Crop, pixels: &[usize], values: &[f32]) -> Vec<Option<f32>> {
    let mut out = vec![None; (crop.width * crop.height) as usize];
    let w = width as usize;
    for (&p, &v) in pixels.iter().zip(values) {
        let (x, y) = ((p % w) as u32, (p / w) as u32);
        if x >= crop.x && y >= crop.y && x < crop.x + crop.width && y < crop.y + crop.height {
            out[((y - crop.y) * crop.width + (x - crop.x)) as usize] = Some(v);
        }
    }
    out
}

fn image_from(crop: Crop, values: &[Option<f32>], colour: impl Fn(f32) -> Rgb<u8>) -> RgbImage {
    RgbImage::from_fn(crop.width, crop.height, |x, y| {
        values[(y * crop.width + x) as usize].map_or(UNSCORED, &colour)
    })
}

/// Visibility (0 shadowed, 1 lit) of the scored points inside `crop`, as grey levels.
pub fn visibility_image(width: u32, crop: Crop, pixels: &[usize], values: &[f32]) -> RgbImage {
    let values = cropped_values(width, crop, pixels, values);
    image_from(crop, &values, |v| {
        let g = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
        Rgb([g, g, g])
    })
}

/// Where `technique` differs from `reference` inside `crop`: black where they agree,
/// [`TOO_BRIGHT`] or [`TOO_DARK`] with a brightness that grows as the square root of the
/// difference (a difference of 0.25 is drawn at half brightness).
pub fn error_image(width: u32, crop: Crop, pixels: &[usize], technique: &[f32], reference: &[f32]) -> RgbImage {
    let diff: Vec<f32> = technique.iter().zip(reference).map(|(t, r)| t - r).collect();
    let values = cropped_values(width, crop, pixels, &diff);
    image_from(crop, &values, |d| {
        if d.is_nan() {
            return UNSCORED;
        }
        let s = d.abs().min(1.0).sqrt();
        let c = if d > 0.0 { TOO_BRIGHT } else { TOO_DARK };
        Rgb(c.0.map(|v| (f32::from(v) * s).round() as u8))
    })
}

/// The `crop` of a rendered frame, without its alpha.
pub fn crop_render(render: &RgbaImage, crop: Crop) -> RgbImage {
    let part = imageops::crop_imm(render, crop.x, crop.y, crop.width, crop.height).to_image();
    RgbImage::from_fn(part.width(), part.height(), |x, y| {
        let p = part.get_pixel(x, y).0;
        Rgb([p[0], p[1], p[2]])
    })
}

/// `panels` side by side, `gap` pixels apart on a white ground, top-aligned.
pub fn strip(panels: &[RgbImage], gap: u32) -> RgbImage {
    let width = panels.iter().map(RgbImage::width).sum::<u32>() + gap * panels.len().saturating_sub(1) as u32;
    let height = panels.iter().map(RgbImage::height).max().unwrap_or(0);
    let mut out = RgbImage::from_pixel(width.max(1), height.max(1), Rgb([255, 255, 255]));
    let mut x = 0;
    for panel in panels {
        imageops::replace(&mut out, panel, i64::from(x), 0);
        x += panel.width() + gap;
    }
    out
}

/// `image` scaled by a whole `factor`, each pixel a `factor × factor` block.
pub fn upscale(image: &RgbImage, factor: u32) -> RgbImage {
    let f = factor.max(1);
    imageops::resize(
        image,
        image.width() * f,
        image.height() * f,
        imageops::FilterType::Nearest,
    )
}

/// One captioned panel: an image, a title and lines of figures under it.
pub struct Panel<'a> {
    /// The picture.
    pub image: &'a RgbImage,
    /// The caption's first line (the technique), in bold.
    pub title: &'a str,
    /// Further caption lines (its figures).
    pub lines: &'a [String],
}

/// `panels` side by side with their captions under them, on a white ground.
pub fn captioned(panels: &[Panel<'_>]) -> RgbImage {
    const GAP: u32 = 12;
    let pictures = strip(&panels.iter().map(|p| p.image.clone()).collect::<Vec<_>>(), GAP);
    let Ok(fonts) = Fonts::load() else {
        return pictures;
    };
    let title = Style {
        font: &fonts.sans,
        px: 22.0,
        color: Rgb([20, 20, 20]),
        bold: true,
    };
    let detail = Style {
        font: &fonts.mono,
        px: 16.0,
        color: Rgb([70, 70, 70]),
        bold: false,
    };
    let line = |s: Style<'_>| measure(s.font, s.px, "Ag").1;
    let most_lines = panels.iter().map(|p| p.lines.len()).max().unwrap_or(0) as f32;
    let caption = (line(title) + most_lines * line(detail) + 10.0).ceil() as u32;
    let mut out = RgbImage::from_pixel(pictures.width(), pictures.height() + caption, Rgb([255, 255, 255]));
    imageops::replace(&mut out, &pictures, 0, 0);
    let mut x = 0.0;
    for p in panels {
        let centre = x + p.image.width() as f32 / 2.0;
        let mut y = pictures.height() as f32 + 4.0;
        text(&mut out, title, p.title, (centre, y), (0.5, 0.0));
        y += line(title);
        for l in p.lines {
            text(&mut out, detail, l, (centre, y), (0.5, 0.0));
            y += line(detail);
        }
        x += (p.image.width() + GAP) as f32;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 12 × 8 frame scored everywhere, with penumbra values only in columns 8–10 of rows
    /// 4–6.
    fn frame() -> (Vec<usize>, Vec<f32>) {
        let pixels: Vec<usize> = (0..12 * 8).collect();
        let reference = pixels
            .iter()
            .map(|&p| {
                let (x, y) = (p % 12, p / 12);
                if (8..=10).contains(&x) && (4..=6).contains(&y) {
                    0.5
                } else {
                    1.0
                }
            })
            .collect();
        (pixels, reference)
    }

    #[test]
    fn the_window_covers_the_penumbra() {
        let (pixels, reference) = frame();
        let (crop, count) = penumbra_window((12, 8), &pixels, &reference, (4, 4));
        assert_eq!(count, 9);
        assert!(crop.x <= 8 && crop.x + crop.width > 10, "{crop:?}");
        assert!(crop.y <= 4 && crop.y + crop.height > 6, "{crop:?}");
        // A window larger than the frame is the frame.
        let (all, n) = penumbra_window((12, 8), &pixels, &reference, (40, 40));
        assert_eq!((all.x, all.y, all.width, all.height, n), (0, 0, 12, 8, 9));
        // Without penumbra: the top-left window, holding none.
        let lit = vec![1.0; pixels.len()];
        assert_eq!(penumbra_window((12, 8), &pixels, &lit, (4, 4)).1, 0);
    }

    #[test]
    fn errors_are_coloured_by_sign_and_unscored_pixels_are_marked() {
        let crop = Crop {
            x: 0,
            y: 0,
            width: 2,
            height: 2,
        };
        // Pixel 3 is not scored.
        let pixels = [0, 1, 2];
        let img = error_image(2, crop, &pixels, &[1.0, 0.0, 0.5], &[0.0, 1.0, 0.5]);
        assert_eq!(*img.get_pixel(0, 0), TOO_BRIGHT);
        assert_eq!(*img.get_pixel(1, 0), TOO_DARK);
        assert_eq!(*img.get_pixel(0, 1), Rgb([0, 0, 0]));
        assert_eq!(*img.get_pixel(1, 1), UNSCORED);
        // A quarter of a difference is drawn at half brightness.
        let half = error_image(2, crop, &[0], &[0.75], &[0.5]);
        assert_eq!(half.get_pixel(0, 0).0[0], 128);
        let vis = visibility_image(2, crop, &pixels, &[1.0, 0.0, 0.5]);
        assert_eq!(vis.get_pixel(0, 0).0, [255; 3]);
        assert_eq!(vis.get_pixel(0, 1).0, [128; 3]);
        assert_eq!(*vis.get_pixel(1, 1), UNSCORED);
    }

    #[test]
    fn strips_and_captions_keep_every_panel() {
        let a = RgbImage::from_pixel(3, 2, Rgb([255, 0, 0]));
        let b = RgbImage::from_pixel(2, 4, Rgb([0, 0, 255]));
        let s = strip(&[a.clone(), b.clone()], 1);
        assert_eq!(s.dimensions(), (6, 4));
        assert_eq!(*s.get_pixel(0, 0), Rgb([255, 0, 0]));
        assert_eq!(*s.get_pixel(4, 3), Rgb([0, 0, 255]));
        assert_eq!(upscale(&a, 2).dimensions(), (6, 4));
        let img = upscale(&a, 20);
        let c = captioned(&[Panel {
            image: &img,
            title: "PCF",
            lines: &["0.1 ms".to_owned()],
        }]);
        assert_eq!(c.width(), 60);
        assert!(c.height() > 40);
        // The caption has ink.
        let ink = (40..c.height())
            .flat_map(|y| (0..60).map(move |x| (x, y)))
            .filter(|&(x, y)| c.get_pixel(x, y).0[0] < 128)
            .count();
        assert!(ink > 10, "{ink}");
        let render = RgbaImage::from_pixel(4, 4, image::Rgba([1, 2, 3, 255]));
        let crop = Crop {
            x: 1,
            y: 1,
            width: 2,
            height: 3,
        };
        assert_eq!(crop_render(&render, crop).dimensions(), (2, 3));
    }
}
