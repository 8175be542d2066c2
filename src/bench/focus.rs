//! Which light the benchmark scores on a scene, and the reference it is scored with.
//!
//! The rule ([`choose_focus`]): a scene with no directional light scores its first shadowed
//! spot light, or without one its first shadowed point light, against the visible fraction of
//! the light's emitter sphere; every other scene scores its first directional light against
//! the visible fraction of the sun's disc, as the benchmark did before it knew other lights.

use bevy_ecs::entity::Entity;
use glam::Vec3;

use crate::analysis::results::ScoredLight;
use crate::ecs::light_views::{FrameLights, PointLightView, SpotLightView};
use crate::math::light_budget::LightKind;
use crate::reference::{
    ReferencePoint, ReferenceScene, ReferenceSettings, SphereLight, SunDisc, Visibility, sphere_light_visibility,
    sun_visibility,
};

/// The kind of light a scene scores.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FocusKind {
    /// A directional light: cascaded shadows, the sun-disc reference.
    Sun,
    /// A spot light: one perspective view, the sphere-light reference.
    Spot,
    /// A point light: a cube of six views, the sphere-light reference.
    Point,
}

/// The light a scene scores, by entity (so it is found again whatever the order of the
/// frame's light lists).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Focus {
    /// What kind of light it is.
    pub kind: FocusKind,
    /// The light's entity.
    pub entity: Entity,
}

/// The light the benchmark scores among `lights`: when there is no directional light, the
/// first shadowed spot light (in the renderer's order), else the first shadowed point light;
/// otherwise the first directional light. A light counts as shadowed when it asks for
/// shadows and has its shadow views this frame. None when the scene has none of these.
pub fn choose_focus(lights: &FrameLights) -> Option<Focus> {
    if lights.suns.is_empty() {
        let spot = lights
            .spots
            .iter()
            .find(|s| s.light.shadows_enabled && s.shadow.is_some())
            .map(|s| (FocusKind::Spot, s.entity));
        let point = || {
            lights
                .points
                .iter()
                .find(|p| p.light.shadows_enabled && p.shadow.is_some())
                .map(|p| (FocusKind::Point, p.entity))
        };
        let (kind, entity) = spot.or_else(point)?;
        return Some(Focus { kind, entity });
    }
    lights.sun().map(|sun| Focus {
        kind: FocusKind::Sun,
        entity: sun.entity,
    })
}

/// What the reference rays aim at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FocusReference {
    /// The sun's disc.
    Sun(SunDisc),
    /// A spot or point light's emitter sphere.
    Sphere(SphereLight),
}

impl FocusReference {
    /// The reference visibility of each point (see [`sun_visibility`] and
    /// [`sphere_light_visibility`]).
    pub fn visibility(
        &self,
        scene: &ReferenceScene,
        points: &[ReferencePoint],
        settings: &ReferenceSettings,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Vec<Visibility> {
        match self {
            Self::Sun(sun) => sun_visibility(scene, sun, points, settings, progress),
            Self::Sphere(light) => sphere_light_visibility(scene, light, points, settings, progress),
        }
    }
}

impl Focus {
    /// The focus spot light this frame (None for a sun focus, or when it is gone).
    fn spot<'a>(&self, lights: &'a FrameLights) -> Option<(usize, &'a SpotLightView)> {
        if self.kind != FocusKind::Spot {
            return None;
        }
        lights.spots.iter().enumerate().find(|(_, s)| s.entity == self.entity)
    }

