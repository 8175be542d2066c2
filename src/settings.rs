//! Shadow settings: every runtime parameter of a light's shadows, with the
//! ranges they are valid in, and the two ways of handling a bad value: reject it (scene files)
//! or clamp it with a warning (values set at run time by code or an inspector).

use std::fmt;

use bevy_ecs::component::Component;
use serde::{Deserialize, Serialize};

/// The most cascades a directional light can have.
pub const MAX_CASCADES: usize = 4;
/// Smallest shadow-map resolution accepted (texels per side): 256, the seed's point-light
/// face size.
pub const MIN_RESOLUTION: u32 = 256;
/// Largest shadow-map resolution accepted (texels per side).
pub const MAX_RESOLUTION: u32 = 4096;
/// Largest PCF kernel radius: 5 gives an 11×11 grid.
pub const MAX_PCF_RADIUS: u32 = 5;
/// Largest VSM pre-blur radius, texels.
pub const MAX_VSM_BLUR: u32 = 8;

/// How the shadow map is filtered when a receiver samples it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ShadowMode {
    /// Fixed-size percentage-closer filtering on a `(2R+1)²` grid of comparison taps.
    #[default]
    Pcf,
    /// Percentage-closer soft shadows: blocker search, penumbra estimate, variable PCF.
    Pcss,
    /// Variance shadow map (spot and point lights): the first two moments of the depth are
    /// pre-filtered once per redrawn map (`vsm_blur`), and a pixel's shadow is one filtered
    /// fetch and Chebyshev's bound, whatever the penumbra width. A sun asked for it is
    /// filtered with PCF (its moment technique is EVSM, to come).
    Vsm,
}

/// Sample counts for PCSS (blocker search taps / filter taps).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum PcssQuality {
    /// 16 blocker taps, 16 filter taps.
    Low,
    /// 16 blocker taps, 25 filter taps.
    #[default]
    Medium,
    /// 32 blocker taps, 49 filter taps.
    High,
}

impl PcssQuality {
    /// Number of Poisson taps used by the blocker search.
    pub fn blocker_samples(self) -> u32 {
        match self {
            PcssQuality::Low | PcssQuality::Medium => 16,
            PcssQuality::High => 32,
        }
    }

    /// Number of Poisson taps used by the variable-width filter.
    pub fn filter_samples(self) -> u32 {
        match self {
            PcssQuality::Low => 16,
            PcssQuality::Medium => 25,
            PcssQuality::High => 49,
        }
    }
}

/// How each cascade's orthographic box is fitted to its slice of the view frustum.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum CascadeFit {
    /// XY fitted tightly to the slice corners in light space: the most texels on screen,
    /// but the box changes size as the camera turns.
    #[default]
    Tight,
    /// A sphere around the camera position that reaches the slice's farthest corner: a few
    /// texels are wasted behind the camera, but turning in place never changes the cascades.
    Stable,
}

/// A debug visualisation drawn instead of normal shading.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ShadowDebugView {
    /// Normal shading.
    #[default]
    None,
    /// Tint every pixel by the cascade it samples (red, green, blue, yellow for 0..3) — for a
    /// point light, by the cube face (+X red, −X cyan, +Y green, −Y magenta, +Z blue, −Z
    /// yellow). Shown for the renderer's focus light.
    Cascades,
}

