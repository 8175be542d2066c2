//! What a sun's moment shadows (EVSM2, EVSM4, MSM) are made with, per cascade: the technique,
//! the depth span the moments cover (the cascade's receivers), the warp exponents (the
//! format's strongest over that span) and the blur radius in texels (the same softness in
//! metres), and the format of the cascades' moments. The bake pass
//! ([`cascade_moments_pass`](super::cascade_moments_pass)) and the packed shadow views read the
//! same values from here, so what is baked is what is tested.

use crate::ecs::light_views::{FrameLights, SunView};
use crate::ecs::view_list::ShadowViews;
use crate::layout::{ShadowStorage, StorageMoments};
use crate::math::cascades::Cascade;
use crate::math::evsm::{MomentPrecision, cascade_blur_texels, cascade_exponent};
use crate::math::msm::{MSM_BIAS_16, MSM_BIAS_32};
use crate::math::shadow_memory::{self, CascadeMomentFormat, hardening_mips};
pub use crate::math::shadow_memory::{MOMENT_MIPS, MomentSupport};
use crate::settings::{MAX_MOMENT_BLUR_TEXELS, ShadowMode};
use crate::shader::contract::{SHADOW_FILTER_EVSM2, SHADOW_FILTER_EVSM4, SHADOW_FILTER_MSM};

/// How one cascade's moments are baked and tested.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CascadeMoments {
    /// `SHADOW_FILTER_EVSM2`, `SHADOW_FILTER_EVSM4` or `SHADOW_FILTER_MSM`.
    pub technique: u32,
    /// The positive warp's exponent (EVSM).
    pub c_positive: f32,
    /// The negative warp's exponent (EVSM4).
    pub c_negative: f32,
    /// Radius of the Gaussian pre-blur, texels of this cascade.
    pub blur_texels: f32,
    /// Where the cascade's receivers start in its depth ([`Cascade::receiver_start`]): the
    /// moments are of `clamp((d − depth_start) / (1 − depth_start), 0, 1)`, so the format's
    /// precision and the warp are spent on the depths receivers can have.
    ///
    /// [`Cascade::receiver_start`]: crate::math::cascades::Cascade::receiver_start
    pub depth_start: f32,
    /// EVSM moments stored in half floats are rounded so their variance is never above the
    /// true one: without contact hardening, rounding to the nearest lit casters' feet (71 %
    /// of their umbra in `tests/sun_moments.rs`); with it a foot compares the depth itself,
    /// and rounding down would only darken penumbrae.
    pub variance_down: bool,
}

/// The precision of `sun`'s moments on a device that does (`fp32_filterable`) or does not
/// filter 32-bit floats.
pub fn sun_precision(sun: &SunView, fp32_filterable: bool) -> MomentPrecision {
    sun.settings.filter.moments.precision.resolve(fp32_filterable)
}

/// The technique code of a sun's settings, if it filters moments.
fn technique(sun: &SunView) -> Option<u32> {
    match sun.settings.filter.mode.effective(true) {
        ShadowMode::Evsm => Some(SHADOW_FILTER_EVSM2),
        ShadowMode::Evsm4 => Some(SHADOW_FILTER_EVSM4),
        ShadowMode::Msm => Some(SHADOW_FILTER_MSM),
        _ => None,
    }
}

