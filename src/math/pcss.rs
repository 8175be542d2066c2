//! CPU-side PCSS parameters of one cascade: how the light's angular size maps a
//! blocker-to-receiver distance to a penumbra width in shadow-map UV.

/// Largest angular diameter (radians) used; larger values are clamped so `tan(θ/2)` stays
/// finite. NaN and negative values become 0.
pub const MAX_ANGULAR_DIAMETER: f32 = 3.0;

/// Per-cascade PCSS scale factors for a light of angular diameter `θ`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PcssParams {
    /// `2·tan(θ/2) / width_x`: penumbra width in UV (u) per world unit of blocker-to-receiver
    /// distance; also the blocker-search radius scale.
    pub light_size_uv: f32,
    /// `depth_range · 2·tan(θ/2) / width_x`: multiplies a difference of NDC depths (which is
    /// `world distance / depth_range`) to give the penumbra width in UV (u).
    pub pcss_scale: f32,
    /// `width_x / width_y`: multiplies a u-size to get the v-size covering the same world
    /// distance (elliptical kernels on non-square cascades).
    pub uv_scale_y: f32,
}

/// The PCSS parameters of a cascade whose ortho box is `width_x × width_y` world units
/// laterally and `depth_range` world units deep, for a light of angular diameter
/// `angular_diameter` (radians; the sun is about 0.0093).
///
/// - `light_size_uv = 2·tan(θ/2) / width_x`
/// - `pcss_scale = depth_range · 2·tan(θ/2) / width_x`
/// - `uv_scale_y = width_x / width_y`
///
/// Widths and depth below `f32::MIN_POSITIVE` (or NaN) are treated as that value, and all
/// results are clamped to finite values.
pub fn pcss_params(angular_diameter: f32, width_x: f32, width_y: f32, depth_range: f32) -> PcssParams {
    pcss_params_f64(
        angular_diameter,
        f64::from(width_x),
        f64::from(width_y),
        f64::from(depth_range),
    )
}

/// [`pcss_params`] with the box sizes in f64.
pub(crate) fn pcss_params_f64(angular_diameter: f32, width_x: f64, width_y: f64, depth_range: f64) -> PcssParams {
    let theta = if angular_diameter.is_nan() {
        0.0
    } else {
        f64::from(angular_diameter.clamp(0.0, MAX_ANGULAR_DIAMETER))
    };
    // NOTE: guard every divisor: a positive floor (which also maps NaN to the floor) keeps
    // the quotients finite, and the final clamp keeps them inside f32 range.
    let floor = f64::from(f32::MIN_POSITIVE);
    let wx = width_x.max(floor);
    let wy = width_y.max(floor);
    let depth = depth_range.max(floor);
    let spread = 2.0 * (0.5 * theta).tan();
    let finite = |v: f64| v.min(f64::from(f32::MAX)) as f32;
    PcssParams {
        light_size_uv: finite(spread / wx),
        pcss_scale: finite(depth * spread / wx),
        // NOTE: a ratio, so it is also kept away from zero (an extreme width_y would
        // otherwise underflow it).
        uv_scale_y: finite(wx / wy).max(f32::MIN_POSITIVE),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formulas() {
        let theta = 0.02_f32;
        let p = pcss_params(theta, 40.0, 20.0, 300.0);
        let s = 2.0 * (theta * 0.5).tan();
        assert!((p.light_size_uv - s / 40.0).abs() < 1e-9);
        assert!((p.pcss_scale - 300.0 * s / 40.0).abs() < 1e-6);
        assert_eq!(p.uv_scale_y, 2.0);
    }

    #[test]
    fn penumbra_in_uv_matches_geometry() {
        // A blocker 10 m above a receiver under a light of angular diameter θ casts a
        // penumbra 10·2·tan(θ/2) m wide; in a 50 m wide cascade that is that / 50 in UV.
        let (theta, width, depth) = (0.1_f32, 50.0, 200.0);
        let p = pcss_params(theta, width, width, depth);
        let ndc_depth_difference = 10.0 / depth;
        let uv = ndc_depth_difference * p.pcss_scale;
        let want = 10.0 * 2.0 * (theta * 0.5).tan() / width;
        assert!((uv - want).abs() < 1e-7);
        assert!((10.0 * p.light_size_uv - want).abs() < 1e-7);
    }

    #[test]
    fn bad_inputs_stay_finite() {
        for p in [
            pcss_params(f32::NAN, 0.0, 0.0, 0.0),
            pcss_params(10.0, f32::MIN_POSITIVE, f32::MAX, f32::MAX),
            pcss_params(-1.0, -5.0, f32::NAN, -1.0),
        ] {
            assert!(p.light_size_uv.is_finite() && p.light_size_uv >= 0.0, "{p:?}");
            assert!(p.pcss_scale.is_finite() && p.pcss_scale >= 0.0, "{p:?}");
            assert!(p.uv_scale_y.is_finite() && p.uv_scale_y > 0.0, "{p:?}");
        }
        assert_eq!(pcss_params(0.0, 1.0, 1.0, 1.0).pcss_scale, 0.0);
    }
}
