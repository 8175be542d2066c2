//! Repairs for light parameters that code (a user's system, an editor, a physics crate) set
//! out of range: each bad value is replaced by a safe one and named in [`ShadowDiagnostics`],
//! so one light never poisons a frame with NaN and never vanishes without a word.

use bevy_ecs::entity::Entity;

use crate::ecs::components::DirectionalLight;
use crate::ecs::lights::{PointLight, SpotLight};
use crate::ecs::stats::ShadowDiagnostics;
use crate::math::spot::MAX_SPOT_HALF_ANGLE;
use crate::settings::ShadowSettings;

/// Largest angular diameter of a directional light, radians (about 34°).
pub const MAX_ANGULAR_DIAMETER: f32 = 0.6;

/// The entity's shadow settings (or the defaults), clamped into range with a warning per
/// problem.
pub fn sanitized_settings(settings: Option<&ShadowSettings>, diagnostics: &mut ShadowDiagnostics) -> ShadowSettings {
    let (settings, problems) = settings.copied().unwrap_or_default().sanitized();
    for p in problems {
        diagnostics.warn(format!("shadow settings: {p}; clamped"));
    }
    settings
}

/// Warns when a light asks for a filter its kind does not have (`sun`: a directional light),
/// naming the one it gets instead ([`crate::settings::ShadowMode::effective`]).
pub fn warn_mode(
    diagnostics: &mut ShadowDiagnostics,
    what: &str,
    entity: Entity,
    settings: &ShadowSettings,
    sun: bool,
) {
    let effective = settings.filter.mode.effective(sun);
    if effective != settings.filter.mode {
        let kinds = if sun { "spot and point lights" } else { "suns" };
        diagnostics.warn_about(
            &entity.to_string(),
            format!(
                "{what} {entity} asks for {:?}, which only {kinds} have; it is filtered with {effective:?}",
                settings.filter.mode
            ),
        );
    }
}

/// `value` when `ok`, else `fallback` with a warning naming the light and the field.
fn checked(
    what: &str,
    entity: Entity,
    field: &str,
    value: f32,
    ok: bool,
    fallback: f32,
    diagnostics: &mut ShadowDiagnostics,
) -> f32 {
    if ok {
        return value;
    }
    diagnostics.warn_about(
        &entity.to_string(),
        format!("{what} light {entity} has {field} {value}, out of range; using {fallback}"),
    );
    fallback
}

/// Colour and intensity must be finite and not negative.
fn check_color(
    what: &str,
    entity: Entity,
    color: glam::Vec3,
    intensity: f32,
    diagnostics: &mut ShadowDiagnostics,
) -> (glam::Vec3, f32) {
    let color = if color.is_finite() && color.min_element() >= 0.0 {
        color
    } else {
        diagnostics.warn_about(
            &entity.to_string(),
            format!("{what} light {entity} has colour {color}, out of range; using white"),
        );
        glam::Vec3::ONE
    };
    let ok = intensity.is_finite() && intensity >= 0.0;
    let intensity = checked(what, entity, "intensity", intensity, ok, 0.0, diagnostics);
    (color, intensity)
}

/// A positional light's `(range, radius)`: a positive range (else `default_range`) and a
/// radius that is not negative (else 0).
fn check_reach(
    what: &str,
    entity: Entity,
    (range, radius): (f32, f32),
    default_range: f32,
    diagnostics: &mut ShadowDiagnostics,
) -> (f32, f32) {
    let range_ok = range.is_finite() && range > 0.0;
    let range = checked(what, entity, "range", range, range_ok, default_range, diagnostics);
    let radius_ok = radius.is_finite() && radius >= 0.0;
    let radius = checked(what, entity, "radius", radius, radius_ok, 0.0, diagnostics);
    (range, radius)
}

/// A directional light with its colour, illuminance and angular diameter in range.
pub fn sanitize_sun(entity: Entity, light: &DirectionalLight, diagnostics: &mut ShadowDiagnostics) -> DirectionalLight {
    let (color, illuminance) = check_color("directional", entity, light.color, light.illuminance, diagnostics);
    let a = light.angular_diameter;
    let ok = a.is_finite() && (0.0..=MAX_ANGULAR_DIAMETER).contains(&a);
    let fallback = DirectionalLight::default().angular_diameter;
    DirectionalLight {
        color,
        illuminance,
        angular_diameter: checked("directional", entity, "angular_diameter", a, ok, fallback, diagnostics),
        ..*light
    }
}