    /// The focus point light this frame (None for another focus, or when it is gone).
    fn point<'a>(&self, lights: &'a FrameLights) -> Option<(usize, &'a PointLightView)> {
        if self.kind != FocusKind::Point {
            return None;
        }
        lights.points.iter().enumerate().find(|(_, p)| p.entity == self.entity)
    }

    /// Its index in the renderer's light list (suns, then spots, then points), for
    /// [`Renderer::set_focus_light`](crate::render::Renderer::set_focus_light).
    pub fn light_index(&self, lights: &FrameLights) -> Option<usize> {
        match self.kind {
            FocusKind::Sun => {
                let i = lights.suns.iter().position(|s| s.entity == self.entity)?;
                Some(lights.light_index(LightKind::Directional, i))
            }
            FocusKind::Spot => Some(lights.light_index(LightKind::Spot, self.spot(lights)?.0)),
            FocusKind::Point => Some(lights.light_index(LightKind::Point, self.point(lights)?.0)),
        }
    }

    /// The light as the report names it.
    pub fn scored_light(&self, lights: &FrameLights) -> Option<ScoredLight> {
        match self.kind {
            FocusKind::Sun => {
                let sun = lights.suns.iter().find(|s| s.entity == self.entity)?;
                Some(ScoredLight::Sun {
                    angular_diameter: sun.light.angular_diameter.to_degrees(),
                })
            }
            FocusKind::Spot => {
                let (index, spot) = self.spot(lights)?;
                Some(ScoredLight::Spot {
                    index,
                    radius: spot.light.radius,
                })
            }
            FocusKind::Point => {
                let (index, point) = self.point(lights)?;
                Some(ScoredLight::Point {
                    index,
                    radius: point.light.radius,
                })
            }
        }
    }

    /// What its reference rays aim at. Positions are those of `lights` (relative to the
    /// render origin, like the analysis targets and the reference scene).
    pub fn reference(&self, lights: &FrameLights) -> Option<FocusReference> {
        match self.kind {
            FocusKind::Sun => {
                let sun = lights.suns.iter().find(|s| s.entity == self.entity)?;
                Some(FocusReference::Sun(SunDisc {
                    direction: sun.direction,
                    angular_diameter: sun.light.angular_diameter,
                }))
            }
            FocusKind::Spot => {
                let (_, spot) = self.spot(lights)?;
                Some(FocusReference::Sphere(SphereLight {
                    center: spot.position,
                    radius: spot.light.radius,
                }))
            }
            FocusKind::Point => {
                let (_, point) = self.point(lights)?;
                Some(FocusReference::Sphere(SphereLight {
                    center: point.position,
                    radius: point.light.radius,
                }))
            }
        }
    }

    /// The world size of one shadow-map texel, the step of the stability paths: cascade 0's
    /// texel for a sun; for a spot light, its map's texel at the distance of `target` (the
    /// camera's target, relative to the render origin) along the light's axis; for a point
    /// light, its face's texel at the distance of `target` along the face's axis. 1 cm where
    /// none is known.
    pub fn texel(&self, lights: &FrameLights, target: Vec3) -> f32 {
        const FALLBACK: f32 = 0.01;
        let texel = match self.kind {
            FocusKind::Sun => lights
                .suns
                .iter()
                .find(|s| s.entity == self.entity)
                .filter(|s| s.cascades.count > 0)
                .map(|s| s.cascades.cascades[0].texel_world_size),
            FocusKind::Spot => self.spot(lights).and_then(|(_, spot)| {
                let view = spot.shadow?;
                Some(view.texel_size_at((target - spot.position).dot(spot.direction)))
            }),
            FocusKind::Point => self.point(lights).and_then(|(_, point)| {
                let view = point.shadow?;
                Some(view.texel_per_metre * (target - point.position).abs().max_element())
            }),
        };
        texel.filter(|t| t.is_finite() && *t > 0.0).unwrap_or(FALLBACK)
    }
}

#[cfg(test)]
mod tests {
    use bevy_ecs::world::World;

    use super::*;
    use crate::ecs::components::DirectionalLight;
    use crate::ecs::light_views::SunView;
    use crate::ecs::lights::{PointLight, SpotLight};
    use crate::math::cascades::CascadeSet;
    use crate::math::point::point_view;
    use crate::math::spot::{SpotInput, spot_view};
    use crate::settings::ShadowSettings;

    fn sun(entity: Entity) -> SunView {
        SunView {
            entity,
            direction: Vec3::NEG_Y,
            light: DirectionalLight::default(),
            settings: ShadowSettings::default(),
            resolution: 2048,
            cascades: CascadeSet::default(),
            clipmap: Default::default(),
            paged: None,
        }
    }

    /// A spot light 6 m up, pointing down, with a 1024² shadow view when `shadowed`.
    fn spot(entity: Entity, radius: f32, shadowed: bool) -> SpotLightView {
        let position = Vec3::new(0.0, 6.0, 0.0);
        let light = SpotLight {
            radius,
            outer_angle: 45f32.to_radians(),
            ..SpotLight::default()
        };
        let shadow = spot_view(&SpotInput {
            position,
            direction: Vec3::NEG_Y,
            outer_angle: light.outer_angle,
            range: light.range,
            near: 0.05,
            resolution: 1024,
        });
        assert!(shadow.is_some());
        SpotLightView {
            entity,
            position,
            direction: Vec3::NEG_Y,
            light,
            settings: ShadowSettings::default(),
            resolution: 2048,
            shadow: shadow.filter(|_| shadowed),
        }
    }

