//! The shadow bind group (group 3), described once: every binding's name, what it holds and
//! its type. Binding numbers are positions in [`bindings`]; the renderer builds the group's
//! layout and its bind groups from this list, and the shader library declares the WGSL
//! module `penumbra::shadows::bindings` from it ([`wgsl`]), so neither side numbers a binding
//! by hand. A storage added to [`ShadowStorage::ALL`] gets its bindings here with no edit.

use std::fmt::Write;

use crate::layout::{ShadowStorage, StorageMoments};

/// What one binding of the shadow group holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Slot {
    /// The frame's first `MAX_LIGHTS` lights (a uniform array: read through the constant
    /// cache, faster per pixel than a storage buffer on the GPUs measured).
    Lights,
    /// The shadow views (a uniform array).
    Views,
    /// The comparison sampler: 1 where the reference depth is ≥ the stored depth (reverse-Z:
    /// the receiver is at least as close to the light as the nearest caster).
    CompareSampler,
    /// The nearest-neighbour sampler for raw depth reads (PCSS blocker search).
    PointSampler,
    /// [`CompareSampler`](Slot::CompareSampler) repeating at the layer's edges: for a clipmap
    /// level whose layer wraps (its window's texels kept where they are as it moves).
    WrapCompareSampler,
    /// [`PointSampler`](Slot::PointSampler) repeating at the layer's edges.
    WrapPointSampler,
    /// The bilinear sampler that filters the moments (trilinear over a sun's mips).
    MomentsSampler,
    /// The Poisson tap patterns.
    PoissonTaps,
    /// Each resolved light's visibility per pixel, written by the compute resolve before the
    /// lighting pass (a 1×1 stand-in when nothing is resolved).
    Resolved,
    /// A storage's depth array.
    Maps(ShadowStorage),
    /// A storage's moments (1×1 stand-ins while no light of it filters moments).
    Moments(ShadowStorage),
    /// The lights past the first `MAX_LIGHTS` (a storage buffer that grows with the scene);
    /// declared only in the variants of frames with more lights than that.
    MoreLights,
    /// A paged storage's page table: per level and table entry, the physical page holding
    /// it (a stand-in entry while no light is paged).
    PageTable(ShadowStorage),
}

/// A binding's type, as WGSL declares it and wgpu lays it out.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BindingKind {
    /// `var<uniform>` of the struct named.
    Uniform(&'static str),
    /// `var<storage, read>` array of the struct named.
    StorageArray(&'static str),
    /// `texture_depth_2d_array`.
    DepthArray,
    /// `texture_depth_cube_array`.
    DepthCubeArray,
    /// `texture_2d_array<f32>`, filterable.
    FloatArray,
    /// `texture_2d_array<f32>`, not filterable (`R32Float`).
    UnfilterableFloatArray,
    /// `texture_cube_array<f32>`, filterable.
    FloatCubeArray,
    /// `sampler_comparison`.
    CompareSampler,
    /// `sampler`, non-filtering.
    NearestSampler,
    /// `sampler`, filtering.
    FilterSampler,
}

/// One binding of the shadow group.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowBinding {
    /// What it holds.
    pub slot: Slot,
    /// Its WGSL name.
    pub name: &'static str,
    /// Its type.
    pub kind: BindingKind,
    /// The shader def it is declared under, if any.
    pub define: Option<&'static str>,
}

impl Slot {
    /// The binding's WGSL name.
    pub fn name(self) -> &'static str {
        match self {
            Slot::Lights => "lights",
            Slot::Views => "shadow_views",
            Slot::CompareSampler => "shadow_compare",
            Slot::PointSampler => "shadow_point",
            Slot::WrapCompareSampler => "shadow_compare_wrap",
            Slot::WrapPointSampler => "shadow_point_wrap",
            Slot::MomentsSampler => "moments_sampler",
            Slot::PoissonTaps => "poisson_taps",
            Slot::Resolved => "resolved_visibility",
            Slot::Maps(storage) => storage.desc().maps_binding,
            Slot::Moments(storage) => storage.desc().moments_binding,
            Slot::MoreLights => "more_lights",
            Slot::PageTable(_) => "page_table",
        }
    }

    /// The binding's type.
    pub fn kind(self) -> BindingKind {
        match self {
            Slot::Lights => BindingKind::Uniform("LightList"),
            Slot::Views => BindingKind::Uniform("ShadowViewList"),
            Slot::CompareSampler | Slot::WrapCompareSampler => BindingKind::CompareSampler,
            Slot::PointSampler | Slot::WrapPointSampler => BindingKind::NearestSampler,
            Slot::MomentsSampler => BindingKind::FilterSampler,
            Slot::PoissonTaps => BindingKind::Uniform("PoissonTaps"),
            Slot::Resolved => BindingKind::UnfilterableFloatArray,
            Slot::Maps(storage) if storage.desc().cube => BindingKind::DepthCubeArray,
            Slot::Maps(_) => BindingKind::DepthArray,
            Slot::Moments(storage) if storage.desc().cube => BindingKind::FloatCubeArray,
            Slot::Moments(_) => BindingKind::FloatArray,
            Slot::MoreLights => BindingKind::StorageArray("Light"),
            Slot::PageTable(_) => BindingKind::StorageArray("PageEntry"),
        }
    }

    /// Its comment in the generated WGSL.
    fn doc(self) -> &'static str {
        match self {
            Slot::Lights => "The frame's first MAX_LIGHTS lights (read through the constant cache).",
            Slot::Views => "The shadow views.",
            Slot::CompareSampler => {
                "Comparison sampler: 1 where the reference depth is >= the stored depth (reverse-Z)."
            }
            Slot::PointSampler => "Nearest-neighbour sampler for raw depth reads (PCSS blocker search).",
            Slot::WrapCompareSampler => "The comparison sampler, repeating at the edges (a wrapping clipmap layer).",
            Slot::WrapPointSampler => {
                "The nearest-neighbour sampler, repeating at the edges (a wrapping clipmap layer)."
            }
            Slot::MomentsSampler => "Bilinear sampler of the moments (trilinear over a sun's mips).",
            Slot::PoissonTaps => "The Poisson tap patterns.",
            Slot::Resolved => {
                "Each resolved light's visibility per pixel (layer `Light::resolve_layer`); 1x1 when nothing is resolved."
            }
            Slot::Maps(storage) => storage.desc().doc,
            Slot::Moments(_) => "Moments of the storage above (1x1 while none of its lights filters moments).",
            Slot::MoreLights => "The lights past the first MAX_LIGHTS (`frame.light_count` in all).",
            Slot::PageTable(_) => "The page table of the storage above: level l's entry e at l * entries + e.",
        }
    }

    fn define(self) -> Option<&'static str> {
        match self {
            Slot::MoreLights => Some("MANY_LIGHTS"),
            _ => None,
        }
    }
}

