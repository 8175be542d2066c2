//! The per-light panels: one collapsible panel per spot light, per point light and per
//! directional light after the first (the first is the "Sun" and "Shadows" sections), with
//! every parameter live — placement, colour and intensity, range, cone angles, emitter
//! radius, the shadow switch — and the light's own shadow filter (PCF, PCSS or VSM with its
//! blur and bleed reduction), resolution and biases.

use bevy_ecs::entity::Entity;
use bevy_ecs::query::With;
use bevy_ecs::world::World;
use bevy_transform::components::Transform;
use egui::{CollapsingHeader, DragValue, Slider, Ui};
use glam::Vec3;

use crate::ecs::components::DirectionalLight;
use crate::ecs::lights::{PointLight, SpotLight};
use crate::ecs::view_list::ShadowLightBudget;
use crate::math::spot::MAX_SPOT_HALF_ANGLE;
use crate::settings::ShadowSettings;
use crate::viewer::inspector::settings::{bias_ui, debug_view_ui, filter_ui, resolution_ui, settings_ui};
use crate::viewer::inspector::sun::{sun_angles, sun_direction};

/// Draws a panel per spot light, point light and extra directional light; returns how many.
pub(crate) fn lights_ui(ui: &mut Ui, world: &mut World) -> usize {
    let suns: Vec<Entity> = world
        .query_filtered::<Entity, With<DirectionalLight>>()
        .iter(world)
        .skip(1)
        .collect();
    let spots: Vec<Entity> = world.query_filtered::<Entity, With<SpotLight>>().iter(world).collect();
    let points: Vec<Entity> = world.query_filtered::<Entity, With<PointLight>>().iter(world).collect();
    for (k, &entity) in suns.iter().enumerate() {
        CollapsingHeader::new(format!("directional light {}", k + 1))
            .id_salt(entity)
            .default_open(false)
            .show(ui, |ui| directional_ui(ui, world, entity));
    }
    for (k, &entity) in spots.iter().enumerate() {
        CollapsingHeader::new(format!("spot light {k}"))
            .id_salt(entity)
            .default_open(false)
            .show(ui, |ui| spot_ui(ui, world, entity));
    }
    for (k, &entity) in points.iter().enumerate() {
        CollapsingHeader::new(format!("point light {k}"))
            .id_salt(entity)
            .default_open(false)
            .show(ui, |ui| point_ui(ui, world, entity));
    }
    suns.len() + spots.len() + points.len()
}

/// A directional light after the first: aim, brightness, disc size, shadows and its
/// settings.
fn directional_ui(ui: &mut Ui, world: &mut World, entity: Entity) {
    let Ok(mut e) = world.get_entity_mut(entity) else {
        return;
    };
    if let Some(mut transform) = e.get_mut::<Transform>() {
        let mut aimed = *transform;
        aim_ui(ui, &mut aimed, -5.0..=90.0);
        if aimed != *transform {
            *transform = aimed;
        }
    }
    if let Some(mut light) = e.get_mut::<DirectionalLight>() {
        let mut edited = *light;
        ui.add(Slider::new(&mut edited.illuminance, 0.0..=10.0).text("illuminance"));
        let mut diameter = edited.angular_diameter.to_degrees();
        ui.add(Slider::new(&mut diameter, 0.1..=5.0).text("angular diameter °"));
        edited.angular_diameter = diameter.to_radians();
        ui.checkbox(&mut edited.shadows_enabled, "casts shadows");
        if edited != *light {
            *light = edited;
        }
    }
    let mut settings = e.get::<ShadowSettings>().copied().unwrap_or_default();
    let before = settings;
    settings_ui(ui, &mut settings);
    if settings != before {
        e.insert(settings);
    }
}

/// A spot light: position and aim, colour, intensity, range, cones, radius, shadows, and its
/// shadow filter, resolution and biases (a light without settings gets them on first edit,
/// at the budget's spot resolution).
fn spot_ui(ui: &mut Ui, world: &mut World, entity: Entity) {
    let default_resolution = world.resource::<ShadowLightBudget>().spot_resolution;
    let Ok(mut e) = world.get_entity_mut(entity) else {
        return;
    };
    if let Some(mut transform) = e.get_mut::<Transform>() {
        let mut edited = *transform;
        position_ui(ui, &mut edited);
        aim_ui(ui, &mut edited, -90.0..=90.0);
        if edited != *transform {
            *transform = edited;
        }
    }
    if let Some(mut light) = e.get_mut::<SpotLight>() {
        let mut edited = *light;
        emitter_ui(ui, &mut edited.color, &mut edited.intensity, &mut edited.range);
        let mut outer = edited.outer_angle.to_degrees();
        let mut inner = edited.inner_angle.to_degrees();
        ui.add(Slider::new(&mut outer, 1.0..=MAX_SPOT_HALF_ANGLE.to_degrees()).text("outer angle °"));
        ui.add(Slider::new(&mut inner, 0.0..=outer).text("inner angle °"));
        edited.outer_angle = outer.to_radians();
        edited.inner_angle = inner.min(outer).to_radians();
        ui.add(Slider::new(&mut edited.radius, 0.0..=1.0).text("radius m"))
            .on_hover_text("Size of the emitter; sets the PCSS penumbra width.");
        ui.checkbox(&mut edited.shadows_enabled, "casts shadows");
        if edited != *light {
            *light = edited;
        }
    }
    positional_settings_ui(ui, &mut e, default_resolution);
}

