//! Shadow settings: every runtime parameter of a light's shadows, with the
//! ranges they are valid in, and the two ways of handling a bad value: reject it (scene files)
//! or clamp it with a warning (values set at run time by code or an inspector).

use bevy_ecs::component::Component;
use serde::{Deserialize, Serialize};

use crate::math::evsm::MomentPrecision;
use crate::math::shadow_memory::MIN_BUDGET_RESOLUTION;

pub use crate::math::cascades::{CascadeFit, MAX_CASCADES};
/// Smallest shadow-map resolution accepted (texels per side): 256, the seed's point-light
/// face size, and the smallest the shadow-memory budget lowers a light to.
pub const MIN_RESOLUTION: u32 = MIN_BUDGET_RESOLUTION;
/// Largest shadow-map resolution accepted (texels per side).
pub const MAX_RESOLUTION: u32 = 4096;
/// Largest PCF kernel radius: 5 gives an 11×11 grid.
pub const MAX_PCF_RADIUS: u32 = 5;
/// Largest fewest-cells count of the grid cascade boxes snap to
/// ([`CascadeSettings::snap_cells`]).
pub const MAX_SNAP_CELLS: u32 = 64;
/// Largest VSM pre-blur radius, texels.
pub const MAX_VSM_BLUR: u32 = 8;
/// Largest blur radius of a sun's moments in any cascade, texels: a `moment_blur` wider than
/// this many of a cascade's texels is cut to it there.
pub const MAX_MOMENT_BLUR_TEXELS: f32 = 8.0;
/// Largest EVSM warp exponent (what 32-bit moments hold).
pub const MAX_EVSM_EXPONENT: f32 = 42.0;

/// How the shadow map is filtered when a receiver samples it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ShadowMode {
    /// Fixed-size percentage-closer filtering on a `(2R+1)²` grid of comparison taps.
    #[default]
    Pcf,
    /// Percentage-closer soft shadows: blocker search, penumbra estimate, variable PCF.
    Pcss,
    /// Variance shadow map (spot and point lights): the first two moments of the distance and
    /// their coverage are pre-filtered once per redrawn map (`vsm_blur`); with
    /// `moment_contact_hardening` (the default) PCSS's blocker search gives each pixel's
    /// penumbra from the light's `radius` and the moments are averaged over it (16 fetches),
    /// else a pixel's shadow is one filtered fetch. Chebyshev's bound then gives the shadow. A sun asked for it uses
    /// [`Evsm`](Self::Evsm), its moment technique.
    Vsm,
    /// Exponentially warped variance shadow map, two moments (EVSM2; suns): each redrawn
    /// cascade's depth is warped `exp(c·d)` and stored as moments `(w, w²)` with their
    /// coverage (empty texels count as lit, so a receiver that casts nothing, such as a ground
    /// with `NotShadowCaster`, keeps its shadow edges); a pixel's shadow is a few filtered
    /// fetches over its penumbra (`moment_contact_hardening`) or one fetch of moments
    /// pre-blurred by `moment_blur`, whatever the penumbra's width. A spot or point light
    /// asked for it uses [`Vsm`](Self::Vsm).
    Evsm,
    /// EVSM4 (suns): the positive and the negative warp, four moments, the smaller of the two
    /// bounds. It stores no coverage: over a receiver that casts nothing, the rims of umbrae
    /// are lit further than with [`Evsm`](Self::Evsm).
    Evsm4,
    /// Moment shadow map (suns; Peters & Klein 2015): four power moments of the depth, stored
    /// with an optimised quantisation, and the Hamburger reconstruction of the occluders'
    /// depth distribution.
    Msm,
}

impl ShadowMode {
    /// The mode a light of this kind is filtered with (`sun`: a directional light): suns have
    /// no plain VSM (it means EVSM2 there), spot and point lights no warped or 4-moment
    /// techniques (they mean VSM there).
    pub fn effective(self, sun: bool) -> ShadowMode {
        match self {
            ShadowMode::Vsm if sun => ShadowMode::Evsm,
            ShadowMode::Evsm | ShadowMode::Evsm4 | ShadowMode::Msm if !sun => ShadowMode::Vsm,
            mode => mode,
        }
    }

    /// True for the techniques that filter pre-blurred moments of a sun's cascades.
    pub fn is_sun_moments(self) -> bool {
        matches!(self, ShadowMode::Evsm | ShadowMode::Evsm4 | ShadowMode::Msm)
    }
}