/// The bindings that do not belong to a storage, before the storages' own.
const COMMON: [Slot; 9] = [
    Slot::Lights,
    Slot::Views,
    Slot::CompareSampler,
    Slot::PointSampler,
    Slot::WrapCompareSampler,
    Slot::WrapPointSampler,
    Slot::MomentsSampler,
    Slot::PoissonTaps,
    Slot::Resolved,
];

/// Every binding of the shadow group; binding `i` is element `i`.
pub fn bindings() -> impl Iterator<Item = ShadowBinding> {
    let storages = ShadowStorage::ALL.into_iter().flat_map(|s| {
        let moments = (s.desc().moments != StorageMoments::None).then_some(Slot::Moments(s));
        let table = s.desc().paged.then_some(Slot::PageTable(s));
        [Slot::Maps(s)].into_iter().chain(moments).chain(table)
    });
    COMMON
        .into_iter()
        .chain(storages)
        .chain([Slot::MoreLights])
        .map(|slot| ShadowBinding {
            slot,
            name: slot.name(),
            kind: slot.kind(),
            define: slot.define(),
        })
}

/// The binding number of `slot`.
pub fn binding(slot: Slot) -> u32 {
    let index = bindings().position(|b| b.slot == slot);
    index.expect("every slot is listed") as u32
}

/// Structs the generated module imports from `penumbra::shadows::types`.
const IMPORTED_TYPES: &str = "Light, LightList, PageEntry, PoissonTaps, ShadowViewList";

/// The WGSL module `penumbra::shadows::bindings`: one declaration per binding, in order.
pub fn wgsl() -> String {
    let mut out = String::from(
        "// Generated from `penumbra::layout::group` (the shadow bind group, group 3): edit the Rust list,\n\
         // not this text. A material does not name these; it calls `penumbra::lights`.\n\
         #define_import_path penumbra::shadows::bindings\n\n",
    );
    let _ = writeln!(out, "#import penumbra::shadows::types::{{{IMPORTED_TYPES}}}\n");
    for (i, b) in bindings().enumerate() {
        if let Some(define) = b.define {
            let _ = writeln!(out, "#ifdef {define}");
        }
        let _ = writeln!(out, "// {}", b.slot.doc());
        let (space, ty) = wgsl_type(b.kind);
        let _ = writeln!(out, "@group(3) @binding({i}) var{space} {}: {ty};", b.name);
        if b.define.is_some() {
            let _ = writeln!(out, "#endif");
        }
    }
    out
}

/// The address space (with its `<>`, or empty) and type WGSL declares a binding of `kind` with.
fn wgsl_type(kind: BindingKind) -> (&'static str, String) {
    match kind {
        BindingKind::Uniform(ty) => ("<uniform>", ty.to_string()),
        BindingKind::StorageArray(ty) => ("<storage, read>", format!("array<{ty}>")),
        BindingKind::DepthArray => ("", "texture_depth_2d_array".into()),
        BindingKind::DepthCubeArray => ("", "texture_depth_cube_array".into()),
        BindingKind::FloatArray | BindingKind::UnfilterableFloatArray => ("", "texture_2d_array<f32>".into()),
        BindingKind::FloatCubeArray => ("", "texture_cube_array<f32>".into()),
        BindingKind::CompareSampler => ("", "sampler_comparison".into()),
        BindingKind::NearestSampler | BindingKind::FilterSampler => ("", "sampler".into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_binding_has_a_unique_name_and_number() {
        let all: Vec<_> = bindings().collect();
        for (i, b) in all.iter().enumerate() {
            assert_eq!(binding(b.slot), i as u32, "{}", b.name);
            assert_eq!(all.iter().filter(|o| o.name == b.name).count(), 1, "{}", b.name);
        }
        let tables = ShadowStorage::ALL.iter().filter(|s| s.desc().paged).count();
        let moments = ShadowStorage::ALL
            .iter()
            .filter(|s| s.desc().moments != StorageMoments::None)
            .count();
        assert_eq!(all.len(), COMMON.len() + ShadowStorage::COUNT + moments + tables + 1);
    }

    #[test]
    fn the_generated_module_declares_each_binding_at_its_number() {
        let text = wgsl();
        for (i, b) in bindings().enumerate() {
            let line = text
                .lines()
                .find(|l| l.contains(&format!(" {}: ", b.name)))
                .unwrap_or_else(|| panic!("{} is not declared:\n{text}", b.name));
            assert!(line.starts_with(&format!("@group(3) @binding({i}) var")), "{line}");
        }
        assert!(text.contains("#ifdef MANY_LIGHTS\n"), "{text}");
    }
}
