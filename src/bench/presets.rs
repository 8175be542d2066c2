//! The presets the benchmark scores: each a small change on top of the scored light's own
//! settings. Every preset applies to suns; those that only change cascade blending do not
//! apply to spot lights (one view, nothing to blend) and are not run on spot-light scenes.

use crate::bench::focus::FocusKind;
use crate::settings::{PcssQuality, ShadowMode, ShadowSettings};

/// One named configuration of the shadow filter.
#[derive(Clone, Copy, Debug)]
pub struct Preset {
    /// Short name used in reports and on the plot.
    pub name: &'static str,
    /// What it is, in a few words.
    pub description: &'static str,
    /// Applies the preset on top of the scene's settings.
    pub apply: fn(&mut ShadowSettings),
    /// True when the preset differs from another only in cascade settings (blending): it
    /// does not apply to a spot light, and is not run on a scene that scores one.
    pub cascades_only: bool,
}

impl Preset {
    /// Whether the preset means anything for a light of `kind`.
    pub fn applies_to(&self, kind: FocusKind) -> bool {
        kind == FocusKind::Sun || !self.cascades_only
    }
}

fn pcf(s: &mut ShadowSettings, radius: u32) {
    s.mode = ShadowMode::Pcf;
    s.pcf_radius = radius;
}

fn pcss(s: &mut ShadowSettings, quality: PcssQuality) {
    s.mode = ShadowMode::Pcss;
    s.pcss_quality = quality;
}

/// Every preset: hard shadows, PCF radius 1–5, PCSS Low/Medium/High, and receiver-plane bias
/// and cascade blending switched off on the mid presets.
pub fn presets() -> Vec<Preset> {
    vec![
        Preset {
            name: "hard",
            description: "PCF radius 0: one hardware 2×2 comparison",
            apply: |s| pcf(s, 0),
            cascades_only: false,
        },
        Preset {
            name: "pcf1",
            description: "PCF 3×3",
            apply: |s| pcf(s, 1),
            cascades_only: false,
        },
        Preset {
            name: "pcf2",
            description: "PCF 5×5",
            apply: |s| pcf(s, 2),
            cascades_only: false,
        },
        Preset {
            name: "pcf3",
            description: "PCF 7×7",
            apply: |s| pcf(s, 3),
            cascades_only: false,
        },
        Preset {
            name: "pcf4",
            description: "PCF 9×9",
            apply: |s| pcf(s, 4),
            cascades_only: false,
        },
        Preset {
            name: "pcf5",
            description: "PCF 11×11",
            apply: |s| pcf(s, 5),
            cascades_only: false,
        },
        Preset {
            name: "pcf2-no-rpb",
            description: "PCF 5×5 without receiver-plane bias",
            apply: |s| {
                pcf(s, 2);
                s.receiver_plane_bias = false;
            },
            cascades_only: false,
        },
        Preset {
            name: "pcf2-no-blend",
            description: "PCF 5×5 without cascade blending",
            apply: |s| {
                pcf(s, 2);
                s.blend_width = 0.0;
            },
            cascades_only: true,
        },
        Preset {
            name: "pcss-low",
            description: "PCSS 16 blocker / 16 filter taps",
            apply: |s| pcss(s, PcssQuality::Low),
            cascades_only: false,
        },
        Preset {
            name: "pcss-medium",
            description: "PCSS 16 blocker / 25 filter taps",
            apply: |s| pcss(s, PcssQuality::Medium),
            cascades_only: false,
        },
        Preset {
            name: "pcss-high",
            description: "PCSS 32 blocker / 49 filter taps",
            apply: |s| pcss(s, PcssQuality::High),
            cascades_only: false,
        },
        Preset {
            name: "pcss-medium-no-rpb",
            description: "PCSS Medium without receiver-plane bias",
            apply: |s| {
                pcss(s, PcssQuality::Medium);
                s.receiver_plane_bias = false;
            },
            cascades_only: false,
        },
        Preset {
            name: "pcss-medium-no-blend",
            description: "PCSS Medium without cascade blending",
            apply: |s| {
                pcss(s, PcssQuality::Medium);
                s.blend_width = 0.0;
            },
            cascades_only: true,
        },
    ]
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
        assert_eq!((hard.mode, hard.pcf_radius), (ShadowMode::Pcf, 0));
    }

    #[test]
    fn only_the_cascade_blending_presets_skip_spot_lights() {
        let all = presets();
        let skipped: Vec<&str> = all
            .iter()
            .filter(|p| !p.applies_to(FocusKind::Spot))
            .map(|p| p.name)
            .collect();
        assert_eq!(skipped, ["pcf2-no-blend", "pcss-medium-no-blend"]);
        assert!(all.iter().all(|p| p.applies_to(FocusKind::Sun)));
        // A cascades-only preset changes nothing but cascade settings from some other preset.
        for p in all.iter().filter(|p| p.cascades_only) {
            let mut mine = ShadowSettings::default();
            (p.apply)(&mut mine);
            let twin = all.iter().filter(|q| !q.cascades_only).any(|q| {
                let mut other = ShadowSettings::default();
                (q.apply)(&mut other);
                other.blend_width = mine.blend_width;
                other == mine
            });
            assert!(twin, "{} has no twin that differs only in cascade blending", p.name);
        }
    }
}
