//! The presets the benchmark scores: each a small change on top of the scored light's own
//! settings. Every preset runs on every scene; those that only change cascade blending render
//! a spot or point light (nothing to blend) as their base preset does; the VSM presets render
//! a sun with EVSM2 and the EVSM and MSM presets render spot and point lights with VSM (each
//! kind's own moment technique, [`ShadowMode::effective`]).

use crate::settings::{ContactShadows, MomentFormat, PcssQuality, ShadowMode, ShadowSettings, SunLayout};

/// One named configuration of the shadow filter.
#[derive(Clone, Copy, Debug)]
pub struct Preset {
    /// Short name used in reports and on the plot.
    pub name: &'static str,
    /// What it is, in a few words.
    pub description: &'static str,
    /// Applies the preset on top of the scene's settings.
    pub apply: fn(&mut ShadowSettings),
}

fn pcf(s: &mut ShadowSettings, radius: u32) {
    s.filter.mode = ShadowMode::Pcf;
    s.filter.pcf_radius = radius;
}

fn pcss(s: &mut ShadowSettings, quality: PcssQuality) {
    s.filter.mode = ShadowMode::Pcss;
    s.filter.pcss_quality = quality;
}

fn vsm(s: &mut ShadowSettings, blur: u32) {
    s.filter.mode = ShadowMode::Vsm;
    s.filter.vsm.blur = blur;
}

fn moments(s: &mut ShadowSettings, mode: ShadowMode, precision: MomentFormat) {
    s.filter.mode = mode;
    s.filter.moments.precision = precision;
}