    #[test]
    fn a_scene_without_suns_scores_its_first_shadowed_spot_light() {
        let mut world = World::new();
        let [a, b, c] = [(); 3].map(|_| world.spawn_empty().id());
        let mut lights = FrameLights {
            spots: vec![spot(a, 0.1, false), spot(b, 0.25, true), spot(c, 0.5, true)],
            ..FrameLights::default()
        };
        let focus = choose_focus(&lights).expect("a shadowed spot light");
        assert_eq!(
            focus,
            Focus {
                kind: FocusKind::Spot,
                entity: b
            }
        );
        assert_eq!(focus.light_index(&lights), Some(1));
        assert_eq!(
            focus.scored_light(&lights),
            Some(ScoredLight::Spot { index: 1, radius: 0.25 })
        );
        assert_eq!(
            focus.reference(&lights),
            Some(FocusReference::Sphere(SphereLight {
                center: Vec3::new(0.0, 6.0, 0.0),
                radius: 0.25
            }))
        );
        // The texel at the target's distance along the axis (6 m): 2 · tan 45° · 6 / 1024.
        let texel = focus.texel(&lights, Vec3::new(3.0, 0.0, 0.0));
        assert!((texel - 12.0 / 1024.0).abs() < 1e-4, "{texel}");
        // A spot light that asks for no shadow is not scored.
        lights.spots[1].light.shadows_enabled = false;
        assert_eq!(choose_focus(&lights).map(|f| f.entity), Some(c));
        // None shadowed: nothing to score.
        lights.spots[2].shadow = None;
        assert_eq!(choose_focus(&lights), None);
        assert_eq!(choose_focus(&FrameLights::default()), None);
    }

    /// A point light 3 m up with a 512² cube when `shadowed`.
    fn point(entity: Entity, radius: f32, shadowed: bool) -> PointLightView {
        let position = Vec3::new(0.0, 3.0, 0.0);
        let light = PointLight {
            radius,
            ..PointLight::default()
        };
        PointLightView {
            entity,
            position,
            light,
            settings: ShadowSettings::default(),
            resolution: 2048,
            shadow: point_view(position, 0.05, light.range, 512).filter(|_| shadowed),
        }
    }

    #[test]
    fn a_scene_without_suns_or_shadowed_spots_scores_its_first_shadowed_point_light() {
        let mut world = World::new();
        let [s, a, b] = [(); 3].map(|_| world.spawn_empty().id());
        let mut lights = FrameLights {
            spots: vec![spot(s, 0.1, false)],
            points: vec![point(a, 0.1, false), point(b, 0.2, true)],
            ..FrameLights::default()
        };
        let focus = choose_focus(&lights).expect("a shadowed point light");
        assert_eq!(
            focus,
            Focus {
                kind: FocusKind::Point,
                entity: b
            }
        );
        // After the spot light in the renderer's list: spot 0, point 0, point 1.
        assert_eq!(focus.light_index(&lights), Some(2));
        assert_eq!(
            focus.scored_light(&lights),
            Some(ScoredLight::Point { index: 1, radius: 0.2 })
        );
        assert_eq!(
            focus.reference(&lights),
            Some(FocusReference::Sphere(SphereLight {
                center: Vec3::new(0.0, 3.0, 0.0),
                radius: 0.2
            }))
        );
        // The face texel at the target's distance along its face's axis (3 m down): 2 · 3 / 512.
        let texel = focus.texel(&lights, Vec3::new(1.0, 0.0, 0.5));
        assert!((texel - 6.0 / 512.0).abs() < 1e-5, "{texel}");
        // A shadowed spot light comes first.
        lights.spots[0].shadow = spot(s, 0.1, true).shadow;
        assert_eq!(choose_focus(&lights).map(|f| f.kind), Some(FocusKind::Spot));
    }

    #[test]
    fn any_directional_light_keeps_the_first_sun_in_focus() {
        let mut world = World::new();
        let [s0, s1, p] = [(); 3].map(|_| world.spawn_empty().id());
        let lights = FrameLights {
            suns: vec![sun(s0), sun(s1)],
            spots: vec![spot(p, 0.25, true)],
            ..FrameLights::default()
        };
        let focus = choose_focus(&lights).expect("a sun");
        assert_eq!(
            focus,
            Focus {
                kind: FocusKind::Sun,
                entity: s0
            }
        );
        assert_eq!(focus.light_index(&lights), Some(0));
        assert!(matches!(focus.reference(&lights), Some(FocusReference::Sun(_))));
        assert!(matches!(focus.scored_light(&lights), Some(ScoredLight::Sun { .. })));
        // No cascades this frame: the 1 cm fallback.
        assert_eq!(focus.texel(&lights, Vec3::ZERO), 0.01);
        // The spot light's index in the renderer's list comes after the suns.
        let spot_focus = Focus {
            kind: FocusKind::Spot,
            entity: p,
        };
        assert_eq!(spot_focus.light_index(&lights), Some(2));
    }
}
