//! The sun section: azimuth and elevation (the light's direction), angular diameter and the
//! shadow switch.

use bevy_ecs::world::World;
use bevy_transform::components::Transform;
use egui::{Slider, Ui};
use glam::Vec3;

use crate::ecs::components::DirectionalLight;

/// Sun direction as azimuth and elevation, in degrees, for the sliders.
pub(crate) fn sun_angles(direction: Vec3) -> (f32, f32) {
    let to_sun = -direction.normalize_or(Vec3::NEG_Y);
    let elevation = to_sun.y.clamp(-1.0, 1.0).asin().to_degrees();
    let azimuth = to_sun.x.atan2(to_sun.z).to_degrees();
    (azimuth, elevation)
}

/// Direction the light travels for an azimuth and elevation in degrees.
pub(crate) fn sun_direction(azimuth: f32, elevation: f32) -> Vec3 {
    let (a, e) = (azimuth.to_radians(), elevation.to_radians());
    -Vec3::new(e.cos() * a.sin(), e.sin(), e.cos() * a.cos())
}

/// Draws the sun controls for the first directional light; false when there is none.
pub(crate) fn sun_ui(ui: &mut Ui, world: &mut World) -> bool {
    let mut query = world.query::<(&mut DirectionalLight, &mut Transform)>();
    let Some((mut light, mut transform)) = query.iter_mut(world).next() else {
        return false;
    };
    let (mut azimuth, mut elevation) = sun_angles(transform.rotation * Vec3::NEG_Z);
    let mut turned = ui
        .add(Slider::new(&mut azimuth, -180.0..=180.0).text("azimuth °"))
        .changed();
    turned |= ui
        .add(Slider::new(&mut elevation, -5.0..=90.0).text("elevation °"))
        .changed();
    if turned {
        *transform = Transform::default().looking_at(sun_direction(azimuth, elevation), Vec3::Y);
    }
    // Seed runtime table: 0.1°–5°, the real sun is about 0.53°.
    let mut diameter = light.angular_diameter.to_degrees();
    if ui
        .add(Slider::new(&mut diameter, 0.1..=5.0).text("angular diameter °"))
        .on_hover_text("Size of the sun disc; sets the PCSS penumbra width.")
        .changed()
    {
        light.angular_diameter = diameter.to_radians();
    }
    let mut enabled = light.shadows_enabled;
    if ui.checkbox(&mut enabled, "casts shadows").changed() {
        light.shadows_enabled = enabled;
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sun_angles_round_trip() {
        for (a, e) in [(30.0, 45.0), (-120.0, 10.0), (0.0, 89.0)] {
            let (a2, e2) = sun_angles(sun_direction(a, e));
            assert!((a - a2).abs() < 1e-3 && (e - e2).abs() < 1e-3, "{a} {e} -> {a2} {e2}");
        }
    }
}