/// A spot light with a positive range, `0 < outer_angle ≤ 89°`, `0 ≤ inner_angle ≤
/// outer_angle` and a radius that is not negative.
pub fn sanitize_spot(entity: Entity, light: &SpotLight, diagnostics: &mut ShadowDiagnostics) -> SpotLight {
    let (color, intensity) = check_color("spot", entity, light.color, light.intensity, diagnostics);
    let d = SpotLight::default();
    let (range, radius) = check_reach("spot", entity, (light.range, light.radius), d.range, diagnostics);
    let w = &mut *diagnostics;
    let outer = light.outer_angle;
    let outer_ok = outer.is_finite() && outer > 0.0 && outer <= MAX_SPOT_HALF_ANGLE;
    let fallback = if outer.is_finite() {
        outer.clamp(1e-3, MAX_SPOT_HALF_ANGLE)
    } else {
        d.outer_angle
    };
    let outer_angle = checked("spot", entity, "outer_angle", outer, outer_ok, fallback, w);
    let inner = light.inner_angle;
    let inner_ok = inner.is_finite() && (0.0..=outer_angle).contains(&inner);
    let inner_angle = checked("spot", entity, "inner_angle", inner, inner_ok, 0.0, w);
    SpotLight {
        color,
        intensity,
        range,
        inner_angle,
        outer_angle,
        radius,
        ..*light
    }
}

/// A point light with a positive range and a radius that is not negative.
pub fn sanitize_point(entity: Entity, light: &PointLight, diagnostics: &mut ShadowDiagnostics) -> PointLight {
    let (color, intensity) = check_color("point", entity, light.color, light.intensity, diagnostics);
    let reach = (light.range, light.radius);
    let (range, radius) = check_reach("point", entity, reach, PointLight::default().range, diagnostics);
    PointLight {
        color,
        intensity,
        range,
        radius,
        ..*light
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_spot_values_are_repaired_and_named() {
        let mut d = ShadowDiagnostics::default();
        let e = Entity::from_raw_u32(7).unwrap();
        let bad = SpotLight {
            range: f32::NAN,
            outer_angle: 2.0,
            inner_angle: 3.0,
            radius: -1.0,
            intensity: f32::INFINITY,
            ..SpotLight::default()
        };
        let fixed = sanitize_spot(e, &bad, &mut d);
        assert_eq!(fixed.range, SpotLight::default().range);
        assert_eq!(fixed.outer_angle, MAX_SPOT_HALF_ANGLE);
        assert_eq!(fixed.inner_angle, 0.0);
        assert_eq!(fixed.radius, 0.0);
        assert_eq!(fixed.intensity, 0.0);
        assert_eq!(d.current.len(), 5, "{:?}", d.current);
        assert!(d.current.iter().all(|w| w.starts_with("spot light ")));
        let good = SpotLight::default();
        let mut quiet = ShadowDiagnostics::default();
        assert_eq!(sanitize_spot(e, &good, &mut quiet), good);
        assert!(quiet.current.is_empty());
    }

    #[test]
    fn bad_sun_and_point_values_are_repaired() {
        let mut d = ShadowDiagnostics::default();
        let e = Entity::from_raw_u32(3).unwrap();
        let sun = DirectionalLight {
            angular_diameter: 1.0,
            color: glam::Vec3::NAN,
            ..Default::default()
        };
        let fixed = sanitize_sun(e, &sun, &mut d);
        assert_eq!(fixed.angular_diameter, DirectionalLight::default().angular_diameter);
        assert_eq!(fixed.color, glam::Vec3::ONE);
        let point = PointLight {
            range: -2.0,
            ..Default::default()
        };
        assert_eq!(sanitize_point(e, &point, &mut d).range, PointLight::default().range);
        assert_eq!(d.current.len(), 3, "{:?}", d.current);
    }
}
