//! What a sun's moment shadows (EVSM2, EVSM4, MSM) are made with, per cascade: the technique,
//! the warp exponents (the same warp in metres in every cascade) and the blur radius in texels
//! (the same softness in metres), and the format of the cascades' moments. The bake pass
//! ([`cascade_moments_pass`](super::cascade_moments_pass)) and the packed shadow views read the
//! same values from here, so what is baked is what is tested.

use crate::ecs::frame_lights::{FrameLights, SunView};
use crate::math::evsm::{MomentPrecision, cascade_blur_texels, cascade_exponent};
use crate::math::msm::{MSM_BIAS_16, MSM_BIAS_32};
use crate::render::shadows::gpu::{SHADOW_FILTER_EVSM2, SHADOW_FILTER_EVSM4, SHADOW_FILTER_MSM};
use crate::settings::{MAX_MOMENT_BLUR_TEXELS, ShadowMode};

/// How one cascade's moments are baked and tested.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CascadeMoments {
    /// `SHADOW_FILTER_EVSM2`, `SHADOW_FILTER_EVSM4` or `SHADOW_FILTER_MSM`.
    pub technique: u32,
    /// The positive warp's exponent (EVSM).
    pub c_positive: f32,
    /// The negative warp's exponent (EVSM4).
    pub c_negative: f32,
    /// Radius of the Gaussian pre-blur, texels of this cascade.
    pub blur_texels: f32,
}

/// The precision of `sun`'s moments on a device that does (`fp32_filterable`) or does not
/// filter 32-bit floats.
pub fn sun_precision(sun: &SunView, fp32_filterable: bool) -> MomentPrecision {
    sun.settings.moment_precision.resolve(fp32_filterable)
}

/// The technique code of a sun's settings, if it filters moments.
fn technique(sun: &SunView) -> Option<u32> {
    match sun.settings.mode.effective(true) {
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
    let precision = sun_precision(sun, fp32_filterable);
    let s = &sun.settings;
    let format_max = precision.exponent();
    let max_exponent = if s.evsm_exponent > 0.0 {
        s.evsm_exponent.min(format_max)
    } else {
        format_max
    };
    let deepest = cascades
        .iter()
        .map(|c| c.depth_range)
        .filter(|r| r.is_finite() && *r > 0.0)
        .fold(0.0, f32::max);
    let range = cascade.depth_range;
    Some(CascadeMoments {
        technique,
        c_positive: cascade_exponent(range, deepest, max_exponent),
        c_negative: cascade_exponent(range, deepest, precision.negative_exponent().min(max_exponent)),
        blur_texels: cascade_blur_texels(s.moment_blur, cascade.texel_world_size, MAX_MOMENT_BLUR_TEXELS),
    })
}

/// True when a shadowed sun that filters moments blurs them (the bake then needs its scratch).
pub fn sun_moment_blur(lights: &FrameLights) -> bool {
    lights
        .suns
        .iter()
        .any(|s| s.cascades.count > 0 && technique(s).is_some() && s.settings.moment_blur > 0.0)
}

/// True when MSM moments in `format` are stored quantised: 16-bit channels need the
/// optimised quantisation; 32-bit ones hold the raw moments (the quantisation's own f32
/// round trip would cost more than the 32-bit bias).
pub fn msm_quantised(format: wgpu::TextureFormat) -> bool {
    !matches!(
        format,
        wgpu::TextureFormat::Rg32Float | wgpu::TextureFormat::Rgba32Float
    )
}

/// What the device can store moments in: 32-bit floats it filters (`FLOAT32_FILTERABLE`),
/// and 16-bit unorm (`TEXTURE_FORMAT_16BIT_NORM`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MomentSupport {
    /// 32-bit floats can be filtered.
    pub fp32_filterable: bool,
    /// `Rgba16Unorm` can be sampled and written.
    pub unorm16: bool,
}

