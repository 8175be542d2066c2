//! Range checks of [`ShadowSettings`]: every out-of-range value is reported as a
//! [`SettingsProblem`] and clamped (NaN replaced by the default).

use std::fmt;

use crate::math::pages::{MAX_VIRTUAL_RESOLUTION, MIN_VIRTUAL_RESOLUTION, PAGE_SIZES};
use crate::settings::{
    MAX_CASCADES, MAX_CLIPMAP_LEVELS, MAX_EVSM_EXPONENT, MAX_PCF_RADIUS, MAX_RESOLUTION, MAX_SNAP_CELLS, MAX_VSM_BLUR,
    MIN_RESOLUTION, ShadowSettings, SunLayout,
};

/// One out-of-range value found in a [`ShadowSettings`].
#[derive(Clone, Debug, PartialEq)]
pub struct SettingsProblem {
    /// Field name, as written in a scene file (a dotted path for a field inside another:
    /// `layout.levels`).
    pub field: &'static str,
    /// The value that was given, formatted.
    pub found: String,
    /// What a valid value looks like.
    pub expected: &'static str,
}

impl fmt::Display for SettingsProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "`{}` is {}, expected {}", self.field, self.found, self.expected)
    }
}

/// Checks a float against an inclusive range; NaN and infinities always fail.
pub(super) fn check_f32(
    problems: &mut Vec<SettingsProblem>,
    field: &'static str,
    value: &mut f32,
    lo: f32,
    hi: f32,
    fallback: f32,
    expected: &'static str,
) {
    if !(value.is_finite() && *value >= lo && *value <= hi) {
        problems.push(SettingsProblem {
            field,
            found: format!("{value}"),
            expected,
        });
        *value = if value.is_finite() {
            value.clamp(lo, hi)
        } else {
            fallback
        };
    }
}

/// Checks an integer against an inclusive range.
pub(super) fn check_u32(
    problems: &mut Vec<SettingsProblem>,
    field: &'static str,
    value: &mut u32,
    lo: u32,
    hi: u32,
    expected: &'static str,
) {
    if !(lo..=hi).contains(value) {
        problems.push(SettingsProblem {
            field,
            found: value.to_string(),
            expected,
        });
        *value = (*value).clamp(lo, hi);
    }
}

/// Checks that `value` is a power of two in `lo..=hi`, else rounds it to the nearest one
/// there (logarithmically).
fn check_power_of_two(
    problems: &mut Vec<SettingsProblem>,
    field: &'static str,
    value: &mut u32,
    (lo, hi): (u32, u32),
    expected: &'static str,
) {
    if !(value.is_power_of_two() && (lo..=hi).contains(value)) {
        problems.push(SettingsProblem {
            field,
            found: value.to_string(),
            expected,
        });
        let rounded = 1u32 << (f64::from((*value).max(1)).log2().round() as u32).min(31);
        *value = rounded.clamp(lo, hi);
    }
}

/// What a pool's page count must be.
const POOL_PAGES_EXPECTED: &str = "from 1 to as many pages as fit an 8192² atlas (4096 of 128² pages)";

/// The most pages a pool of `page_size`² pages holds: its atlas is at most 8192 texels a
/// side (the texture size every adapter allows).
pub fn max_pool_pages(page_size: u32) -> u32 {
    let tiles = 8192 / page_size.clamp(1, 8192);
    tiles * tiles
}

