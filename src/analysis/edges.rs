//! Where acne and leaks lie: next to a shadow edge of the reference (where a shadow drawn a
//! texel too wide or too narrow lands: resolution, filter width, blocker search) or away from
//! every edge (a surface shadowing itself, or light through a solid caster: bias). A scored
//! pixel is next to an edge when a scored pixel within [`EDGE_RADIUS`] pixels of it on the
//! analysis image has a reference value of the other kind (not fully lit around a lit pixel,
//! not fully shadowed around a shadowed one).

use serde::Serialize;

use crate::analysis::metrics::Thresholds;

/// Pixels around a scored pixel (on the analysis image) searched for a reference edge.
pub const EDGE_RADIUS: i64 = 2;

/// Acne and leak rates split by where they lie, as shares of all fully lit and fully
/// shadowed reference pixels (so the two parts add up to the overall rate).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct EdgeSplit {
    /// Acne within [`EDGE_RADIUS`] pixels of a reference pixel that is not fully lit.
    pub acne_near_edges: f64,
    /// Acne with only fully lit reference pixels around it.
    pub acne_away_from_edges: f64,
    /// Leaks within [`EDGE_RADIUS`] pixels of a reference pixel that is not fully shadowed.
    pub leak_near_edges: f64,
    /// Leaks with only fully shadowed reference pixels around it.
    pub leak_away_from_edges: f64,
}

/// Splits the acne and leaks of `technique` against `reference`, one value per scored
/// pixel, where `pixels[k]` is the index (row by row, `width` wide) of scored pixel `k` on
/// the analysis image. NaN values are not scored.
///
/// # Panics
/// If the three slices differ in length.
pub fn edge_split(
    technique: &[f32],
    reference: &[f32],
    pixels: &[usize],
    (width, height): (u32, u32),
    t: &Thresholds,
) -> EdgeSplit {
    assert!(technique.len() == reference.len() && reference.len() == pixels.len());
    let (w, h) = (i64::from(width), i64::from(height));
    let mut image = vec![f32::NAN; (width as usize) * (height as usize)];
    for (&p, &r) in pixels.iter().zip(reference) {
        if let Some(slot) = image.get_mut(p) {
            *slot = r;
        }
    }
    let around = |p: usize, other: &dyn Fn(f32) -> bool| {
        let (x, y) = ((p as i64) % w.max(1), (p as i64) / w.max(1));
        (-EDGE_RADIUS..=EDGE_RADIUS).any(|dy| {
            (-EDGE_RADIUS..=EDGE_RADIUS).any(|dx| {
                let (nx, ny) = (x + dx, y + dy);
                (0..w).contains(&nx) && (0..h).contains(&ny) && {
                    let v = image[(ny * w + nx) as usize];
                    !v.is_nan() && other(v)
                }
            })
        })
    };
    let (mut lit, mut shadowed) = (0u64, 0u64);
    let mut counts = [0u64; 4];
    for ((&tech, &r), &p) in technique.iter().zip(reference).zip(pixels) {
        if tech.is_nan() || r.is_nan() {
            continue;
        }
        if r >= t.lit {
            lit += 1;
            if tech < t.acne_below {
                let near = around(p, &|v| v < t.lit);
                counts[usize::from(!near)] += 1;
            }
        } else if r <= t.shadowed {
            shadowed += 1;
            if tech > t.leak_above {
                let near = around(p, &|v| v > t.shadowed);
                counts[2 + usize::from(!near)] += 1;
            }
        }
    }
    let rate = |n: u64, of: u64| if of == 0 { 0.0 } else { n as f64 / of as f64 };
    EdgeSplit {
        acne_near_edges: rate(counts[0], lit),
        acne_away_from_edges: rate(counts[1], lit),
        leak_near_edges: rate(counts[2], shadowed),
        leak_away_from_edges: rate(counts[3], shadowed),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn acne_and_leaks_are_split_by_their_distance_to_an_edge() {
        // A 10×1 strip: reference lit on x < 5, shadowed from x = 5.
        let pixels: Vec<usize> = (0..10).collect();
        let reference: Vec<f32> = (0..10).map(|x| if x < 5 { 1.0 } else { 0.0 }).collect();
        // Dark at x = 0 (away) and x = 4 (next to the edge); lit at x = 5 (next) and 9 (away).
        let mut technique = reference.clone();
        technique[0] = 0.0;
        technique[4] = 0.0;
        technique[5] = 1.0;
        technique[9] = 1.0;
        let split = edge_split(&technique, &reference, &pixels, (10, 1), &Thresholds::default());
        assert_eq!(
            split,
            EdgeSplit {
                acne_near_edges: 0.2,
                acne_away_from_edges: 0.2,
                leak_near_edges: 0.2,
                leak_away_from_edges: 0.2,
            }
        );
    }

    #[test]
    fn unscored_neighbours_are_no_edge_and_nothing_scored_is_zero() {
        // Two lit pixels far apart on a 9×1 image, one dark: no reference edge in reach.
        let split = edge_split(&[0.0, 1.0], &[1.0, 1.0], &[0, 8], (9, 1), &Thresholds::default());
        assert_eq!(split.acne_away_from_edges, 0.5);
        assert_eq!(split.acne_near_edges, 0.0);
        assert_eq!(
            edge_split(&[], &[], &[], (4, 4), &Thresholds::default()),
            EdgeSplit::default()
        );
    }
}
