//! The constants Rust and WGSL share, written once: the WGSL module `penumbra::contract` is
//! generated from [`CONSTANTS`] ([`wgsl`]), and every shader imports them from it, so a flag
//! bit, a technique id or a list capacity cannot differ between the two sides. The test in
//! `tests/contract.rs` reads them back from naga's view of the composed shaders.

use std::fmt::Write;

use crate::math::shadow_memory::MOMENT_MIPS;

/// Lights in the uniform light list; the rest go to a storage buffer that grows with the
/// scene.
pub const MAX_LIGHTS: u32 = 256;
/// Capacity of the shadow-view list (a uniform array).
pub const MAX_SHADOW_VIEWS: u32 = 256;
/// `Light::kind` of a directional light.
pub const LIGHT_DIRECTIONAL: u32 = 0;
/// `Light::kind` of a spot light.
pub const LIGHT_SPOT: u32 = 1;
/// `Light::kind` of a point light.
pub const LIGHT_POINT: u32 = 2;
/// `Light::shadow_filter`: PCF.
pub const SHADOW_FILTER_PCF: u32 = 0;
/// `Light::shadow_filter`: PCSS.
pub const SHADOW_FILTER_PCSS: u32 = 1;
/// `Light::shadow_filter`: variance shadow map (spot and point lights).
pub const SHADOW_FILTER_VSM: u32 = 2;
/// `Light::shadow_filter`: EVSM2 from the cascades' moments (suns).
pub const SHADOW_FILTER_EVSM2: u32 = 3;
/// `Light::shadow_filter`: EVSM4 from the cascades' moments (suns).
pub const SHADOW_FILTER_EVSM4: u32 = 4;
/// `Light::shadow_filter`: 4-moment shadow map from the cascades' moments (suns).
pub const SHADOW_FILTER_MSM: u32 = 5;
/// `Light::flags`: PCSS blocker early-out.
pub const SHADOW_FLAG_BLOCKER_EARLY_OUT: u32 = 2;
/// `Light::flags`: receiver-plane depth bias.
pub const SHADOW_FLAG_RECEIVER_PLANE: u32 = 4;
/// `Light::flags`: temporal rotation of the Poisson patterns.
pub const SHADOW_FLAG_TEMPORAL: u32 = 8;
/// `Light::flags`: contact hardening of a sun's moment shadows (mipmapped moments).
pub const SHADOW_FLAG_MOMENT_HARDENING: u32 = 16;
/// `Light::flags`: the sun's views are clipmap levels (chosen by light-frame position).
pub const SHADOW_FLAG_CLIPMAP: u32 = 32;
/// `Light::flags`: the sun's clipmap levels are paged (read through `page_table`).
pub const SHADOW_FLAG_PAGED: u32 = 64;
/// `Light::flags`: the light's resolved layer holds its contact shadows alone (the lighting
/// pass filters the shadow maps itself and multiplies them in).
pub const SHADOW_FLAG_CONTACT_ONLY: u32 = 128;
/// `PageEntry::physical` of an entry holding no page.
pub const PAGE_NONE: u32 = u32::MAX;
/// `Light::resolve_layer` of a light filtered in the lighting pass (no resolved layer).
pub const RESOLVE_NONE: u32 = u32::MAX;
/// `Instance::flags`: the instance receives shadows.
pub const INSTANCE_FLAG_RECEIVE_SHADOWS: u32 = 1;
/// `Instance::flags`: the instance's material is opaque and has no texture, so the prepass's
/// pixels of it can be lit without drawing it again ([`crate::render::deferred`]).
pub const INSTANCE_FLAG_UNTEXTURED: u32 = 2;
/// What the prepass writes into the camera's shading ids where the pixel's surface is not
/// lit from them (it is drawn again by the forward pass).
pub const SHADING_ID_NONE: u32 = u32::MAX;
/// Bits of a single-pass caster entry below its cascade mask: the instance index.
pub const CASCADE_MASK_SHIFT: u32 = 28;
/// Largest PCSS kernel radius, in texels: bounds the cost where layered casters make the
/// average blocker depth far from the receiver.
pub const MAX_PENUMBRA_TEXELS: f32 = 32.0;

// NOTE: the last mip of a sun's moments averages the widest penumbra filter's diameter.
const _: () = assert!(1 << (MOMENT_MIPS - 1) == 2 * MAX_PENUMBRA_TEXELS as u32);