/// Every tunable parameter of a light's shadows. Attach it to the entity that holds the
/// [`DirectionalLight`](crate::ecs::DirectionalLight), [`SpotLight`](crate::ecs::SpotLight) or
/// [`PointLight`](crate::ecs::PointLight); lights without it use the defaults (positional
/// lights at the [`ShadowLightBudget`](crate::ecs::ShadowLightBudget)'s resolution). The
/// cascade fields only apply to suns, the `vsm_*` fields only to spot and point lights.
#[derive(Component, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ShadowSettings {
    /// Filtering mode (PCF or PCSS).
    pub mode: ShadowMode,
    /// Number of cascades, 1–4.
    pub cascade_count: u32,
    /// Shadow-map resolution per cascade (or spot map, or point-light cube face) in texels,
    /// 256–4096.
    pub resolution: u32,
    /// PSSM split blend: 0 is linear, 1 is logarithmic. Views wider than 120° pull the splits
    /// in towards the logarithmic ones ([`crate::math::splits::wide_view_splits`]).
    pub split_lambda: f32,
    /// Distance from the camera (view depth, metres) where shadows end.
    pub max_distance: f32,
    /// How cascades are fitted to the view frustum.
    pub fit: CascadeFit,
    /// Hardware slope-scaled depth bias factor, 0–10.
    pub slope_bias: f32,
    /// Largest depth bias the hardware may apply, in reverse-Z NDC depth, 0–0.05.
    pub bias_clamp: f32,
    /// Offset of the sampling position along the surface normal, in shadow texels, 0–5, applied
    /// in full at grazing angles and scaled by `1 − n·l` (a tenth of it where the surface faces
    /// the light), and never more than 2 cm.
    pub normal_offset: f32,
    /// PCF kernel radius, 0 (a single hardware comparison) to 5 (11×11); taps are one texel
    /// apart, or 1 cm where a texel is larger.
    pub pcf_radius: u32,
    /// PCSS sample counts.
    pub pcss_quality: PcssQuality,
    /// PCSS: return fully shadowed when every blocker tap finds an occluder.
    pub blocker_early_out: bool,
    /// PCSS: tilt each tap's comparison depth along the receiver plane.
    pub receiver_plane_bias: bool,
    /// PCSS: rotate the Poisson pattern per pixel and per frame.
    pub temporal_rotation: bool,
    /// Fraction (0–0.5) of each cascade's depth range blended into the next cascade.
    pub blend_width: f32,
    /// Fraction (0–0.5) of `max_distance` over which shadows fade out at the far end.
    pub distance_fade_width: f32,
    /// Clamp casters in front of the near plane to it instead of clipping them, where the
    /// adapter supports unclipped depth.
    pub depth_clamp: bool,
    /// Debug visualisation.
    pub debug_view: ShadowDebugView,
    /// VSM: radius in texels (0–8) of the separable Gaussian pre-blur of the moments; 0
    /// keeps only the hardware bilinear filter. Cube faces are blurred across their edges.
    pub vsm_blur: u32,
    /// VSM: light-bleed reduction, 0–0.95: the bound's low tail up to this value is clipped
    /// to black and the rest stretched (`clamp((p − amount)/(1 − amount), 0, 1)`).
    pub vsm_bleed_reduction: f32,
    /// VSM: smallest variance, as a fraction of the light's range squared, 0–0.01; hides the
    /// moments' quantisation on flat receivers.
    pub vsm_min_variance: f32,
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            mode: ShadowMode::Pcf,
            cascade_count: 4,
            resolution: 2048,
            split_lambda: 0.6,
            max_distance: 120.0,
            fit: CascadeFit::Tight,
            slope_bias: 4.0,
            bias_clamp: 0.005,
            normal_offset: 1.0,
            pcf_radius: 1,
            pcss_quality: PcssQuality::Medium,
            blocker_early_out: true,
            receiver_plane_bias: true,
            temporal_rotation: true,
            blend_width: 0.1,
            distance_fade_width: 0.1,
            depth_clamp: true,
            debug_view: ShadowDebugView::None,
            vsm_blur: 2,
            vsm_bleed_reduction: 0.3,
            vsm_min_variance: 1e-6,
        }
    }
}