/// How cascade `index` of `sun` is baked and tested; None when the sun does not filter
/// moments or has no such cascade.
pub fn cascade_moments(sun: &SunView, index: usize, fp32_filterable: bool) -> Option<CascadeMoments> {
    let technique = technique(sun)?;
    let cascades = sun.cascades.active();
    let cascade = cascades.get(index)?;
    // NOTE: a paged sun's moments cover each level's whole depth, not its receivers' span
    // (which moves with the camera): a page baked in an earlier frame is read with the same
    // parameters as one baked now.
    let paged = sun.paged.is_some();
    let span_of = |c: &Cascade| if paged { c.depth_range } else { receiver_span(c) };
    let precision = sun_precision(sun, fp32_filterable);
    let s = &sun.settings;
    let format_max = precision.exponent();
    let max_exponent = if s.filter.moments.evsm_exponent > 0.0 {
        s.filter.moments.evsm_exponent.min(format_max)
    } else {
        format_max
    };
    // NOTE: the warp is the same in metres in every cascade, with the format's strongest
    // exponent over the deepest receiver span: the spans, not the boxes (which reach up to
    // the scene's casters), so 16-bit moments keep enough warp to shadow contacts.
    let deepest = cascades
        .iter()
        .map(span_of)
        .filter(|r| r.is_finite() && *r > 0.0)
        .fold(0.0, f32::max);
    let span = span_of(cascade);
    Some(CascadeMoments {
        technique,
        c_positive: if s.filter.moments.contact_hardening {
            // NOTE: contact hardening filters the moments over wide penumbrae from coarse mip
            // levels, where a near cascade's weak warp left half floats unable to tell the
            // occluders from the receiver (61-85 % of the field's near umbra lit under a 3°
            // sun): every cascade warps at least as hard as the 16-bit format allows.
            let floor = MomentPrecision::Fp16.exponent().min(max_exponent);
            cascade_exponent(span, deepest, max_exponent).max(floor)
        } else {
            cascade_exponent(span, deepest, max_exponent)
        },
        // NOTE: the negative warp's moments stay within ±1 at any exponent, so every cascade
        // takes the format's: scaled down like the positive one, near cascades' negative warp
        // was almost linear and let a receiver that casts nothing light the rim of umbrae.
        c_negative: precision.negative_exponent().min(max_exponent),
        // NOTE: contact hardening filters the unblurred moments over each pixel's penumbra.
        blur_texels: if s.filter.moments.contact_hardening {
            0.0
        } else {
            cascade_blur_texels(s.filter.moments.blur, cascade.texel_world_size, MAX_MOMENT_BLUR_TEXELS)
        },
        depth_start: if paged {
            0.0
        } else {
            cascade.receiver_start.clamp(0.0, MAX_DEPTH_START)
        },
        variance_down: precision == MomentPrecision::Fp16 && !s.filter.moments.contact_hardening,
    })
}

/// Metres of a cascade's depth its receivers span (what its moments cover).
fn receiver_span(cascade: &Cascade) -> f32 {
    cascade.depth_range * (1.0 - cascade.receiver_start.clamp(0.0, MAX_DEPTH_START))
}

/// Largest [`CascadeMoments::depth_start`]: the receiver span keeps at least a thousandth of
/// the box's depth.
pub const MAX_DEPTH_START: f32 = 0.999;

/// The shadowed suns whose moments the cascade moments pass bakes: those with cascades or
/// a plain clipmap (a paged sun's moments are baked per page).
fn cascade_suns(lights: &FrameLights) -> impl Iterator<Item = &SunView> {
    lights.suns.iter().filter(|s| s.cascades.count > 0 && s.paged.is_none())
}

/// True when a shadowed sun that filters moments blurs them (the bake then needs its scratch).
pub fn sun_moment_blur(lights: &FrameLights) -> bool {
    cascade_suns(lights).any(|s| {
        technique(s).is_some() && !s.settings.filter.moments.contact_hardening && s.settings.filter.moments.blur > 0.0
    })
}

/// True when MSM moments in `format` are stored quantised: 16-bit channels need the
/// optimised quantisation; 32-bit ones hold the raw moments (the quantisation's own f32
/// round trip would cost more than the 32-bit bias).
pub fn msm_quantised(format: wgpu::TextureFormat) -> bool {
    format != wgpu::TextureFormat::Rgba32Float
}

/// Mip levels of the cascades' moments in layers of `side` texels: enough for contact
/// hardening's widest filter ([`MOMENT_MIPS`]) while a shadowed sun filters MSM with it, else
/// 1 (EVSM keeps a fixed blur).
pub fn sun_moment_mips(lights: &FrameLights, side: u32) -> u32 {
    let hardening = cascade_suns(lights).any(|s| technique(s).is_some() && s.settings.filter.moments.contact_hardening);
    if hardening { hardening_mips(side) } else { 1 }
}

/// Mip levels of a paged sun's moments: [`MOMENT_MIPS`] with contact hardening (each page's
/// tile averaged down on its own: a page of 64 texels or more still has a texel at the last),
/// else 1.
pub fn paged_moment_mips(lights: &FrameLights) -> u32 {
    let hardening = lights
        .paged_sun()
        .is_some_and(|s| technique(s).is_some() && s.settings.filter.moments.contact_hardening);
    if hardening { MOMENT_MIPS } else { 1 }
}

/// The sun moments a storage must hold this frame: their format, side, layers, mips, and
/// whether the bake needs a blur scratch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MomentNeed {
    /// The moments' format.
    pub format: wgpu::TextureFormat,
    /// Texels per side.
    pub side: u32,
    /// Layers.
    pub layers: u32,
    /// Mip levels.
    pub mips: u32,
    /// A blur scratch.
    pub blur: bool,
}

