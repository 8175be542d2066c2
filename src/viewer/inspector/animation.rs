//! The animation section: play or pause every [`AnimationPlayer`] and set their speed, shown
//! while the world has skinned, animated meshes.

use bevy_ecs::world::World;
use egui::{Slider, Ui};

use crate::ecs::skinning::AnimationPlayer;

/// Draws the controls over every player of `world`; nothing without players.
pub(crate) fn animation_ui(ui: &mut Ui, world: &mut World) {
    let mut players = world.query::<&mut AnimationPlayer>();
    let Some(first) = players.iter(world).next().copied() else {
        ui.label("no animated meshes");
        return;
    };
    let count = players.iter(world).count();
    let mut playing = !first.paused;
    let mut speed = first.speed;
    let toggled = ui
        .checkbox(&mut playing, format!("play ({count} animated meshes)"))
        .changed();
    let sped = ui
        .add(Slider::new(&mut speed, 0.0..=3.0).text("animation speed"))
        .changed();
    if toggled || sped {
        for mut p in players.iter_mut(world) {
            p.paused = !playing;
            p.speed = speed;
        }
    }
}