/// How a sun's moments are stored (EVSM, MSM).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum MomentFormat {
    /// 32-bit floats where the device filters them (`FLOAT32_FILTERABLE`), else 16-bit.
    #[default]
    Auto,
    /// 16-bit floats: half the memory and bandwidth; EVSM's warp exponent is limited to 5.2.
    Fp16,
    /// 32-bit floats (16-bit where the device cannot filter them, with a warning): a warp
    /// exponent up to 42.
    Fp32,
}

impl MomentFormat {
    /// The precision used on a device that does (`fp32_filterable`) or does not filter
    /// 32-bit floats.
    pub fn resolve(self, fp32_filterable: bool) -> MomentPrecision {
        match self {
            MomentFormat::Fp16 => MomentPrecision::Fp16,
            MomentFormat::Auto | MomentFormat::Fp32 if fp32_filterable => MomentPrecision::Fp32,
            MomentFormat::Auto | MomentFormat::Fp32 => MomentPrecision::Fp16,
        }
    }
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

/// A debug visualisation drawn instead of normal shading.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ShadowDebugView {
    /// Normal shading.
    #[default]
    None,
    /// Tint every pixel by the cascade it samples (red, green, blue, yellow for 0..3) — for a
    /// point light, by the cube face (+X red, −X cyan, +Y green, −Y magenta, +Z blue, −Z
    /// yellow). Shown for the renderer's focus light. A paged sun's pixels are tinted by the
    /// level they read, half magenta where the pool overflowed and a coarser level was read,
    /// magenta where no level was resident.
    Cascades,
    /// Show the focus light's contact shadows alone (grey: 1 unoccluded, 0 occluded by the
    /// march); white where none ran.
    Contact,
}

/// Every tunable parameter of a light's shadows, in three parts: the maps themselves
/// ([`map`](Self::map): size, cascades, depth range), the depth bias they are drawn and
/// sampled with ([`bias`](Self::bias)), and how receivers filter them
/// ([`filter`](Self::filter)). Changing the map or the depth bias redraws the light's
/// shadow maps; changing the filter (or the normal offset) redraws none. Attach it to the
/// entity that holds the [`DirectionalLight`](crate::ecs::DirectionalLight),
/// [`SpotLight`](crate::ecs::SpotLight) or [`PointLight`](crate::ecs::PointLight); lights
/// without it use the defaults (positional lights at the
/// [`ShadowLightBudget`](crate::ecs::ShadowLightBudget)'s resolution). Scene files write it
/// flat ([`ShadowSettingsFile`]).
#[derive(Component, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "ShadowSettingsFile", into = "ShadowSettingsFile")]
pub struct ShadowSettings {
    /// The shadow maps: what changes them redraws them.
    pub map: ShadowMapSettings,
    /// Depth bias.
    pub bias: ShadowBias,
    /// How receivers sample the maps.
    pub filter: ShadowFilterSettings,
}

/// What a light's shadow maps are. A change redraws them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowMapSettings {
    /// Side of each map (cascade, spot map or point-light cube face) in texels, 256–4096: what
    /// the light asks for; the shadow-memory budget may grant less (the views carry what was
    /// granted).
    pub resolution: u32,
    /// How a sun's shadow is divided into maps: cascades (`cascades`) or a clipmap.
    pub layout: SunLayout,
    /// A sun's cascades (with [`SunLayout::Cascades`]).
    pub cascades: CascadeSettings,
    /// Distance from the camera (view depth, metres) where a sun's shadows end.
    pub max_distance: f32,
    /// Clamp casters in front of the near plane to it instead of clipping them, where the
    /// adapter supports unclipped depth.
    pub depth_clamp: bool,
}

impl ShadowMapSettings {
    /// How many maps a sun with these settings renders: its cascades or its clipmap levels.
    pub fn sun_views(&self) -> u32 {
        match self.layout {
            SunLayout::Cascades => self.cascades.count,
            SunLayout::Clipmap { levels, .. } | SunLayout::VirtualClipmap { levels, .. } => levels,
        }
    }
}

