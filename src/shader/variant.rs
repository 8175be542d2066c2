//! Shader variants: which shader defs a forward pipeline is composed with.

use std::collections::HashMap;

use naga_oil::compose::ShaderDefValue;

use crate::settings::{ShadowDebugView, ShadowMode, ShadowSettings};

/// Which shadow filters a forward shader compiles in: PCF always, PCSS when a light needs it
/// (each light samples the taps its own quality asks for, `Light::pcss_samples`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShadowFilter {
    /// PCF only (a `(2R+1)²` grid for cascades, a rotated Poisson disc for spot lights; the
    /// radius is per light).
    Pcf,
    /// PCF and PCSS.
    Pcss,
}

/// One forward-shader variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ForwardVariant {
    /// Shadow filter.
    pub filter: ShadowFilter,
    /// Compile spot-light shadows in (the frame has a shadowed spot light). A variant without
    /// it lights spot lights unshadowed; leaving the code out when no spot light casts keeps
    /// the sun-only shader as lean as before spot lights existed.
    pub spot_shadows: bool,
    /// Compile point-light shadows in (the frame has a shadowed point light); apart from
    /// spot shadows, so a frame without point shadows pays nothing for their code (it made a
    /// spot-light frame's lighting pass 5 % slower on the H100).
    pub point_shadows: bool,
    /// Compile the suns' moment techniques in (EVSM2, EVSM4, MSM: a shadowed sun uses one).
    pub sun_moments: bool,
    /// Tint fragments by cascade.
    pub debug_cascades: bool,
    /// Compile diffuse transmission in (`TRANSMISSION`: a material of the scene has some);
    /// without, its code costs a frame nothing (it made the H100's lighting pass 11 % slower
    /// on a scene without such materials).
    pub transmission: bool,
    /// Discard fragments below the material's alpha cutoff.
    pub alpha_mask: bool,
    /// With `alpha_mask`, under MSAA: instead of discarding, output the alpha sharpened
    /// around the cutoff for the pipeline's alpha-to-coverage (`ALPHA_TO_COVERAGE`). Such a
    /// material is drawn outside the depth prepass, so it filters its own shadows instead of
    /// reading resolved ones (`UNRESOLVED_SHADOWS`, which `penumbra::lights` honours).
    pub alpha_to_coverage: bool,
    /// Also write the shadow factor, world position and normal of every pixel (three extra
    /// `Rgba32Float` targets), for scoring against a reference.
    pub analysis: bool,
    /// Also read the lights past the uniform list's [`MAX_LIGHTS`](crate::shader::contract::MAX_LIGHTS) (`MANY_LIGHTS`: the frame
    /// has more); without, their code and binding are left out (compiled in, they made the
    /// H200's lighting pass 4–7 % slower on scenes of a few lights).
    pub many_lights: bool,
}

impl ForwardVariant {
    /// The variant the given settings need for opaque or masked materials.
    pub fn for_settings(settings: &ShadowSettings, alpha_mask: bool) -> Self {
        let filter = match settings.filter.mode {
            ShadowMode::Pcss => ShadowFilter::Pcss,
            _ => ShadowFilter::Pcf,
        };
        Self {
            filter,
            spot_shadows: false,
            point_shadows: false,
            sun_moments: settings.filter.mode.effective(true).is_sun_moments(),
            debug_cascades: settings.filter.debug_view == ShadowDebugView::Cascades,
            transmission: false,
            alpha_mask,
            alpha_to_coverage: false,
            analysis: false,
            many_lights: false,
        }
    }

    /// This variant for a lighting pass that reads every shadowed light's resolved visibility
    /// (the compute resolve ran): the filters' code is left out, so its registers do not weigh
    /// on the pass (compiled in, point-light PCSS made it 20 % slower on the H100). The cube
    /// debug tint and the analysis outputs still need their modules, so those keep them; an
    /// alpha-to-coverage variant filters its own shadows, so it stays whole.
    pub fn reading_resolved(self) -> Self {
        if self.analysis || self.alpha_to_coverage {
            return self;
        }
        ForwardVariant {
            filter: ShadowFilter::Pcf,
            spot_shadows: false,
            point_shadows: self.point_shadows && self.debug_cascades,
            sun_moments: false,
            ..self
        }
    }

    /// This variant with alpha-to-coverage in place of the alpha test when the pass draws
    /// `samples` samples per pixel (more than one) and the material is alpha-masked.
    pub fn with_samples(self, samples: u32) -> Self {
        Self {
            alpha_to_coverage: self.alpha_mask && samples > 1,
            ..self
        }
    }

