//! The flat form of [`ShadowSettings`] that scene files and the CLI's JSON write: every field
//! at one level, named as before the settings were split into map, bias and filter, so the
//! files written before still read the same. [`ShadowSettings`] (de)serialises through it.

use serde::{Deserialize, Serialize};

use crate::settings::{
    CascadeFit, CascadeSettings, ContactShadows, MomentFormat, MomentSettings, PcssQuality, ShadowBias,
    ShadowDebugView, ShadowFilterSettings, ShadowMapSettings, ShadowMode, ShadowSettings, SunLayout, VsmSettings,
};

/// [`ShadowSettings`] as a scene file writes it: one level of fields (each documented on the
/// field of [`ShadowSettings`] it becomes), any of them left out taking its default.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields, rename = "ShadowSettings")]
pub struct ShadowSettingsFile {
    /// Filtering mode.
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
    /// Fewest cells per side of the grid each cascade box starts on, 0–64 (0: cells of the
    /// texels its rounded-up extent leaves spare): a moving camera redraws a cascade only when
    /// its box crosses a cell.
    pub cascade_snap_cells: u32,
    /// Cascades whose box moved by whole texels keep their map and draw only the texels they
    /// newly cover (not with moment filters).
    pub cascade_scroll: bool,
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
    /// EVSM, MSM: how the moments are stored.
    pub moment_precision: MomentFormat,
    /// EVSM: the warp exponent over the deepest cascade's receivers, 0–42; 0 takes the largest
    /// the format holds (5.2 for 16 bits, 42 for 32). Larger values are cut to the format's
    /// limit; shallower cascades scale it by the depth their receivers span, so the warp is
    /// the same in metres.
    pub evsm_exponent: f32,
    /// EVSM, MSM without contact hardening: radius in metres (0–1) of the separable Gaussian
    /// pre-blur of the moments, the same in every cascade (at most 8 of a cascade's texels);
    /// 0 keeps only the bilinear filter. Every pixel then gets this softness, whatever the
    /// sun's size.
    pub moment_blur: f32,
    /// EVSM, MSM: light-bleed reduction, 0–0.95 (as `vsm_bleed_reduction`).
    pub moment_bleed_reduction: f32,
    /// EVSM, MSM, VSM: contact hardening (on by default). PCSS's blocker search over the
    /// depth map gives each pixel's penumbra from the light's size (a sun's angular diameter,
    /// a spot or point light's radius); a sun's moments (unblurred, with a mip chain) are
    /// filtered over it in four fetches, a spot or point light's (pre-blurred by `vsm_blur`)
    /// averaged over 16; a pixel whose penumbra is under a texel (a caster's foot) compares
    /// the depth itself. Soft shadows that follow the light's size and harden where casters
    /// touch. Off: every pixel filters `moment_blur` (suns) or `vsm_blur` (spot, point).
    pub moment_contact_hardening: bool,
    /// EVSM: smallest variance of the occluders' depth, square metres, 0–0.01 (scaled by the
    /// warp's slope; the receiver plane's slope across a texel adds to it when
    /// `receiver_plane_bias` is on, which removes most acne without a fixed bias).
    pub moment_min_variance: f32,
    /// A sun's layout: `Cascades` (the default), `Clipmap(levels: 6, level0_extent: 32.0)` or
    /// `VirtualClipmap(levels: 6, level0_extent: 32.0, virtual_resolution: 16384, page_size: 128,
    /// pool_pages: 2048)` (experimental).
    pub layout: SunLayout,
    /// Screen-space contact shadows, `(length: 0.3, steps: 16, thickness: 0.1, intensity: 1.0)`
    /// (off while `steps` is 0, the default).
    pub contact_shadows: ContactShadows,
}

impl Default for ShadowSettingsFile {
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
            cascade_snap_cells: 0,
            cascade_scroll: true,
            distance_fade_width: 0.1,
            depth_clamp: true,
            debug_view: ShadowDebugView::None,
            vsm_blur: 2,
            vsm_bleed_reduction: 0.3,
            vsm_min_variance: 1e-6,
            moment_precision: MomentFormat::Auto,
            evsm_exponent: 0.0,
            moment_blur: 0.03,
            moment_bleed_reduction: 0.15,
            moment_contact_hardening: true,
            moment_min_variance: 1e-5,
            layout: SunLayout::Cascades,
            contact_shadows: ContactShadows::OFF,
        }
    }
}

