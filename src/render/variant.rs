//! The forward-shader variant a frame's lights need ([`forward_variant`]).

use crate::ecs::light_views::FrameLights;
use crate::settings::{ShadowDebugView, ShadowMode};
use crate::shader::contract::MAX_LIGHTS;
use crate::shader::{ForwardVariant, ShadowFilter};

/// The variant a frame's lights need: PCSS when a shadowed light uses it, else PCF; each
/// light then picks its own filter among those compiled in, and samples the PCSS taps its own
/// quality asks for. The cascade (or cube-face) debug tint is on when a sun or point
/// light asks for it.
pub fn forward_variant(lights: &FrameLights, alpha_mask: bool) -> ForwardVariant {
    // NOTE: called for every pipeline a frame draws with, so nothing is collected.
    let suns = lights.suns.iter().filter(|s| s.cascades.count > 0).map(|s| &s.settings);
    let spots = lights.spots.iter().filter(|s| s.shadow.is_some()).map(|s| &s.settings);
    let points = lights.points.iter().filter(|p| p.shadow.is_some()).map(|p| &p.settings);
    let pcss = suns
        .chain(spots)
        .chain(points)
        .any(|s| s.filter.mode == ShadowMode::Pcss);
    ForwardVariant {
        filter: if pcss { ShadowFilter::Pcss } else { ShadowFilter::Pcf },
        spot_shadows: lights.spots.iter().any(|s| s.shadow.is_some()),
        point_shadows: lights.points.iter().any(|p| p.shadow.is_some()),
        sun_moments: lights
            .suns
            .iter()
            .any(|s| s.cascades.count > 0 && s.settings.filter.mode.effective(true).is_sun_moments()),
        debug_cascades: lights
            .suns
            .iter()
            .map(|s| &s.settings)
            .chain(lights.points.iter().map(|p| &p.settings))
            .any(|s| s.filter.debug_view == ShadowDebugView::Cascades),
        transmission: false,
        alpha_mask,
        alpha_to_coverage: false,
        analysis: false,
        many_lights: lights.suns.len() + lights.spots.len() + lights.points.len() > MAX_LIGHTS as usize,
    }
}
