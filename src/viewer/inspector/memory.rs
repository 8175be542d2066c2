//! The shadow-memory section: the budget (a slider, in MiB) and this frame's account — the
//! total and what it is made of, then each shadowed light's layers, side and bytes, with the
//! lights the budget lowered or left without a shadow.

use bevy_ecs::world::World;
use egui::{Color32, Slider, Ui};

use crate::ecs::shadow_memory::{MIB, ShadowMemory, ShadowMemoryBudget};

/// Smallest budget the slider offers, MiB.
const MIN_MIB: u64 = 1;
/// Largest budget the slider offers, MiB (16 GiB).
const MAX_MIB: u64 = 16 * 1024;

/// Draws the budget slider (writing the resource only when it moves) and the account.
pub(crate) fn memory_ui(ui: &mut Ui, world: &mut World) {
    if let Some(mut budget) = world.get_resource_mut::<ShadowMemoryBudget>() {
        let mut mib = (budget.bytes / MIB).clamp(MIN_MIB, MAX_MIB);
        let slider = Slider::new(&mut mib, MIN_MIB..=MAX_MIB)
            .logarithmic(true)
            .text("budget MiB");
        let changed = ui
            .add(slider)
            .on_hover_text("most memory of shadow maps, moments and blur scratch; the lights smallest on screen are lowered to fit")
            .changed();
        if changed {
            budget.bytes = mib * MIB;
        }
    }
    let Some(memory) = world.get_resource::<ShadowMemory>() else {
        return;
    };
    let lines = memory.lines();
    ui.label(&lines[0]);
    for line in &lines[1..] {
        ui.label(line);
    }
    if let Some(error) = &memory.error {
        ui.colored_label(Color32::from_rgb(255, 110, 100), error);
    }
}