/// What `storage`'s sun moments must hold this frame (None while none of its suns filters
/// moments, or for a storage of VSM or no moments): the cascades' a layer per view with a
/// blur scratch and mips for contact hardening; a paged sun's laid out as its pool's atlas
/// (`pool_side` texels a side), one layer, no scratch, mips for contact hardening.
pub fn sun_moment_need(
    storage: ShadowStorage,
    lights: &FrameLights,
    views: &ShadowViews,
    pool_side: Option<u32>,
    support: MomentSupport,
) -> Option<MomentNeed> {
    match storage.desc().moments {
        StorageMoments::Baked => {
            let (side, layers) = views.extent(storage);
            Some(MomentNeed {
                format: cascade_moment_format(lights, support)?,
                side,
                layers,
                mips: sun_moment_mips(lights, side),
                blur: sun_moment_blur(lights),
            })
        }
        StorageMoments::Paged => Some(MomentNeed {
            format: paged_moment_format(lights, support)?,
            side: pool_side?,
            layers: 1,
            mips: paged_moment_mips(lights),
            blur: false,
        }),
        StorageMoments::Vsm | StorageMoments::None => None,
    }
}

/// MSM's moment bias for moments stored in `format` (what keeps the Hankel matrix
/// invertible after rounding).
pub fn msm_bias(format: wgpu::TextureFormat) -> f32 {
    if msm_quantised(format) {
        MSM_BIAS_16
    } else {
        MSM_BIAS_32
    }
}

/// True when a shadowed sun with cascades (or a plain clipmap) filters moments this frame
/// (the cascade moments pass has work).
pub fn any_sun_moments(lights: &FrameLights) -> bool {
    cascade_suns(lights).any(|s| technique(s).is_some())
}

/// The format of the cascades' moments this frame, None while no shadowed sun with cascades
/// (or a plain clipmap) filters moments.
pub fn cascade_moment_format(lights: &FrameLights, support: MomentSupport) -> Option<wgpu::TextureFormat> {
    moment_format(cascade_suns(lights), support)
}

/// The format of the paged sun's moments this frame, None without a paged sun that filters
/// moments.
pub fn paged_moment_format(lights: &FrameLights, support: MomentSupport) -> Option<wgpu::TextureFormat> {
    moment_format(lights.paged_sun().into_iter(), support)
}

