//! Text rendering for the plot with `ab_glyph` and fonts embedded from `epaint_default_fonts`
//! (Ubuntu Light for prose, Hack for numbers), so no font file or system font library is
//! needed at run time.

use ab_glyph::{Font, FontRef, GlyphId, InvalidFont, PxScale, ScaleFont, point};
use image::{Rgb, RgbImage};

use crate::analysis::raster::blend;

/// The two embedded typefaces.
pub(crate) struct Fonts {
    /// Proportional, for titles and labels.
    pub sans: FontRef<'static>,
    /// Monospaced, for tick labels (digits line up).
    pub mono: FontRef<'static>,
}

impl Fonts {
    /// Parses the embedded fonts.
    pub fn load() -> Result<Self, InvalidFont> {
        Ok(Self {
            sans: FontRef::try_from_slice(epaint_default_fonts::UBUNTU_LIGHT)?,
            mono: FontRef::try_from_slice(epaint_default_fonts::HACK_REGULAR)?,
        })
    }
}

/// One line of text as a coverage mask (0 = empty, 1 = ink), row-major, `width × height`.
pub(crate) struct TextMask {
    pub width: usize,
    pub height: usize,
    pub coverage: Vec<f32>,
}

impl TextMask {
    /// Coverage at `(x, y)`.
    pub fn at(&self, x: usize, y: usize) -> f32 {
        self.coverage[y * self.width + x]
    }
}

/// Glyph ids of `text` with the x of each glyph's origin, and the total advance width.
fn layout(font: &FontRef<'_>, px: f32, text: &str) -> (Vec<(GlyphId, f32)>, f32) {
    let scaled = font.as_scaled(PxScale::from(px));
    let mut caret = 0.0;
    let mut prev: Option<GlyphId> = None;
    let mut glyphs = Vec::with_capacity(text.len());
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(prev) = prev {
            caret += scaled.kern(prev, id);
        }
        glyphs.push((id, caret));
        caret += scaled.h_advance(id);
        prev = Some(id);
    }
    (glyphs, caret)
}

/// Renders `text` at `px` pixels (ascent − descent) into a mask one line high; `bold` draws
/// each glyph a second time 0.7 px to the right.
pub(crate) fn render(font: &FontRef<'_>, px: f32, text: &str, bold: bool) -> TextMask {
    let scaled = font.as_scaled(PxScale::from(px));
    let (glyphs, advance) = layout(font, px, text);
    let pad = 2.0;
    let width = (advance + 2.0 * pad).ceil() as usize;
    let height = (scaled.ascent() - scaled.descent()).ceil() as usize + 2;
    let baseline = 1.0 + scaled.ascent();
    let mut coverage = vec![0.0f32; width * height];
    let offsets: &[f32] = if bold { &[0.0, 0.7] } else { &[0.0] };
    for &(id, x) in &glyphs {
        for &dx in offsets {
            let glyph = id.with_scale_and_position(scaled.scale(), point(pad + x + dx, baseline));
            let Some(outlined) = font.outline_glyph(glyph) else {
                continue;
            };
            let bounds = outlined.px_bounds();
            outlined.draw(|gx, gy, c| {
                let x = bounds.min.x as i64 + i64::from(gx);
                let y = bounds.min.y as i64 + i64::from(gy);
                if (0..width as i64).contains(&x) && (0..height as i64).contains(&y) {
                    let cell = &mut coverage[y as usize * width + x as usize];
                    *cell = cell.max(c.min(1.0));
                }
            });
        }
    }
    TextMask {
        width,
        height,
        coverage,
    }
}

/// Width and height in pixels of the mask that [`render`] makes of `text`.
pub(crate) fn measure(font: &FontRef<'_>, px: f32, text: &str) -> (f32, f32) {
    let scaled = font.as_scaled(PxScale::from(px));
    let (_, advance) = layout(font, px, text);
    (
        (advance + 4.0).ceil(),
        (scaled.ascent() - scaled.descent()).ceil() + 2.0,
    )
}

/// How a piece of text is drawn.
#[derive(Clone, Copy)]
pub(crate) struct Style<'a> {
    pub font: &'a FontRef<'a>,
    pub px: f32,
    pub color: Rgb<u8>,
    pub bold: bool,
}

/// Draws `s` so that the point `(x, y)` sits at fraction `align` of its box (0 = left/top).
pub(crate) fn text(img: &mut RgbImage, style: Style<'_>, s: &str, (x, y): (f32, f32), align: (f32, f32)) {
    let mask = render(style.font, style.px, s, style.bold);
    let x0 = x - mask.width as f32 * align.0;
    let y0 = y - mask.height as f32 * align.1;
    blit(img, &mask, (x0.round() as i64, y0.round() as i64), style.color, false);
}

/// Paints `color` through `mask` with its top-left at `at`; `rotated` turns it a quarter
/// counter-clockwise (reading upwards), so that it covers `height × width` pixels.
pub(crate) fn blit(img: &mut RgbImage, mask: &TextMask, at: (i64, i64), color: Rgb<u8>, rotated: bool) {
    for my in 0..mask.height {
        for mx in 0..mask.width {
            let (dx, dy) = if rotated { (my, mask.width - 1 - mx) } else { (mx, my) };
            blend(img, at.0 + dx as i64, at.1 + dy as i64, color, mask.at(mx, my));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fonts_load_and_cover_the_characters_used() {
        let fonts = Fonts::load().expect("embedded fonts parse");
        for c in "GPU time vs penumbra MAE — × ms 0123456789.−-(),:".chars() {
            assert_ne!(fonts.sans.glyph_id(c).0, 0, "sans lacks {c:?}");
        }
        for c in "0123456789.-−".chars() {
            assert_ne!(fonts.mono.glyph_id(c).0, 0, "mono lacks {c:?}");
        }
    }

    #[test]
    fn render_draws_ink_within_the_measured_size() {
        let fonts = Fonts::load().expect("embedded fonts parse");
        let mask = render(&fonts.sans, 20.0, "Hello", false);
        assert_eq!(
            (mask.width as f32, mask.height as f32),
            measure(&fonts.sans, 20.0, "Hello")
        );
        let ink: f32 = mask.coverage.iter().sum();
        assert!(ink > 20.0, "too little ink: {ink}");
        let bold: f32 = render(&fonts.sans, 20.0, "Hello", true).coverage.iter().sum();
        assert!(bold > ink, "bold {bold} not darker than {ink}");
        assert!(measure(&fonts.sans, 20.0, "Hello world").0 > mask.width as f32);
        assert_eq!(render(&fonts.sans, 20.0, "", false).coverage.iter().sum::<f32>(), 0.0);
    }

    #[test]
    fn blit_rotates_a_quarter_counter_clockwise() {
        let mask = TextMask {
            width: 3,
            height: 2,
            coverage: vec![1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        };
        let mut img = RgbImage::from_pixel(4, 4, Rgb([255, 255, 255]));
        blit(&mut img, &mask, (0, 0), Rgb([0, 0, 0]), true);
        // The mask's top-left ends at the bottom-left of its rotated 2 × 3 footprint.
        let inked: Vec<(u32, u32)> = img
            .enumerate_pixels()
            .filter(|p| p.2.0[0] == 0)
            .map(|p| (p.0, p.1))
            .collect();
        assert_eq!(inked, [(0, 2)]);
    }
}
