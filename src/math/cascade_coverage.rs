//! What a cascade box must cover: the light-space bounds of its slice of the view frustum
//! (Tight) or of a sphere around the camera (Stable), cut to the receivers where they meet,
//! as offsets from the camera so that a camera translation leaves them unchanged.

use glam::{DMat3, DVec3};

use crate::math::aabb::Aabb;
use crate::math::clip::clipped_bounds;
use crate::math::frustum::CameraBasis;

/// What a cascade box must cover, relative to the camera position in the light frame.
pub(crate) struct Coverage {
    /// Smallest light-space offset from the camera to cover.
    pub lo: DVec3,
    /// Largest light-space offset from the camera to cover.
    pub hi: DVec3,
    /// The light-most offset of the whole slice (or sphere), receivers or not: the box's
    /// light side reaches at least this far, so that only casters rising above it (not
    /// receivers moving) change the box's depth.
    pub top: f64,
}

/// How far, in texels of a cascade, shadow filters read around a receiver: the widest PCSS
/// kernel (32 texels) plus the largest PCF radius and the normal offset, rounded up. A box
/// fitted to its receivers keeps this margin around them laterally, so no filter reads past
/// its edge.
pub const FILTER_REACH_TEXELS: f64 = 48.0;

impl Coverage {
    /// This coverage cut laterally to `[lo, hi]` (the part of it that receives shadows),
    /// grown by [`FILTER_REACH_TEXELS`] of the box it makes at `resolution` texels but never
    /// past this coverage; its depth keeps this coverage's far side and top, and its `hi.z`
    /// becomes the receivers' top (where the receivers start in depth).
    fn clipped(&self, lo: DVec3, hi: DVec3, resolution: f64) -> Coverage {
        // NOTE: the margin is a share of the grown box: w' = w + 2·reach·w'/res.
        let share = (2.0 * FILTER_REACH_TEXELS / resolution.max(2.0 * FILTER_REACH_TEXELS + 1.0)).min(0.5);
        let grow = (hi - lo) * (0.5 * share / (1.0 - share));
        let margin = DVec3::new(grow.x, grow.y, 0.0);
        // NOTE: the far side stays the whole slice's: raised to the receivers' bottom, it
        // changed the hardware bias's clamp in metres (a share of the box's depth) and with
        // it which texels PCSS finds at the rim of umbrae.
        let lo = (lo - margin).max(self.lo);
        Coverage {
            lo: DVec3::new(lo.x, lo.y, self.lo.z),
            hi: (hi + margin).min(self.hi),
            top: self.top,
        }
    }
}

/// The receivers' box as offsets from the camera position `camera`, if usable.
pub(crate) fn receivers_from_camera(bounds: &Aabb, camera: DVec3) -> Option<(DVec3, DVec3)> {
    if bounds.is_empty() || !bounds.is_finite() {
        return None;
    }
    Some((bounds.min.as_dvec3() - camera, bounds.max.as_dvec3() - camera))
}

/// Tight fit: the light-space bounds of the slice corners, or of the slice's part inside the
/// receivers' box where they meet, as offsets from the camera.
pub(crate) fn tight_coverage(
    basis: &CameraBasis,
    rot: &DMat3,
    (near, far): (f64, f64),
    receivers: Option<(DVec3, DVec3)>,
    resolution: f64,
) -> Coverage {
    // NOTE: the corners are taken relative to the camera *before* rotating, so the extents
    // do not depend on the camera position at all: translating the camera cannot change
    // the box size, not even by a rounding error (unless the receivers' box clips it).
    let corners = basis.slice_offsets(near, far);
    let offsets = corners.map(|o| *rot * o);
    let lo = offsets.iter().fold(DVec3::INFINITY, |a, &o| a.min(o));
    let hi = offsets.iter().fold(DVec3::NEG_INFINITY, |a, &o| a.max(o));
    let whole = Coverage { lo, hi, top: hi.z };
    match receivers.and_then(|(min, max)| clipped_bounds(&corners, min, max, rot)) {
        Some((lo, hi)) => whole.clipped(lo, hi, resolution),
        None => whole,
    }
}

/// Stable fit: a sphere around the camera reaching the slice's farthest corner, cut to the
/// light-space bounds of the receivers' box where they meet (both are fixed while the camera
/// turns in place).
pub(crate) fn stable_coverage(
    basis: &CameraBasis,
    rot: &DMat3,
    far: f64,
    receivers: Option<(DVec3, DVec3)>,
    resolution: f64,
) -> Coverage {
    // NOTE: the radius is computed from the projection parameters, not from rotated corner
    // positions, so it is bit-identical for every camera orientation.
    let radius = far * (1.0 + basis.tan_half_x * basis.tan_half_x + basis.tan_half_y * basis.tan_half_y).sqrt();
    let (lo, hi) = (DVec3::splat(-radius), DVec3::splat(radius));
    if let Some((min, max)) = receivers {
        let corners: [DVec3; 8] = std::array::from_fn(|i| {
            DVec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        });
        let (blo, bhi) = corners
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &c| {
                (a.min(*rot * c), b.max(*rot * c))
            });
        let (clo, chi) = (lo.max(blo), hi.min(bhi));
        if clo.cmple(chi).all() {
            return Coverage { lo, hi, top: hi.z }.clipped(clo, chi, resolution);
        }
    }
    Coverage { lo, hi, top: hi.z }
}
