//! [`ContactShadows`]: a light's screen-space contact shadows, the short march towards the
//! light over the depth prepass that closes the gap a shadow map leaves where a caster meets
//! its receiver; with their ranges and checks.

use serde::{Deserialize, Serialize};

use crate::settings::checks::{SettingsProblem, check_f32, check_u32};

/// Most steps a contact-shadow march takes.
pub const MAX_CONTACT_STEPS: u32 = 64;

/// Contact shadows of one light: from each pixel of the depth prepass, `steps` samples along
/// `length` metres towards the light, jittered per pixel (interleaved-gradient noise); a
/// sample hidden behind the depth the camera saw, by less than `thickness` metres along the
/// camera's ray, is an occluder and darkens the light by `intensity`. Each sample is compared
/// with the plane of the surface the camera saw there (its depth and normal), so flat ground
/// at grazing angles does not shadow itself; a march that leaves the screen or reaches the
/// sky finds nothing. Off by default (`steps` 0); needs the depth prepass (a light that asks
/// for it turns the prepass on in [`DepthPrepass::Auto`](crate::render::DepthPrepass)).
/// Scene files write it as `contact_shadows: (length: 0.3, steps: 16, thickness: 0.02,
/// intensity: 1.0)`, any field left out taking its default.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ContactShadows {
    /// World length of the march, metres (0.01–5).
    pub length: f32,
    /// Samples along it, 0–64; 0 turns contact shadows off.
    pub steps: u32,
    /// How far behind the depth the camera saw a sample may lie and still count as inside
    /// an occluder, metres along the camera's ray (0.001–2): thinner than the casters, or a
    /// ray passing behind one is shadowed.
    pub thickness: f32,
    /// How much an occluded pixel is darkened, 0–1.
    pub intensity: f32,
}

impl ContactShadows {
    /// Off: the defaults with no steps.
    pub const OFF: ContactShadows = ContactShadows {
        length: 0.3,
        steps: 0,
        thickness: 0.02,
        intensity: 1.0,
    };

    /// On with the defaults: 16 steps over 0.3 m, 2 cm thick, full intensity.
    pub const ON: ContactShadows = ContactShadows { steps: 16, ..Self::OFF };

    /// True when a march runs: some steps over some length, with some intensity.
    pub fn enabled(&self) -> bool {
        self.steps > 0 && self.length > 0.0 && self.intensity > 0.0
    }

    /// Clamps every field into its range, reporting each one that had to change.
    pub(super) fn check(&mut self, problems: &mut Vec<SettingsProblem>) {
        let d = ContactShadows::OFF;
        check_f32(
            problems,
            "contact_shadows.length",
            &mut self.length,
            0.01,
            5.0,
            d.length,
            "metres from 0.01 to 5",
        );
        check_u32(
            problems,
            "contact_shadows.steps",
            &mut self.steps,
            0,
            MAX_CONTACT_STEPS,
            "an integer from 0 (off) to 64",
        );
        check_f32(
            problems,
            "contact_shadows.thickness",
            &mut self.thickness,
            0.001,
            2.0,
            d.thickness,
            "metres from 0.001 to 2",
        );
        check_f32(
            problems,
            "contact_shadows.intensity",
            &mut self.intensity,
            0.0,
            1.0,
            d.intensity,
            "a fraction from 0 to 1",
        );
    }
}

impl Default for ContactShadows {
    fn default() -> Self {
        Self::OFF
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::ShadowSettings;

    #[test]
    fn off_by_default_and_on_with_steps() {
        assert!(!ShadowSettings::default().filter.contact.enabled());
        assert!(ContactShadows::ON.enabled());
        let faint = ContactShadows {
            intensity: 0.0,
            ..ContactShadows::ON
        };
        assert!(!faint.enabled());
    }

    #[test]
    fn a_scene_file_writes_them_by_field_and_bad_values_are_named() {
        let s: ShadowSettings = ron::from_str("(contact_shadows: (steps: 24, length: 0.5))").unwrap();
        assert_eq!(
            s.filter.contact,
            ContactShadows {
                steps: 24,
                length: 0.5,
                ..ContactShadows::OFF
            }
        );
        let unknown = ron::from_str::<ShadowSettings>("(contact_shadows: (stepz: 2))").unwrap_err();
        assert!(unknown.to_string().contains("stepz"), "{unknown}");
        let mut bad = ShadowSettings::default();
        bad.filter.contact = ContactShadows {
            length: f32::NAN,
            steps: 500,
            thickness: 0.0,
            intensity: 2.0,
        };
        let (fixed, problems) = bad.sanitized();
        let text: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
        assert_eq!(
            text,
            [
                "`contact_shadows.length` is NaN, expected metres from 0.01 to 5",
                "`contact_shadows.steps` is 500, expected an integer from 0 (off) to 64",
                "`contact_shadows.thickness` is 0, expected metres from 0.001 to 2",
                "`contact_shadows.intensity` is 2, expected a fraction from 0 to 1",
            ]
        );
        assert_eq!(
            fixed.filter.contact,
            ContactShadows {
                length: 0.3,
                steps: 64,
                thickness: 0.001,
                intensity: 1.0
            }
        );
    }
}