/// A point light: position, colour, intensity, range, radius, shadows, and its shadow filter,
/// face resolution and biases (a light without settings gets them on first edit, at the
/// budget's point resolution).
fn point_ui(ui: &mut Ui, world: &mut World, entity: Entity) {
    let default_resolution = world.resource::<ShadowLightBudget>().point_resolution;
    let Ok(mut e) = world.get_entity_mut(entity) else {
        return;
    };
    if let Some(mut transform) = e.get_mut::<Transform>() {
        let mut edited = *transform;
        position_ui(ui, &mut edited);
        if edited != *transform {
            *transform = edited;
        }
    }
    if let Some(mut light) = e.get_mut::<PointLight>() {
        let mut edited = *light;
        emitter_ui(ui, &mut edited.color, &mut edited.intensity, &mut edited.range);
        ui.add(Slider::new(&mut edited.radius, 0.0..=1.0).text("radius m"))
            .on_hover_text("Size of the emitter; sets the PCSS penumbra width.");
        ui.checkbox(&mut edited.shadows_enabled, "casts shadows");
        if edited != *light {
            *light = edited;
        }
    }
    positional_settings_ui(ui, &mut e, default_resolution);
    ui.label("Point lights share one cube size: the largest any shadowed one asks for.");
}

/// Position drag values.
fn position_ui(ui: &mut Ui, transform: &mut Transform) {
    ui.horizontal(|ui| {
        ui.label("position m");
        for (axis, name) in ["x", "y", "z"].into_iter().enumerate() {
            let label = ui.label(name);
            ui.add(DragValue::new(&mut transform.translation[axis]).speed(0.05))
                .labelled_by(label.id);
        }
    });
}

/// Colour, intensity and range of a positional light.
fn emitter_ui(ui: &mut Ui, color: &mut Vec3, intensity: &mut f32, range: &mut f32) {
    ui.horizontal(|ui| {
        ui.label("colour");
        let mut rgb = color.to_array();
        ui.color_edit_button_rgb(&mut rgb);
        *color = Vec3::from_array(rgb);
    });
    ui.add(Slider::new(intensity, 0.0..=1000.0).logarithmic(true).text("intensity"));
    ui.add(Slider::new(range, 0.1..=200.0).logarithmic(true).text("range m"));
}

/// A positional light's own shadow settings (filter with VSM, resolution, biases), inserted
/// on first edit with `default_resolution`.
fn positional_settings_ui(ui: &mut Ui, e: &mut bevy_ecs::world::EntityWorldMut<'_>, default_resolution: u32) {
    let mut settings = e
        .get::<ShadowSettings>()
        .copied()
        .unwrap_or(ShadowSettings::with_resolution(default_resolution));
    let before = settings;
    filter_ui(ui, &mut settings, false);
    resolution_ui(ui, &mut settings);
    bias_ui(ui, &mut settings);
    debug_view_ui(ui, &mut settings.filter.debug_view);
    if settings != before {
        e.insert(settings);
    }
}

/// Azimuth and elevation sliders for a transform's forward (−Z) axis, keeping its position.
fn aim_ui(ui: &mut Ui, transform: &mut Transform, elevation: std::ops::RangeInclusive<f32>) {
    let (mut azimuth, mut elev) = sun_angles(transform.rotation * Vec3::NEG_Z);
    let mut turned = ui
        .add(Slider::new(&mut azimuth, -180.0..=180.0).text("azimuth °"))
        .changed();
    turned |= ui.add(Slider::new(&mut elev, elevation).text("elevation °")).changed();
    if turned {
        let direction = sun_direction(azimuth, elev);
        let up = if direction.cross(Vec3::Y).length_squared() < 1e-6 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        *transform = transform.looking_to(direction, up);
    }
}