/// One out-of-range value found in a [`ShadowSettings`].
#[derive(Clone, Debug, PartialEq)]
pub struct SettingsProblem {
    /// Field name, as written in a scene file.
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
fn check_f32(
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
fn check_u32(
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
            &mut s.cascade_count,
            1,
            MAX_CASCADES as u32,
            "an integer from 1 to 4",
        );
        check_u32(
            &mut p,
            "resolution",
            &mut s.resolution,
            MIN_RESOLUTION,
            MAX_RESOLUTION,
            "texels per side from 256 to 4096",
        );
        check_f32(
            &mut p,
            "split_lambda",
            &mut s.split_lambda,
            0.0,
            1.0,
            d.split_lambda,
            "a number from 0 (linear) to 1 (logarithmic)",
        );
        check_f32(
            &mut p,
            "max_distance",
            &mut s.max_distance,
            0.1,
            1.0e6,
            d.max_distance,
            "metres from 0.1 to 1e6",
        );
        check_f32(
            &mut p,
            "slope_bias",
            &mut s.slope_bias,
            0.0,
            10.0,
            d.slope_bias,
            "a number from 0 to 10",
        );
        check_f32(
            &mut p,
            "bias_clamp",
            &mut s.bias_clamp,
            0.0,
            0.05,
            d.bias_clamp,
            "a number from 0 to 0.05",
        );
        check_f32(
            &mut p,
            "normal_offset",
            &mut s.normal_offset,
            0.0,
            5.0,
            d.normal_offset,
            "shadow texels from 0 to 5",
        );
        check_u32(
            &mut p,
            "pcf_radius",
            &mut s.pcf_radius,
            0,
            MAX_PCF_RADIUS,
            "an integer from 0 to 5",
        );
        check_f32(
            &mut p,
            "blend_width",
            &mut s.blend_width,
            0.0,
            0.5,
            d.blend_width,
            "a fraction from 0 to 0.5",
        );
        check_f32(
            &mut p,
            "distance_fade_width",
            &mut s.distance_fade_width,
            0.0,
            0.5,
            d.distance_fade_width,
            "a fraction from 0 to 0.5",
        );
        check_u32(
            &mut p,
            "vsm_blur",
            &mut s.vsm_blur,
            0,
            MAX_VSM_BLUR,
            "texels from 0 to 8",
        );
        check_f32(
            &mut p,
            "vsm_bleed_reduction",
            &mut s.vsm_bleed_reduction,
            0.0,
            0.95,
            d.vsm_bleed_reduction,
            "a fraction from 0 to 0.95",
        );
        check_f32(
            &mut p,
            "vsm_min_variance",
            &mut s.vsm_min_variance,
            0.0,
            0.01,
            d.vsm_min_variance,
            "a fraction of the range squared from 0 to 0.01",
        );
        (s, p)
    }

    /// The problems [`sanitized`](Self::sanitized) would fix; empty when all values are valid.
    pub fn problems(&self) -> Vec<SettingsProblem> {
        self.sanitized().1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid() {
        assert!(ShadowSettings::default().problems().is_empty());
    }

    #[test]
    fn bad_values_are_clamped_and_reported() {
        let bad = ShadowSettings {
            cascade_count: 0,
            resolution: 100_000,
            split_lambda: f32::NAN,
            pcf_radius: 9,
            ..ShadowSettings::default()
        };
        let (fixed, problems) = bad.sanitized();
        let fields: Vec<_> = problems.iter().map(|p| p.field).collect();
        assert_eq!(fields, ["cascade_count", "resolution", "split_lambda", "pcf_radius"]);
        assert_eq!(fixed.cascade_count, 1);
        assert_eq!(fixed.resolution, MAX_RESOLUTION);
        assert_eq!(fixed.split_lambda, ShadowSettings::default().split_lambda);
        assert_eq!(fixed.pcf_radius, MAX_PCF_RADIUS);
        assert!(fixed.problems().is_empty());
        assert_eq!(
            problems[0].to_string(),
            "`cascade_count` is 0, expected an integer from 1 to 4"
        );
    }

    #[test]
    fn pcss_sample_counts_follow_the_quality_table() {
        let counts: Vec<_> = [PcssQuality::Low, PcssQuality::Medium, PcssQuality::High]
            .iter()
            .map(|q| (q.blocker_samples(), q.filter_samples()))
            .collect();
        assert_eq!(counts, [(16, 16), (16, 25), (32, 49)]);
    }
}
