//! Drawing primitives on an `image::RgbImage`: boxes, blending, filled rectangles,
//! anti-aliased discs and Xiaolin Wu lines. Positions are continuous: pixel `i` spans
//! `[i, i + 1)`, so its centre is `i + 0.5`.

use image::{Rgb, RgbImage};

/// An axis-aligned box in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Rect {
    pub x0: f32,
    pub y0: f32,
    pub x1: f32,
    pub y1: f32,
}

impl Rect {
    /// The box from `(x0, y0)` to `(x1, y1)`.
    pub const fn new(x0: f32, y0: f32, x1: f32, y1: f32) -> Self {
        Self { x0, y0, x1, y1 }
    }

    /// The `2r × 2r` box centred at `(cx, cy)`.
    pub fn around(cx: f32, cy: f32, r: f32) -> Self {
        Self::new(cx - r, cy - r, cx + r, cy + r)
    }

    /// This box grown by `d` on every side.
    pub fn grow(self, d: f32) -> Self {
        Self::new(self.x0 - d, self.y0 - d, self.x1 + d, self.y1 + d)
    }

    /// Whether the two boxes share any area.
    pub fn overlaps(&self, o: &Self) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }

    /// Whether this box lies within `o`.
    pub fn inside(&self, o: &Self) -> bool {
        self.x0 >= o.x0 && self.x1 <= o.x1 && self.y0 >= o.y0 && self.y1 <= o.y1
    }

    /// Distance from `(x, y)` to the nearest point of the box, and that point.
    pub fn nearest(&self, x: f32, y: f32) -> (f32, (f32, f32)) {
        let (nx, ny) = (x.clamp(self.x0, self.x1), y.clamp(self.y0, self.y1));
        ((nx - x).hypot(ny - y), (nx, ny))
    }
}

/// Mixes `color` into the pixel `(x, y)` with weight `alpha`; outside the image does nothing.
pub(crate) fn blend(img: &mut RgbImage, x: i64, y: i64, color: Rgb<u8>, alpha: f32) {
    if alpha <= 0.0 || x < 0 || y < 0 || x >= i64::from(img.width()) || y >= i64::from(img.height()) {
        return;
    }
    let a = alpha.min(1.0);
    let pixel = img.get_pixel_mut(x as u32, y as u32);
    for (p, c) in pixel.0.iter_mut().zip(color.0) {
        *p = (f32::from(*p) * (1.0 - a) + f32::from(c) * a).round() as u8;
    }
}

/// Fills the pixels whose top-left corners, rounded, lie in `r`.
pub(crate) fn fill_rect(img: &mut RgbImage, r: Rect, color: Rgb<u8>) {
    for y in r.y0.round() as i64..r.y1.round() as i64 {
        for x in r.x0.round() as i64..r.x1.round() as i64 {
            blend(img, x, y, color, 1.0);
        }
    }
}

/// An anti-aliased filled disc of radius `r` centred at `(cx, cy)`.
pub(crate) fn disc(img: &mut RgbImage, cx: f32, cy: f32, r: f32, color: Rgb<u8>) {
    for y in (cy - r - 1.0).floor() as i64..=(cy + r + 1.0).ceil() as i64 {
        for x in (cx - r - 1.0).floor() as i64..=(cx + r + 1.0).ceil() as i64 {
            let d = (x as f32 + 0.5 - cx).hypot(y as f32 + 0.5 - cy);
            blend(img, x, y, color, (r + 0.5 - d).clamp(0.0, 1.0));
        }
    }
}