/// How a sun's view is cut into cascades.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CascadeSettings {
    /// Number of cascades, 1–4.
    pub count: u32,
    /// PSSM split blend: 0 is linear, 1 is logarithmic. Views wider than 120° pull the splits
    /// in towards the logarithmic ones ([`crate::math::splits::wide_view_splits`]).
    pub split_lambda: f32,
    /// How cascades are fitted to the view frustum.
    pub fit: CascadeFit,
    /// Fraction (0–0.5) of each cascade's depth range blended into the next cascade (the
    /// next one starts that much earlier).
    pub blend_width: f32,
    /// Fewest cells per side of the grid each cascade box starts on, 0–64. A cascade holds
    /// still, and its map is not drawn again, while the camera moves within a cell. With 0 a
    /// cell is the texels the box's rounded-up extent leaves spare (no cost in resolution);
    /// N makes cells at least `1 / N` of the box, the box then one cell wider to pay for it
    /// ([`CascadeInput::snap_cells`](crate::math::cascades::CascadeInput::snap_cells)).
    pub snap_cells: u32,
    /// Cascades scroll ([`CascadeSet::scrolls`](crate::math::cascades::CascadeSet::scrolls)):
    /// a cascade whose box moved by whole texels, keeping its size and depth range, keeps
    /// its map and draws only the texels it newly covers, as a clipmap level does (where its
    /// box moved, and where its receiver-bounded cull volume newly reaches). Suns filtering
    /// moments (VSM, EVSM, MSM) do not scroll their cascades.
    pub scroll: bool,
}

/// Depth bias: the hardware's, applied when the maps are drawn (a change redraws them), and
/// the normal offset, applied when they are sampled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowBias {
    /// Hardware slope-scaled depth bias factor, 0–10.
    pub slope_bias: f32,
    /// Largest depth bias the hardware may apply, in reverse-Z NDC depth, 0–0.05.
    pub bias_clamp: f32,
    /// Offset of the sampling position along the surface normal, in shadow texels, 0–5, applied
    /// in full at grazing angles and scaled by `1 − n·l` (a tenth of it where the surface faces
    /// the light), and never more than 2 cm.
    pub normal_offset: f32,
}

/// How receivers sample a light's shadow maps. A change redraws no map (moments are baked
/// again where their parameters changed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowFilterSettings {
    /// Filtering mode.
    pub mode: ShadowMode,
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
    /// Fraction (0–0.5) of `max_distance` over which shadows fade out at the far end.
    pub distance_fade_width: f32,
    /// Debug visualisation.
    pub debug_view: ShadowDebugView,
    /// Variance shadow maps (spot and point lights).
    pub vsm: VsmSettings,
    /// A sun's moment techniques (EVSM2, EVSM4, MSM).
    pub moments: MomentSettings,
    /// Screen-space contact shadows (off by default).
    pub contact: ContactShadows,
}

/// Variance shadow maps (spot and point lights).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VsmSettings {
    /// Radius in texels (0–8) of the separable Gaussian pre-blur of the moments; 0 keeps only
    /// the hardware bilinear filter. Cube faces are blurred across their edges.
    pub blur: u32,
    /// Light-bleed reduction, 0–0.95: the bound's low tail up to this value is clipped to
    /// black and the rest stretched (`clamp((p − amount)/(1 − amount), 0, 1)`).
    pub bleed_reduction: f32,
    /// Smallest variance, as a fraction of the light's range squared, 0–0.01; hides the
    /// moments' quantisation on flat receivers.
    pub min_variance: f32,
}

/// A sun's moment techniques (EVSM2, EVSM4, MSM); `contact_hardening` also applies to VSM.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MomentSettings {
    /// How the moments are stored.
    pub precision: MomentFormat,
    /// EVSM: the warp exponent over the deepest cascade's receivers, 0–42; 0 takes the largest
    /// the format holds (5.2 for 16 bits, 42 for 32). Larger values are cut to the format's
    /// limit; shallower cascades scale it by the depth their receivers span, so the warp is
    /// the same in metres.
    pub evsm_exponent: f32,
    /// Without contact hardening: radius in metres (0–1) of the separable Gaussian pre-blur
    /// of the moments, the same in every cascade (at most 8 of a cascade's texels); 0 keeps
    /// only the bilinear filter. Every pixel then gets this softness, whatever the sun's size.
    pub blur: f32,
    /// Light-bleed reduction, 0–0.95 (as [`VsmSettings::bleed_reduction`]).
    pub bleed_reduction: f32,
    /// Contact hardening (on by default; EVSM, MSM and VSM). PCSS's blocker search over the
    /// depth map gives each pixel's penumbra from the light's size (a sun's angular diameter,
    /// a spot or point light's radius); a sun's moments (unblurred, with a mip chain) are
    /// filtered over it in four fetches, a spot or point light's (pre-blurred by the VSM
    /// blur) averaged over 16; a pixel whose penumbra is under a texel (a caster's foot)
    /// compares the depth itself. Soft shadows that follow the light's size and harden where
    /// casters touch. Off: every pixel filters `blur` (suns) or the VSM blur (spot, point).
    pub contact_hardening: bool,
    /// EVSM: smallest variance of the occluders' depth, square metres, 0–0.01 (scaled by the
    /// warp's slope; the receiver plane's slope across a texel adds to it when
    /// `receiver_plane_bias` is on, which removes most acne without a fixed bias).
    pub min_variance: f32,
}