/// Every preset: hard shadows, PCF radius 1–5, PCSS Low/Medium/High, receiver-plane bias and
/// cascade blending switched off on the mid presets, VSM with contact hardening (the default)
/// without and with pre-blur and VSM with a fixed blur, the suns' EVSM2 (16 and 32 bits),
/// EVSM4 and MSM (16 and 32 bits) with contact hardening, and EVSM2 and MSM with a fixed blur
/// instead; PCF 3×3, PCSS Medium and 32-bit EVSM2 with contact shadows; and a sun's clipmap
/// with PCF, PCSS and EVSM2.
pub fn presets() -> Vec<Preset> {
    vec![
        Preset {
            name: "hard",
            description: "PCF radius 0: one hardware 2×2 comparison",
            apply: |s| pcf(s, 0),
        },
        Preset {
            name: "pcf1",
            description: "PCF 3×3",
            apply: |s| pcf(s, 1),
        },
        Preset {
            name: "pcf2",
            description: "PCF 5×5",
            apply: |s| pcf(s, 2),
        },
        Preset {
            name: "pcf3",
            description: "PCF 7×7",
            apply: |s| pcf(s, 3),
        },
        Preset {
            name: "pcf4",
            description: "PCF 9×9",
            apply: |s| pcf(s, 4),
        },
        Preset {
            name: "pcf5",
            description: "PCF 11×11",
            apply: |s| pcf(s, 5),
        },
        Preset {
            name: "pcf2-no-rpb",
            description: "PCF 5×5 without receiver-plane bias",
            apply: |s| {
                pcf(s, 2);
                s.filter.receiver_plane_bias = false;
            },
        },
        Preset {
            name: "pcf2-no-blend",
            description: "PCF 5×5 without cascade blending",
            apply: |s| {
                pcf(s, 2);
                s.map.cascades.blend_width = 0.0;
            },
        },
        Preset {
            name: "pcf1-contact",
            description: "PCF 3×3 with contact shadows (the light's own, else 16 steps over 0.3 m)",
            apply: |s| {
                pcf(s, 1);
                contact(s);
            },
        },
        Preset {
            name: "pcss-low",
            description: "PCSS 16 blocker / 16 filter taps",
            apply: |s| pcss(s, PcssQuality::Low),
        },
        Preset {
            name: "pcss-medium",
            description: "PCSS 16 blocker / 25 filter taps",
            apply: |s| pcss(s, PcssQuality::Medium),
        },
        Preset {
            name: "pcss-high",
            description: "PCSS 32 blocker / 49 filter taps",
            apply: |s| pcss(s, PcssQuality::High),
        },
        Preset {
            name: "pcss-medium-contact",
            description: "PCSS Medium with contact shadows (the light's own, else 16 steps over 0.3 m)",
            apply: |s| {
                pcss(s, PcssQuality::Medium);
                contact(s);
            },
        },
        Preset {
            name: "pcss-medium-no-rpb",
            description: "PCSS Medium without receiver-plane bias",
            apply: |s| {
                pcss(s, PcssQuality::Medium);
                s.filter.receiver_plane_bias = false;
            },
        },
        Preset {
            name: "pcss-medium-no-blend",
            description: "PCSS Medium without cascade blending",
            apply: |s| {
                pcss(s, PcssQuality::Medium);
                s.map.cascades.blend_width = 0.0;
            },
        },
        Preset {
            name: "vsm",
            description: "VSM with contact hardening, no pre-blur (spot and point lights)",
            apply: |s| vsm(s, 0),
        },
        Preset {
            name: "vsm-blur4",
            description: "VSM with contact hardening over a 4-texel Gaussian pre-blur (spot and point lights)",
            apply: |s| vsm(s, 4),
        },
        Preset {
            name: "vsm-fixed",
            description: "VSM, a fixed 2-texel pre-blur and one fetch (no contact hardening; spot and point lights)",
            apply: |s| {
                vsm(s, 2);
                s.filter.moments.contact_hardening = false;
            },
        },
        Preset {
            name: "evsm-fp16",
            description: "EVSM2, 16-bit moments (exponent 5.2), suns",
            apply: |s| moments(s, ShadowMode::Evsm, MomentFormat::Fp16),
        },
        Preset {
            name: "evsm-fp32",
            description: "EVSM2, 32-bit moments (exponent 42), suns",
            apply: |s| moments(s, ShadowMode::Evsm, MomentFormat::Fp32),
        },
        Preset {
            name: "evsm-fp32-contact",
            description: "EVSM2, 32-bit moments, suns, with contact shadows (the light's own, else 16 steps over 0.3 m)",
            apply: |s| {
                moments(s, ShadowMode::Evsm, MomentFormat::Fp32);
                contact(s);
            },
        },
        Preset {
            name: "evsm4",
            description: "EVSM4, 32-bit moments where filterable, suns",
            apply: |s| moments(s, ShadowMode::Evsm4, MomentFormat::Auto),
        },
        Preset {
            name: "msm-fp16",
            description: "4-moment shadow map, 16-bit quantised moments, suns",
            apply: |s| moments(s, ShadowMode::Msm, MomentFormat::Fp16),
        },
        Preset {
            name: "msm-fp32",
            description: "4-moment shadow map, 32-bit moments, suns",
            apply: |s| moments(s, ShadowMode::Msm, MomentFormat::Fp32),
        },
        Preset {
            name: "evsm-fixed",
            description: "EVSM2, 32-bit moments, a fixed blur (no contact hardening), suns",
            apply: |s| {
                moments(s, ShadowMode::Evsm, MomentFormat::Fp32);
                s.filter.moments.contact_hardening = false;
            },
        },
        Preset {
            name: "msm-fixed",
            description: "4-moment shadow map, 16 bits, a fixed blur (no contact hardening), suns",
            apply: |s| {
                moments(s, ShadowMode::Msm, MomentFormat::Fp16);
                s.filter.moments.contact_hardening = false;
            },
        },
        Preset {
            name: "clipmap-pcf",
            description: "a sun's clipmap (6 levels, the finest 32 m) with PCF 5×5",
            apply: |s| {
                clipmap(s);
                pcf(s, 2);
            },
        },
        Preset {
            name: "clipmap-pcss",
            description: "a sun's clipmap (6 levels, the finest 32 m) with PCSS Medium",
            apply: |s| {
                clipmap(s);
                pcss(s, PcssQuality::Medium);
            },
        },
        Preset {
            name: "clipmap-evsm",
            description: "a sun's clipmap (6 levels, the finest 32 m) with 32-bit EVSM2",
            apply: |s| {
                clipmap(s);
                moments(s, ShadowMode::Evsm, MomentFormat::Fp32);
            },
        },
        Preset {
            name: "pages-pcf",
            description: "a sun's virtual clipmap (6 levels of 16384², the finest 32 m; 2048 pages of 128²) with PCF 5×5",
            apply: |s| {
                s.map.layout = SunLayout::virtual_clipmap();
                pcf(s, 2);
            },
        },
        Preset {
            name: "pages-pcss",
            description: "a sun's virtual clipmap (6 levels of 16384², the finest 32 m; 2048 pages of 128²) with PCSS Medium",
            apply: |s| {
                s.map.layout = SunLayout::virtual_clipmap();
                pcss(s, PcssQuality::Medium);
            },
        },
        Preset {
            name: "pages-evsm",
            description: "a sun's virtual clipmap (6 levels of 16384², the finest 32 m; 2048 pages of 128²) with 32-bit EVSM2, blurred within each page",
            apply: |s| {
                s.map.layout = SunLayout::virtual_clipmap();
                moments(s, ShadowMode::Evsm, MomentFormat::Fp32);
            },
        },
    ]
}

/// The light's own contact shadows where it has some, else the defaults
/// ([`ContactShadows::ON`]).
fn contact(s: &mut ShadowSettings) {
    if !s.filter.contact.enabled() {
        s.filter.contact = ContactShadows::ON;
    }
}

/// A sun's clipmap of the presets: 6 levels, the finest 32 m wide (spot and point lights
/// render as their base preset does).
fn clipmap(s: &mut ShadowSettings) {
    s.map.layout = SunLayout::Clipmap {
        levels: 6,
        level0_extent: 32.0,
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_distinct_and_valid() {
        let all = presets();
        let mut seen = std::collections::HashSet::new();
        for p in &all {
            assert!(seen.insert(p.name), "duplicate {}", p.name);
            let mut s = ShadowSettings::default();
            (p.apply)(&mut s);
            assert!(s.problems().is_empty(), "{}: {:?}", p.name, s.problems());
        }
        let mut hard = ShadowSettings::default();
        (all[0].apply)(&mut hard);
        assert_eq!((hard.filter.mode, hard.filter.pcf_radius), (ShadowMode::Pcf, 0));
    }
}