impl From<ShadowSettingsFile> for ShadowSettings {
    fn from(f: ShadowSettingsFile) -> Self {
        ShadowSettings {
            map: ShadowMapSettings {
                layout: f.layout,
                resolution: f.resolution,
                cascades: CascadeSettings {
                    count: f.cascade_count,
                    split_lambda: f.split_lambda,
                    fit: f.fit,
                    blend_width: f.blend_width,
                    snap_cells: f.cascade_snap_cells,
                    scroll: f.cascade_scroll,
                },
                max_distance: f.max_distance,
                depth_clamp: f.depth_clamp,
            },
            bias: ShadowBias {
                slope_bias: f.slope_bias,
                bias_clamp: f.bias_clamp,
                normal_offset: f.normal_offset,
            },
            filter: ShadowFilterSettings {
                mode: f.mode,
                pcf_radius: f.pcf_radius,
                pcss_quality: f.pcss_quality,
                blocker_early_out: f.blocker_early_out,
                receiver_plane_bias: f.receiver_plane_bias,
                temporal_rotation: f.temporal_rotation,
                distance_fade_width: f.distance_fade_width,
                debug_view: f.debug_view,
                vsm: VsmSettings {
                    blur: f.vsm_blur,
                    bleed_reduction: f.vsm_bleed_reduction,
                    min_variance: f.vsm_min_variance,
                },
                moments: MomentSettings {
                    precision: f.moment_precision,
                    evsm_exponent: f.evsm_exponent,
                    blur: f.moment_blur,
                    bleed_reduction: f.moment_bleed_reduction,
                    contact_hardening: f.moment_contact_hardening,
                    min_variance: f.moment_min_variance,
                },
                contact: f.contact_shadows,
            },
        }
    }
}

impl From<ShadowSettings> for ShadowSettingsFile {
    fn from(s: ShadowSettings) -> Self {
        let (map, bias, filter) = (s.map, s.bias, s.filter);
        ShadowSettingsFile {
            mode: filter.mode,
            layout: map.layout,
            cascade_count: map.cascades.count,
            resolution: map.resolution,
            split_lambda: map.cascades.split_lambda,
            max_distance: map.max_distance,
            fit: map.cascades.fit,
            slope_bias: bias.slope_bias,
            bias_clamp: bias.bias_clamp,
            normal_offset: bias.normal_offset,
            pcf_radius: filter.pcf_radius,
            pcss_quality: filter.pcss_quality,
            blocker_early_out: filter.blocker_early_out,
            receiver_plane_bias: filter.receiver_plane_bias,
            temporal_rotation: filter.temporal_rotation,
            blend_width: map.cascades.blend_width,
            cascade_snap_cells: map.cascades.snap_cells,
            cascade_scroll: map.cascades.scroll,
            distance_fade_width: filter.distance_fade_width,
            depth_clamp: map.depth_clamp,
            debug_view: filter.debug_view,
            vsm_blur: filter.vsm.blur,
            vsm_bleed_reduction: filter.vsm.bleed_reduction,
            vsm_min_variance: filter.vsm.min_variance,
            moment_precision: filter.moments.precision,
            evsm_exponent: filter.moments.evsm_exponent,
            moment_blur: filter.moments.blur,
            moment_bleed_reduction: filter.moments.bleed_reduction,
            moment_contact_hardening: filter.moments.contact_hardening,
            moment_min_variance: filter.moments.min_variance,
            contact_shadows: filter.contact,
        }
    }
}

impl Default for ShadowSettings {
    fn default() -> Self {
        ShadowSettingsFile::default().into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_flat_form_round_trips_every_field() {
        let flat = ShadowSettingsFile {
            cascade_count: 3,
            resolution: 1024,
            slope_bias: 2.5,
            pcf_radius: 3,
            vsm_blur: 5,
            cascade_snap_cells: 16,
            moment_min_variance: 2e-4,
            ..Default::default()
        };
        let nested = ShadowSettings::from(flat);
        assert_eq!(nested.map.cascades.count, 3);
        assert_eq!(nested.bias.slope_bias, 2.5);
        assert_eq!(nested.filter.vsm.blur, 5);
        assert_eq!(nested.map.cascades.snap_cells, 16);
        assert_eq!(ShadowSettingsFile::from(nested), flat);
    }

    #[test]
    fn a_file_written_before_the_split_reads_into_the_parts() {
        let text = "(mode: Evsm, cascade_count: 3, fit: Stable, slope_bias: 2.0, normal_offset: 0.5, \
                    pcf_radius: 2, blend_width: 0.2, vsm_blur: 4, moment_blur: 0.1, moment_precision: Fp16)";
        let s: ShadowSettings = ron::from_str(text).unwrap();
        assert_eq!((s.filter.mode, s.map.cascades.count), (ShadowMode::Evsm, 3));
        assert_eq!(
            (s.map.cascades.fit, s.map.cascades.blend_width),
            (CascadeFit::Stable, 0.2)
        );
        assert_eq!((s.bias.slope_bias, s.bias.normal_offset), (2.0, 0.5));
        assert_eq!((s.filter.pcf_radius, s.filter.vsm.blur), (2, 4));
        assert_eq!(
            (s.filter.moments.blur, s.filter.moments.precision),
            (0.1, MomentFormat::Fp16)
        );
        let back: ShadowSettings = ron::from_str(&ron::to_string(&s).unwrap()).unwrap();
        assert_eq!(back, s);
        let unknown = ron::from_str::<ShadowSettings>("(pcf_radious: 2)").unwrap_err();
        assert!(unknown.to_string().contains("pcf_radious"), "{unknown}");
    }
}