/// A shared constant's value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    /// A `u32`.
    U32(u32),
    /// An `f32`.
    F32(f32),
}

/// Every shared constant: its name (the same in Rust and WGSL) and value.
pub const CONSTANTS: [(&str, Value); 26] = [
    ("MAX_LIGHTS", Value::U32(MAX_LIGHTS)),
    ("MAX_SHADOW_VIEWS", Value::U32(MAX_SHADOW_VIEWS)),
    ("LIGHT_DIRECTIONAL", Value::U32(LIGHT_DIRECTIONAL)),
    ("LIGHT_SPOT", Value::U32(LIGHT_SPOT)),
    ("LIGHT_POINT", Value::U32(LIGHT_POINT)),
    ("SHADOW_FILTER_PCF", Value::U32(SHADOW_FILTER_PCF)),
    ("SHADOW_FILTER_PCSS", Value::U32(SHADOW_FILTER_PCSS)),
    ("SHADOW_FILTER_VSM", Value::U32(SHADOW_FILTER_VSM)),
    ("SHADOW_FILTER_EVSM2", Value::U32(SHADOW_FILTER_EVSM2)),
    ("SHADOW_FILTER_EVSM4", Value::U32(SHADOW_FILTER_EVSM4)),
    ("SHADOW_FILTER_MSM", Value::U32(SHADOW_FILTER_MSM)),
    (
        "SHADOW_FLAG_BLOCKER_EARLY_OUT",
        Value::U32(SHADOW_FLAG_BLOCKER_EARLY_OUT),
    ),
    ("SHADOW_FLAG_RECEIVER_PLANE", Value::U32(SHADOW_FLAG_RECEIVER_PLANE)),
    ("SHADOW_FLAG_TEMPORAL", Value::U32(SHADOW_FLAG_TEMPORAL)),
    ("SHADOW_FLAG_MOMENT_HARDENING", Value::U32(SHADOW_FLAG_MOMENT_HARDENING)),
    ("SHADOW_FLAG_CLIPMAP", Value::U32(SHADOW_FLAG_CLIPMAP)),
    ("SHADOW_FLAG_PAGED", Value::U32(SHADOW_FLAG_PAGED)),
    ("SHADOW_FLAG_CONTACT_ONLY", Value::U32(SHADOW_FLAG_CONTACT_ONLY)),
    ("PAGE_NONE", Value::U32(PAGE_NONE)),
    ("RESOLVE_NONE", Value::U32(RESOLVE_NONE)),
    (
        "INSTANCE_FLAG_RECEIVE_SHADOWS",
        Value::U32(INSTANCE_FLAG_RECEIVE_SHADOWS),
    ),
    ("INSTANCE_FLAG_UNTEXTURED", Value::U32(INSTANCE_FLAG_UNTEXTURED)),
    ("SHADING_ID_NONE", Value::U32(SHADING_ID_NONE)),
    ("CASCADE_MASK_SHIFT", Value::U32(CASCADE_MASK_SHIFT)),
    ("MAX_PENUMBRA_TEXELS", Value::F32(MAX_PENUMBRA_TEXELS)),
    ("MOMENT_MIPS", Value::U32(MOMENT_MIPS)),
];

/// The WGSL module `penumbra::contract`: one `const` per entry of [`CONSTANTS`].
pub fn wgsl() -> String {
    let mut out = String::from(
        "// Generated from `penumbra::shader::contract`: the constants Rust and WGSL share. Edit the\n\
         // Rust list, not this text.\n\
         #define_import_path penumbra::contract\n\n",
    );
    for (name, value) in CONSTANTS {
        let _ = match value {
            Value::U32(v) => writeln!(out, "const {name}: u32 = {v}u;"),
            Value::F32(v) => writeln!(out, "const {name}: f32 = {v:?};"),
        };
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_generated_module_declares_every_constant_once() {
        let text = wgsl();
        for (name, _) in CONSTANTS {
            assert_eq!(text.matches(&format!("const {name}:")).count(), 1, "{name}:\n{text}");
        }
        assert!(text.contains("const RESOLVE_NONE: u32 = 4294967295u;"), "{text}");
        assert!(text.contains("const MAX_PENUMBRA_TEXELS: f32 = 32.0;"), "{text}");
    }
}