/// Mip levels of the cascades' moments in layers of `side` texels: enough for contact
/// hardening's widest filter ([`MOMENT_MIPS`]) while a shadowed sun filters MSM with it, else
/// 1 (EVSM keeps a fixed blur).
pub fn sun_moment_mips(lights: &FrameLights, side: u32) -> u32 {
    let hardening = lights.suns.iter().any(|s| {
        s.cascades.count > 0 && technique(s) == Some(SHADOW_FILTER_MSM) && s.settings.moment_contact_hardening
    });
    if hardening {
        MOMENT_MIPS.min(32 - side.max(1).leading_zeros())
    } else {
        1
    }
}

/// Mip levels of a sun's moments with contact hardening: the last averages 64² texels, the
/// widest penumbra filter (`MAX_PENUMBRA_TEXELS` = 32 texels of radius in the shaders).
pub const MOMENT_MIPS: u32 = 7;

/// MSM's moment bias for moments stored in `format` (what keeps the Hankel matrix
/// invertible after rounding).
pub fn msm_bias(format: wgpu::TextureFormat) -> f32 {
    if msm_quantised(format) {
        MSM_BIAS_16
    } else {
        MSM_BIAS_32
    }
}

/// True when a shadowed sun filters moments this frame (the bake has work).
pub fn any_sun_moments(lights: &FrameLights) -> bool {
    lights
        .suns
        .iter()
        .any(|s| s.cascades.count > 0 && technique(s).is_some())
}

/// The format of the cascades' moments this frame, None while no shadowed sun filters
/// moments: four channels when one uses EVSM4 or MSM, else two; 32-bit floats when one
/// resolves to 32 bits (which needs 32-bit filtering), else 16 bits: `Rgba16Unorm` when every
/// such sun uses MSM and the device has it, else `Rgba16Float` (there is no two-channel
/// 16-bit storage format every device writes). 16-bit MSM without unorm takes 32 bits where
/// they filter: in half floats the quantised moments are too coarse for a receiver lying on a
/// caster (the ground in a far cascade shadows itself; see `tests/sun_moments.rs`).
pub fn cascade_moment_format(lights: &FrameLights, support: MomentSupport) -> Option<wgpu::TextureFormat> {
    let mut any = false;
    let mut four = false;
    let mut fp32 = false;
    let mut all_msm = true;
    for sun in lights.suns.iter().filter(|s| s.cascades.count > 0) {
        let Some(technique) = technique(sun) else {
            continue;
        };
        any = true;
        four |= technique != SHADOW_FILTER_EVSM2;
        all_msm &= technique == SHADOW_FILTER_MSM;
        fp32 |= sun_precision(sun, support.fp32_filterable) == MomentPrecision::Fp32;
    }
    any.then_some(match (four, fp32) {
        (false, true) => wgpu::TextureFormat::Rg32Float,
        (true, true) => wgpu::TextureFormat::Rgba32Float,
        (_, false) if all_msm && support.unorm16 => wgpu::TextureFormat::Rgba16Unorm,
        (_, false) if all_msm && support.fp32_filterable => wgpu::TextureFormat::Rgba32Float,
        (_, false) => wgpu::TextureFormat::Rgba16Float,
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
            settings: ShadowSettings {
                mode,
                moment_precision: precision,
                moment_blur: 0.05,
                ..ShadowSettings::default()
            },
            cascades,
        }
    }

    #[test]
    fn the_warp_and_blur_are_the_same_in_metres_in_every_cascade() {
        let s = sun(ShadowMode::Evsm, MomentFormat::Auto, &[20.0, 40.0, 100.0, 200.0]);
        let m: Vec<_> = (0..4).map(|i| cascade_moments(&s, i, true).unwrap()).collect();
        assert_eq!(m[3].c_positive, 42.0);
        for (i, c) in m.iter().enumerate() {
            let range = s.cascades.cascades[i].depth_range;
            assert!((c.c_positive / range - 42.0 / 200.0).abs() < 1e-6);
            assert!((c.c_negative / range - 10.0 / 200.0).abs() < 1e-6);
            let texel = s.cascades.cascades[i].texel_world_size;
            let metres = c.blur_texels * texel;
            assert!((metres - 0.05).abs() < 1e-6 || c.blur_texels == MAX_MOMENT_BLUR_TEXELS);
        }
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
        assert_eq!(format(&lights, all), Some(wgpu::TextureFormat::Rg32Float));
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
        o.settings.evsm_exponent = 30.0;
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