impl ShadowSettings {
    /// The defaults with maps of `resolution` texels per side.
    pub fn with_resolution(resolution: u32) -> Self {
        let mut settings = ShadowSettings::default();
        settings.map.resolution = resolution;
        settings
    }

    /// What the shadow maps are drawn from (the map settings and the hardware depth bias):
    /// a view's cached map stays valid while this is unchanged.
    pub fn map_key(&self) -> MapKey {
        MapKey {
            map: self.map,
            slope_bias: self.bias.slope_bias,
            bias_clamp: self.bias.bias_clamp,
        }
    }
}

impl Default for ShadowMapSettings {
    fn default() -> Self {
        ShadowSettings::default().map
    }
}

impl Default for CascadeSettings {
    fn default() -> Self {
        ShadowSettings::default().map.cascades
    }
}

impl Default for ShadowBias {
    fn default() -> Self {
        ShadowSettings::default().bias
    }
}

impl Default for ShadowFilterSettings {
    fn default() -> Self {
        ShadowSettings::default().filter
    }
}

impl Default for VsmSettings {
    fn default() -> Self {
        ShadowSettings::default().filter.vsm
    }
}

impl Default for MomentSettings {
    fn default() -> Self {
        ShadowSettings::default().filter.moments
    }
}

/// The part of [`ShadowSettings`] a shadow map is drawn from ([`ShadowSettings::map_key`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapKey {
    /// The map settings.
    pub map: ShadowMapSettings,
    /// Hardware slope-scaled bias.
    pub slope_bias: f32,
    /// Hardware bias clamp.
    pub bias_clamp: f32,
}

mod checks;
mod contact;
mod file;
mod sun_layout;

pub use checks::{SettingsProblem, max_pool_pages};
pub use contact::{ContactShadows, MAX_CONTACT_STEPS};
pub use file::ShadowSettingsFile;
pub use sun_layout::{
    DEFAULT_PAGE_SIZE, DEFAULT_POOL_PAGES, DEFAULT_VIRTUAL_RESOLUTION, MAX_CLIPMAP_LEVELS, SunLayout,
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid() {
        assert!(ShadowSettings::default().problems().is_empty());
    }

    #[test]
    fn bad_values_are_clamped_and_reported() {
        let bad = {
            let mut s = ShadowSettings::default();
            s.map.cascades.count = 0;
            s.map.resolution = 100_000;
            s.map.cascades.split_lambda = f32::NAN;
            s.filter.pcf_radius = 9;
            s
        };
        let (fixed, problems) = bad.sanitized();
        let fields: Vec<_> = problems.iter().map(|p| p.field).collect();
        assert_eq!(fields, ["cascade_count", "resolution", "split_lambda", "pcf_radius"]);
        assert_eq!(fixed.map.cascades.count, 1);
        assert_eq!(fixed.map.resolution, MAX_RESOLUTION);
        assert_eq!(
            fixed.map.cascades.split_lambda,
            ShadowSettings::default().map.cascades.split_lambda
        );
        assert_eq!(fixed.filter.pcf_radius, MAX_PCF_RADIUS);
        assert!(fixed.problems().is_empty());
        assert_eq!(
            problems[0].to_string(),
            "`cascade_count` is 0, expected an integer from 1 to 4"
        );
    }

    #[test]
    fn each_light_kind_maps_the_moment_modes_to_its_own_technique() {
        assert_eq!(ShadowMode::Vsm.effective(true), ShadowMode::Evsm);
        assert_eq!(ShadowMode::Vsm.effective(false), ShadowMode::Vsm);
        for mode in [ShadowMode::Evsm, ShadowMode::Evsm4, ShadowMode::Msm] {
            assert_eq!(mode.effective(true), mode);
            assert_eq!(mode.effective(false), ShadowMode::Vsm);
            assert!(mode.is_sun_moments());
        }
        for mode in [ShadowMode::Pcf, ShadowMode::Pcss] {
            assert_eq!((mode.effective(true), mode.effective(false)), (mode, mode));
            assert!(!mode.is_sun_moments());
        }
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