    /// Every variant the renderer can ask for (alpha-to-coverage only with the alpha mask).
    pub fn all() -> Vec<ForwardVariant> {
        let filters = [ShadowFilter::Pcf, ShadowFilter::Pcss];
        let mut all = Vec::new();
        for filter in filters {
            for (spot_shadows, point_shadows) in [(false, false), (true, false), (false, true), (true, true)] {
                for sun_moments in [false, true] {
                    for (debug_cascades, transmission) in [(false, false), (true, false), (false, true), (true, true)] {
                        for (alpha_mask, alpha_to_coverage) in [(false, false), (true, false), (true, true)] {
                            for (analysis, many_lights) in [(false, false), (true, false), (false, true), (true, true)]
                            {
                                all.push(ForwardVariant {
                                    filter,
                                    spot_shadows,
                                    point_shadows,
                                    sun_moments,
                                    debug_cascades,
                                    transmission,
                                    alpha_mask,
                                    alpha_to_coverage,
                                    analysis,
                                    many_lights,
                                });
                            }
                        }
                    }
                }
            }
        }
        all
    }

    /// The naga_oil shader defs of this variant.
    pub fn shader_defs(&self) -> HashMap<String, ShaderDefValue> {
        let mut defs = HashMap::new();
        if self.filter == ShadowFilter::Pcss {
            defs.insert("SHADOW_FILTER_PCSS".to_string(), ShaderDefValue::Bool(true));
        }
        if self.spot_shadows {
            defs.insert("SHADOW_SPOT".to_string(), ShaderDefValue::Bool(true));
        }
        if self.point_shadows {
            defs.insert("SHADOW_POINT".to_string(), ShaderDefValue::Bool(true));
        }
        if self.sun_moments {
            defs.insert("SHADOW_SUN_MOMENTS".to_string(), ShaderDefValue::Bool(true));
        }
        if self.debug_cascades {
            defs.insert("SHADOW_DEBUG_CASCADES".to_string(), ShaderDefValue::Bool(true));
        }
        if self.transmission {
            defs.insert("TRANSMISSION".to_string(), ShaderDefValue::Bool(true));
        }
        if self.alpha_mask {
            defs.insert("ALPHA_MASK".to_string(), ShaderDefValue::Bool(true));
        }
        if self.alpha_mask && self.alpha_to_coverage {
            defs.insert("ALPHA_TO_COVERAGE".to_string(), ShaderDefValue::Bool(true));
            defs.insert("UNRESOLVED_SHADOWS".to_string(), ShaderDefValue::Bool(true));
        }
        if self.analysis {
            defs.insert("ANALYSIS_OUTPUTS".to_string(), ShaderDefValue::Bool(true));
        }
        if self.many_lights {
            defs.insert("MANY_LIGHTS".to_string(), ShaderDefValue::Bool(true));
        }
        defs
    }

    /// A short label for pipeline names and logs, e.g. `pcss+mask`.
    pub fn label(&self) -> String {
        let mut s = match self.filter {
            ShadowFilter::Pcf => "pcf".to_string(),
            ShadowFilter::Pcss => "pcss".to_string(),
        };
        if self.spot_shadows {
            s.push_str("+spot");
        }
        if self.point_shadows {
            s.push_str("+point");
        }
        if self.sun_moments {
            s.push_str("+moments");
        }
        if self.debug_cascades {
            s.push_str("+cascades");
        }
        if self.transmission {
            s.push_str("+transmission");
        }
        if self.alpha_mask {
            s.push_str("+mask");
        }
        if self.alpha_mask && self.alpha_to_coverage {
            s.push_str("+a2c");
        }
        if self.many_lights {
            s.push_str("+many-lights");
        }
        if self.analysis {
            s.push_str("+analysis");
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lighting_pass_reading_resolved_shadows_leaves_the_filters_out() {
        let full = ForwardVariant {
            filter: ShadowFilter::Pcss,
            spot_shadows: true,
            point_shadows: true,
            sun_moments: true,
            debug_cascades: false,
            transmission: true,
            alpha_mask: true,
            alpha_to_coverage: false,
            analysis: false,
            many_lights: true,
        };
        let lean = full.reading_resolved();
        assert_eq!(lean.filter, ShadowFilter::Pcf);
        assert!(!lean.spot_shadows && !lean.point_shadows && !lean.sun_moments);
        assert!(
            lean.alpha_mask && lean.many_lights,
            "the material's own defs and the light lists stay"
        );
        // The cube-face debug tint needs the point module; the analysis outputs need both.
        let debug = ForwardVariant {
            debug_cascades: true,
            ..full
        };
        assert!(debug.reading_resolved().point_shadows);
        let analysis = ForwardVariant { analysis: true, ..full };
        assert_eq!(analysis.reading_resolved(), analysis);
        // Alpha-to-coverage materials are drawn outside the prepass: nothing resolved to read.
        let covered = full.with_samples(4);
        assert!(covered.alpha_to_coverage);
        assert_eq!(covered.reading_resolved(), covered);
        assert!(!full.with_samples(1).alpha_to_coverage);
        let opaque = ForwardVariant {
            alpha_mask: false,
            ..full
        };
        assert!(!opaque.with_samples(4).alpha_to_coverage, "only masked materials");
    }
}