impl ShadowSettings {
    /// Returns a copy with every out-of-range value clamped into its range (NaN replaced by
    /// the default), and the list of values that had to change. An empty list means the
    /// settings were valid as given.
    pub fn sanitized(&self) -> (ShadowSettings, Vec<SettingsProblem>) {
        let d = ShadowSettings::default();
        let mut s = *self;
        let mut p = Vec::new();
        check_u32(
            &mut p,
            "cascade_count",
            &mut s.map.cascades.count,
            1,
            MAX_CASCADES as u32,
            "an integer from 1 to 4",
        );
        if let SunLayout::Clipmap { levels, level0_extent }
        | SunLayout::VirtualClipmap {
            levels, level0_extent, ..
        } = &mut s.map.layout
        {
            check_u32(
                &mut p,
                "layout.levels",
                levels,
                1,
                MAX_CLIPMAP_LEVELS,
                "an integer from 1 to 8",
            );
            check_f32(
                &mut p,
                "layout.level0_extent",
                level0_extent,
                0.5,
                1.0e5,
                32.0,
                "metres from 0.5 to 1e5",
            );
        }
        if let SunLayout::VirtualClipmap {
            virtual_resolution,
            page_size,
            pool_pages,
            ..
        } = &mut s.map.layout
        {
            check_power_of_two(
                &mut p,
                "layout.virtual_resolution",
                virtual_resolution,
                (MIN_VIRTUAL_RESOLUTION, MAX_VIRTUAL_RESOLUTION),
                "a power of two from 4096 to 16384",
            );
            check_power_of_two(
                &mut p,
                "layout.page_size",
                page_size,
                (PAGE_SIZES[0], PAGE_SIZES[PAGE_SIZES.len() - 1]),
                "a power of two from 64 to 512",
            );
            let most = max_pool_pages(*page_size);
            check_u32(&mut p, "layout.pool_pages", pool_pages, 1, most, POOL_PAGES_EXPECTED);
        }
        check_u32(
            &mut p,
            "resolution",
            &mut s.map.resolution,
            MIN_RESOLUTION,
            MAX_RESOLUTION,
            "texels per side from 256 to 4096",
        );
        check_f32(
            &mut p,
            "split_lambda",
            &mut s.map.cascades.split_lambda,
            0.0,
            1.0,
            d.map.cascades.split_lambda,
            "a number from 0 (linear) to 1 (logarithmic)",
        );
        check_f32(
            &mut p,
            "max_distance",
            &mut s.map.max_distance,
            0.1,
            1.0e6,
            d.map.max_distance,
            "metres from 0.1 to 1e6",
        );
        check_f32(
            &mut p,
            "slope_bias",
            &mut s.bias.slope_bias,
            0.0,
            10.0,
            d.bias.slope_bias,
            "a number from 0 to 10",
        );
        check_f32(
            &mut p,
            "bias_clamp",
            &mut s.bias.bias_clamp,
            0.0,
            0.05,
            d.bias.bias_clamp,
            "a number from 0 to 0.05",
        );
        check_f32(
            &mut p,
            "normal_offset",
            &mut s.bias.normal_offset,
            0.0,
            5.0,
            d.bias.normal_offset,
            "shadow texels from 0 to 5",
        );
        check_u32(
            &mut p,
            "pcf_radius",
            &mut s.filter.pcf_radius,
            0,
            MAX_PCF_RADIUS,
            "an integer from 0 to 5",
        );
        check_f32(
            &mut p,
            "blend_width",
            &mut s.map.cascades.blend_width,
            0.0,
            0.5,
            d.map.cascades.blend_width,
            "a fraction from 0 to 0.5",
        );
        check_u32(
            &mut p,
            "cascade_snap_cells",
            &mut s.map.cascades.snap_cells,
            0,
            MAX_SNAP_CELLS,
            "cells per side from 0 (whole texels) to 64",
        );
        check_f32(
            &mut p,
            "distance_fade_width",
            &mut s.filter.distance_fade_width,
            0.0,
            0.5,
            d.filter.distance_fade_width,
            "a fraction from 0 to 0.5",
        );
        check_u32(
            &mut p,
            "vsm_blur",
            &mut s.filter.vsm.blur,
            0,
            MAX_VSM_BLUR,
            "texels from 0 to 8",
        );
        check_f32(
            &mut p,
            "vsm_bleed_reduction",
            &mut s.filter.vsm.bleed_reduction,
            0.0,
            0.95,
            d.filter.vsm.bleed_reduction,
            "a fraction from 0 to 0.95",
        );
        check_f32(
            &mut p,
            "vsm_min_variance",
            &mut s.filter.vsm.min_variance,
            0.0,
            0.01,
            d.filter.vsm.min_variance,
            "a fraction of the range squared from 0 to 0.01",
        );
        check_f32(
            &mut p,
            "evsm_exponent",
            &mut s.filter.moments.evsm_exponent,
            0.0,
            MAX_EVSM_EXPONENT,
            d.filter.moments.evsm_exponent,
            "a number from 0 (the format's largest) to 42",
        );
        check_f32(
            &mut p,
            "moment_blur",
            &mut s.filter.moments.blur,
            0.0,
            1.0,
            d.filter.moments.blur,
            "metres from 0 to 1",
        );
        check_f32(
            &mut p,
            "moment_bleed_reduction",
            &mut s.filter.moments.bleed_reduction,
            0.0,
            0.95,
            d.filter.moments.bleed_reduction,
            "a fraction from 0 to 0.95",
        );
        check_f32(
            &mut p,
            "moment_min_variance",
            &mut s.filter.moments.min_variance,
            0.0,
            0.01,
            d.filter.moments.min_variance,
            "square metres from 0 to 0.01",
        );
        s.filter.contact.check(&mut p);
        (s, p)
    }

    /// The problems [`sanitized`](Self::sanitized) would fix; empty when all values are valid.
    pub fn problems(&self) -> Vec<SettingsProblem> {
        self.sanitized().1
    }
}
