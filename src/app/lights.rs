//! The lights of a scene file as entities to spawn: the `sun` first (with the scene's
//! `shadows`), then every entry of `lights` in file order.

use bevy_ecs::name::Name;
use bevy_ecs::world::World;
use bevy_transform::components::Transform;
use glam::Vec3;

use crate::app::scene_entity::SceneEntity;
use crate::ecs::components::DirectionalLight;
use crate::ecs::lights::{PointLight, SpotLight};
use crate::scene::{LightDesc, SceneDesc, SunDesc};
use crate::settings::ShadowSettings;

/// One light entity to spawn.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum LightPlan {
    /// A directional light with its shadow settings.
    Directional(DirectionalLight, Transform, ShadowSettings),
    /// A spot light, with its own shadow settings if the file gives them.
    Spot(SpotLight, Transform, Option<ShadowSettings>),
    /// A point light.
    Point(PointLight, Transform, Option<ShadowSettings>),
}

/// A transform at `position` whose forward (−Z) axis is `direction`.
fn aimed(position: Vec3, direction: Vec3) -> Transform {
    Transform::from_translation(position).looking_at(position + direction, Vec3::Y)
}

/// A directional light travelling along `sun.direction` (angles in the file are degrees).
fn directional(sun: &SunDesc, shadows_enabled: bool, settings: ShadowSettings) -> LightPlan {
    let light = DirectionalLight {
        color: sun.color,
        illuminance: sun.illuminance,
        angular_diameter: sun.angular_diameter.to_radians(),
        shadows_enabled,
    };
    LightPlan::Directional(light, aimed(Vec3::ZERO, sun.direction), settings)
}

/// Every light of `desc`, the sun first, each with its name: `sun` for the scene's sun,
/// `lights[i]` for the `i`th entry of `lights`.
pub(crate) fn light_plans(desc: &SceneDesc) -> Vec<(Name, LightPlan)> {
    let sun = desc
        .sun
        .iter()
        .map(|s| (Name::new("sun"), directional(s, true, desc.shadows)));
    let lights = desc.lights.iter().map(|l| match *l {
        LightDesc::Directional {
            direction,
            color,
            illuminance,
            angular_diameter,
            shadows,
            shadows_enabled,
        } => {
            let sun = SunDesc {
                direction,
                color,
                illuminance,
                angular_diameter,
            };
            directional(&sun, shadows_enabled, shadows.unwrap_or(desc.shadows))
        }
        LightDesc::Spot {
            position,
            direction,
            color,
            intensity,
            range,
            inner_angle,
            outer_angle,
            radius,
            shadows,
            shadows_enabled,
        } => {
            let light = SpotLight {
                color,
                intensity,
                range,
                inner_angle: inner_angle.to_radians(),
                outer_angle: outer_angle.to_radians(),
                radius,
                shadows_enabled,
            };
            LightPlan::Spot(light, aimed(position, direction), shadows)
        }
        LightDesc::Point {
            position,
            color,
            intensity,
            range,
            radius,
            shadows,
            shadows_enabled,
        } => {
            let light = PointLight {
                color,
                intensity,
                range,
                radius,
                shadows_enabled,
            };
            LightPlan::Point(light, Transform::from_translation(position), shadows)
        }
    });
    let named = lights
        .enumerate()
        .map(|(i, plan)| (Name::new(format!("lights[{i}]")), plan));
    sun.chain(named).collect()
}

/// Spawns the planned lights, each marked [`SceneEntity`] and with its name.
pub(crate) fn spawn_lights(world: &mut World, plans: Vec<(Name, LightPlan)>) {
    for (name, plan) in plans {
        match plan {
            LightPlan::Directional(light, transform, settings) => {
                world.spawn((light, transform, settings, SceneEntity, name));
            }
            LightPlan::Spot(light, transform, settings) => {
                let mut entity = world.spawn((light, transform, SceneEntity, name));
                if let Some(settings) = settings {
                    entity.insert(settings);
                }
            }
            LightPlan::Point(light, transform, settings) => {
                let mut entity = world.spawn((light, transform, SceneEntity, name));
                if let Some(settings) = settings {
                    entity.insert(settings);
                }
            }
        }
    }
}