/// The format that holds the moments of `suns` ([`shadow_memory::cascade_moment_format`]),
/// None while none of them filters moments.
fn moment_format<'a>(suns: impl Iterator<Item = &'a SunView>, support: MomentSupport) -> Option<wgpu::TextureFormat> {
    let suns = suns.filter_map(|sun| {
        let technique = technique(sun)?;
        let fp32 = sun_precision(sun, support.fp32_filterable) == MomentPrecision::Fp32;
        Some((technique == SHADOW_FILTER_MSM, fp32))
    });
    shadow_memory::cascade_moment_format(suns, support).map(|format| match format {
        CascadeMomentFormat::Rgba32Float => wgpu::TextureFormat::Rgba32Float,
        CascadeMomentFormat::Rgba16Unorm => wgpu::TextureFormat::Rgba16Unorm,
        CascadeMomentFormat::Rgba16Float => wgpu::TextureFormat::Rgba16Float,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ecs::DirectionalLight;
    use crate::math::cascades::CascadeSet;
    use crate::settings::{MomentFormat, ShadowSettings};
    use bevy_ecs::entity::Entity;
    use glam::Vec3;

    fn sun(mode: ShadowMode, precision: MomentFormat, ranges: &[f32]) -> SunView {
        let mut cascades = CascadeSet {
            count: ranges.len(),
            ..CascadeSet::default()
        };
        for (c, &r) in cascades.cascades.iter_mut().zip(ranges) {
            c.depth_range = r;
            c.texel_world_size = r / 4000.0;
        }
        SunView {
            entity: Entity::PLACEHOLDER,
            direction: Vec3::NEG_Y,
            light: DirectionalLight::default(),
            settings: {
                let mut s = ShadowSettings::default();
                s.filter.mode = mode;
                s.filter.moments.precision = precision;
                s.filter.moments.blur = 0.05;
                s
            },
            resolution: 2048,
            cascades,
            clipmap: Default::default(),
            paged: None,
        }
    }

    #[test]
    fn the_positive_warp_and_the_blur_are_the_same_in_metres_over_every_receiver_span() {
        let mut s = sun(ShadowMode::Evsm, MomentFormat::Auto, &[20.0, 40.0, 100.0, 400.0]);
        s.settings.filter.moments.contact_hardening = false;
        for (c, start) in s.cascades.cascades.iter_mut().zip([0.5, 0.25, 0.0, 0.5]) {
            c.receiver_start = start;
        }
        // Receiver spans: 10, 30, 100 and 200 m.
        let spans = [10.0, 30.0, 100.0, 200.0];
        let m: Vec<_> = (0..4).map(|i| cascade_moments(&s, i, true).unwrap()).collect();
        assert_eq!(m[3].c_positive, 42.0);
        for (i, c) in m.iter().enumerate() {
            assert!((c.c_positive / spans[i] - 42.0 / 200.0).abs() < 1e-6, "{c:?}");
            // The negative warp's moments stay within ±1: the format's exponent everywhere.
            assert_eq!(c.c_negative, 10.0);
            let texel = s.cascades.cascades[i].texel_world_size;
            let metres = c.blur_texels * texel;
            assert!((metres - 0.05).abs() < 1e-6 || c.blur_texels == MAX_MOMENT_BLUR_TEXELS);
        }
        let starts: Vec<f32> = m.iter().map(|c| c.depth_start).collect();
        assert_eq!(starts, [0.5, 0.25, 0.0, 0.5]);
        // Contact hardening filters unblurred moments; a fixed blur in 16 bits rounds the
        // variance down.
        assert!(m.iter().all(|c| !c.variance_down));
        s.settings.filter.moments.precision = MomentFormat::Fp16;
        assert!(cascade_moments(&s, 0, true).unwrap().variance_down);
        s.settings.filter.moments.contact_hardening = true;
        let hardened = cascade_moments(&s, 0, true).unwrap();
        assert_eq!((hardened.blur_texels, hardened.variance_down), (0.0, false));
        // A span that vanishes keeps a thousandth of its box.
        s.cascades.cascades[0].receiver_start = 1.0;
        assert_eq!(cascade_moments(&s, 0, true).unwrap().depth_start, MAX_DEPTH_START);
        assert_eq!(cascade_moments(&s, 4, true), None);
    }

    #[test]
    fn the_precision_bounds_the_exponent_and_picks_the_format() {
        // No 32-bit filtering: Auto and Fp32 fall back to 16 bits and their exponent.
        let s = sun(ShadowMode::Evsm, MomentFormat::Fp32, &[100.0]);
        assert!((cascade_moments(&s, 0, false).unwrap().c_positive - 5.2).abs() < 0.05);
        let mut lights = FrameLights::default();
        lights.suns.push(s);
        let all = MomentSupport {
            fp32_filterable: true,
            unorm16: true,
        };
        let fp16 = MomentSupport {
            fp32_filterable: false,
            unorm16: true,
        };
        let format = |lights: &FrameLights, support| cascade_moment_format(lights, support);
        assert_eq!(format(&lights, all), Some(wgpu::TextureFormat::Rgba32Float));
        assert_eq!(format(&lights, fp16), Some(wgpu::TextureFormat::Rgba16Float));
        lights.suns.push(sun(ShadowMode::Msm, MomentFormat::Auto, &[100.0]));
        assert_eq!(format(&lights, all), Some(wgpu::TextureFormat::Rgba32Float));
        // 16-bit MSM alone takes unorm where the device has it, else half floats.
        lights.suns = vec![sun(ShadowMode::Msm, MomentFormat::Fp16, &[100.0])];
        assert_eq!(format(&lights, all), Some(wgpu::TextureFormat::Rgba16Unorm));
        let no_unorm = MomentSupport { unorm16: false, ..all };
        assert_eq!(format(&lights, no_unorm), Some(wgpu::TextureFormat::Rgba32Float));
        let half_only = MomentSupport::default();
        assert_eq!(format(&lights, half_only), Some(wgpu::TextureFormat::Rgba16Float));
        // An exponent override is cut to the format's limit.
        let mut o = sun(ShadowMode::Evsm4, MomentFormat::Fp16, &[100.0]);
        o.settings.filter.moments.evsm_exponent = 30.0;
        assert!((cascade_moments(&o, 0, true).unwrap().c_positive - 5.2).abs() < 0.05);
        assert_eq!(msm_bias(wgpu::TextureFormat::Rgba16Float), MSM_BIAS_16);
        assert_eq!(msm_bias(wgpu::TextureFormat::Rgba32Float), MSM_BIAS_32);
        // PCF and PCSS suns have none.
        lights.suns = vec![sun(ShadowMode::Pcss, MomentFormat::Auto, &[100.0])];
        assert_eq!(format(&lights, all), None);
        assert_eq!(cascade_moments(&lights.suns[0], 0, true), None);
        // A sun asked for VSM gets EVSM2.
        let v = sun(ShadowMode::Vsm, MomentFormat::Auto, &[100.0]);
        assert_eq!(cascade_moments(&v, 0, true).unwrap().technique, SHADOW_FILTER_EVSM2);
    }
}