/// An anti-aliased one-pixel line (Xiaolin Wu) from `a` to `b`.
pub(crate) fn wu_line(img: &mut RgbImage, a: (f32, f32), b: (f32, f32), color: Rgb<u8>) {
    // Wu's algorithm puts integer coordinates at pixel centres.
    let (mut x0, mut y0, mut x1, mut y1) = (a.0 - 0.5, a.1 - 0.5, b.0 - 0.5, b.1 - 0.5);
    let steep = (y1 - y0).abs() > (x1 - x0).abs();
    if steep {
        (x0, y0, x1, y1) = (y0, x0, y1, x1);
    }
    if x0 > x1 {
        (x0, y0, x1, y1) = (x1, y1, x0, y0);
    }
    let gradient = if x1 == x0 { 1.0 } else { (y1 - y0) / (x1 - x0) };
    let mut plot = |x: f32, y: f32, a: f32| {
        let (x, y) = if steep { (y, x) } else { (x, y) };
        blend(img, x as i64, y as i64, color, a);
    };
    let mut endpoint = |x: f32, y: f32, gap: f32| {
        let x_end = x.round();
        let y_end = y + gradient * (x_end - x);
        plot(x_end, y_end.floor(), (1.0 - y_end.fract()) * gap);
        plot(x_end, y_end.floor() + 1.0, y_end.fract() * gap);
        (x_end, y_end)
    };
    let (start, y_start) = endpoint(x0, y0, 1.0 - (x0 + 0.5).fract());
    let (end, _) = endpoint(x1, y1, (x1 + 0.5).fract());
    let (mut x, mut y) = (start + 1.0, y_start + gradient);
    while x < end {
        plot(x, y.floor(), 1.0 - (y - y.floor()));
        plot(x, y.floor() + 1.0, y - y.floor());
        (x, y) = (x + 1.0, y + gradient);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const WHITE: Rgb<u8> = Rgb([255, 255, 255]);
    const BLACK: Rgb<u8> = Rgb([0, 0, 0]);

    /// Ink (0 = white, 1 = black) of the pixel.
    fn ink(img: &RgbImage, x: u32, y: u32) -> f32 {
        1.0 - f32::from(img.get_pixel(x, y).0[0]) / 255.0
    }

    #[test]
    fn wu_line_puts_about_one_pixel_of_ink_per_column() {
        let mut img = RgbImage::from_pixel(20, 20, WHITE);
        wu_line(&mut img, (2.5, 2.5), (17.5, 12.5), BLACK);
        for x in 3..17 {
            let column: f32 = (0..20).map(|y| ink(&img, x, y)).sum();
            assert!((0.85..1.15).contains(&column), "column {x}: {column}");
        }
        // Anti-aliased: some pixels are partly covered.
        assert!((0..20).any(|y| (0.2..0.8).contains(&ink(&img, 9, y))));
        assert_eq!(*img.get_pixel(17, 2), WHITE);
        // Half-covered end pixels: the ink adds up to the length along x.
        let mut img = RgbImage::from_pixel(20, 20, WHITE);
        wu_line(&mut img, (2.5, 2.9), (17.5, 12.3), BLACK);
        let total: f32 = (0..20)
            .flat_map(|x| (0..20).map(move |y| (x, y)))
            .map(|(x, y)| ink(&img, x, y))
            .sum();
        assert!((total - 15.0).abs() < 0.15, "{total}");
        // Steep lines, drawn either way, cover each row.
        let mut img = RgbImage::from_pixel(20, 20, WHITE);
        wu_line(&mut img, (10.5, 18.5), (6.5, 1.5), BLACK);
        for y in 2..18 {
            let row: f32 = (0..20).map(|x| ink(&img, x, y)).sum();
            assert!((0.85..1.15).contains(&row), "row {y}: {row}");
        }
    }

    #[test]
    fn disc_and_rect_cover_their_area() {
        let mut img = RgbImage::from_pixel(20, 20, WHITE);
        disc(&mut img, 10.0, 10.0, 4.0, BLACK);
        let total: f32 = (0..20)
            .flat_map(|x| (0..20).map(move |y| (x, y)))
            .map(|(x, y)| ink(&img, x, y))
            .sum();
        let area = std::f32::consts::PI * 16.0;
        assert!((total - area).abs() < 1.0, "{total} vs {area}");
        assert_eq!(*img.get_pixel(10, 10), BLACK);
        assert_eq!(*img.get_pixel(15, 15), WHITE);
        let mut img = RgbImage::from_pixel(20, 20, WHITE);
        fill_rect(&mut img, Rect::new(2.0, 3.0, 5.0, 4.0), BLACK);
        let filled: Vec<(u32, u32)> = img
            .enumerate_pixels()
            .filter(|p| *p.2 == BLACK)
            .map(|p| (p.0, p.1))
            .collect();
        assert_eq!(filled, [(2, 3), (3, 3), (4, 3)]);
        // Off-image drawing is clipped, not a panic.
        disc(&mut img, -1.0, 25.0, 5.0, BLACK);
    }

    #[test]
    fn rect_relations() {
        let a = Rect::new(0.0, 0.0, 10.0, 10.0);
        assert!(a.overlaps(&Rect::new(9.0, 9.0, 12.0, 12.0)));
        assert!(!a.overlaps(&Rect::new(10.0, 0.0, 12.0, 10.0)));
        assert!(Rect::new(1.0, 1.0, 2.0, 2.0).inside(&a) && !a.grow(1.0).inside(&a));
        assert_eq!(a.nearest(13.0, 14.0), (5.0, (10.0, 10.0)));
        assert_eq!(a.nearest(5.0, 5.0).0, 0.0);
    }
}
