//! Rust and WGSL agree on the shadow bind group and on every shared constant: read back from
//! naga's view of the composed shaders (forward, resolve, probe), each group-3 global sits at
//! the binding the Rust list gives its name, with a type the Rust layout entry accepts; every
//! shared constant found in them has the Rust value; and no shipped WGSL file declares a
//! shared constant itself.

use std::collections::BTreeSet;

use penumbra::layout::group::bindings;
use penumbra::render::layouts::shadow_binding_type;
use penumbra::shader::contract::{CONSTANTS, Value};
use penumbra::shader::{ForwardVariant, ShaderLibrary};

/// The name a composed module gives an item, without naga_oil's module suffix.
fn plain(name: &str) -> &str {
    name.split("X_naga_oil_mod_").next().unwrap_or(name)
}

/// The composed shaders that bind group 3: every forward variant with spot, point and
/// moment shadows and the many-lights list (the widest bindings), the compute resolve and
/// the probe of each filter.
fn shaders() -> Vec<(String, naga::Module)> {
    let mut library = ShaderLibrary::new().expect("shared modules compose");
    let mut out = Vec::new();
    for variant in ForwardVariant::all() {
        let wide = variant.spot_shadows && variant.point_shadows && variant.sun_moments && !variant.analysis;
        if !wide || variant.alpha_mask || variant.transmission {
            continue;
        }
        let module = library.forward(variant).expect("forward composes");
        out.push((format!("forward {}", variant.label()), module));
        if !variant.debug_cascades {
            out.push((
                format!("resolve {}", variant.label()),
                library.resolve(variant).expect("resolve composes"),
            ));
            out.push((
                format!("probe {}", variant.label()),
                library.probe(variant).expect("probe composes"),
            ));
        }
    }
    out
}

/// Whether the layout entry `ty` accepts the WGSL global `var` of `module`.
fn accepts(module: &naga::Module, var: &naga::GlobalVariable, ty: wgpu::BindingType) -> bool {
    use naga::{AddressSpace, ImageClass, ImageDimension, TypeInner};
    match (var.space, &module.types[var.ty].inner, ty) {
        (AddressSpace::Uniform, _, wgpu::BindingType::Buffer { ty, .. }) => ty == wgpu::BufferBindingType::Uniform,
        (AddressSpace::Storage { .. }, _, wgpu::BindingType::Buffer { ty, .. }) => {
            ty == wgpu::BufferBindingType::Storage { read_only: true }
        }
        (
            AddressSpace::Handle,
            TypeInner::Image { dim, arrayed, class },
            wgpu::BindingType::Texture {
                sample_type,
                view_dimension,
                multisampled,
            },
        ) => {
            let dimension = match (dim, arrayed) {
                (ImageDimension::D2, true) => wgpu::TextureViewDimension::D2Array,
                (ImageDimension::Cube, true) => wgpu::TextureViewDimension::CubeArray,
                (ImageDimension::D2, false) => wgpu::TextureViewDimension::D2,
                _ => return false,
            };
            let class_ok = match (class, sample_type) {
                (ImageClass::Depth { multi }, wgpu::TextureSampleType::Depth) => *multi == multisampled,
                (
                    ImageClass::Sampled {
                        kind: naga::ScalarKind::Float,
                        multi,
                    },
                    wgpu::TextureSampleType::Float { .. },
                ) => *multi == multisampled,
                _ => false,
            };
            class_ok && dimension == view_dimension
        }
        (AddressSpace::Handle, TypeInner::Sampler { comparison }, wgpu::BindingType::Sampler(kind)) => {
            *comparison == (kind == wgpu::SamplerBindingType::Comparison)
        }
        _ => false,
    }
}

#[test]
fn every_group_3_binding_in_wgsl_is_where_and_what_rust_lays_out() {
    let table: Vec<_> = bindings().collect();
    let mut seen = BTreeSet::new();
    let shaders = shaders();
    for (label, module) in &shaders {
        for (_, var) in module.global_variables.iter() {
            let Some(binding) = &var.binding else { continue };
            if binding.group != 3 {
                continue;
            }
            let name = plain(var.name.as_deref().unwrap_or(""));
            let (number, rust) = table
                .iter()
                .enumerate()
                .find(|(_, b)| b.name == name)
                .unwrap_or_else(|| panic!("{label}: group 3 binding `{name}` is not in the Rust list"));
            assert_eq!(binding.binding, number as u32, "{label}: `{name}`'s binding number");
            let ty = shadow_binding_type(rust.slot, rust.kind);
            assert!(
                accepts(module, var, ty),
                "{label}: `{name}` in WGSL is not what the layout entry {ty:?} accepts"
            );
            seen.insert(name.to_string());
        }
    }
    let missing: Vec<_> = table
        .iter()
        .filter(|b| !seen.contains(b.name))
        .map(|b| b.name)
        .collect();
    assert!(missing.is_empty(), "bindings no composed shader declares: {missing:?}");
    println!("{} bindings checked in {} shaders", seen.len(), shaders.len());
    assert!(shaders.len() >= 12, "only {} shaders judged", shaders.len());
}

/// The value of a constant whose initialiser is a literal.
fn literal(module: &naga::Module, constant: &naga::Constant) -> Option<Value> {
    match module.global_expressions[constant.init] {
        naga::Expression::Literal(naga::Literal::U32(v)) => Some(Value::U32(v)),
        naga::Expression::Literal(naga::Literal::F32(v)) => Some(Value::F32(v)),
        _ => None,
    }
}

#[test]
fn every_shared_constant_the_shaders_use_has_the_rust_value() {
    let mut library = ShaderLibrary::new().expect("shared modules compose");
    let mut modules = shaders();
    for multiview in [false, true] {
        modules.push(("caster".into(), library.caster(multiview).unwrap()));
    }
    for format in [wgpu::TextureFormat::Rgba32Float, wgpu::TextureFormat::Rgba16Float] {
        modules.push(("cascade moments".into(), library.cascade_moments(format).unwrap()));
    }
    modules.push(("prepass".into(), library.prepass().unwrap()));
    let mut seen = BTreeSet::new();
    for (label, module) in &modules {
        for (_, constant) in module.constants.iter() {
            let name = plain(constant.name.as_deref().unwrap_or(""));
            let Some((_, rust)) = CONSTANTS.iter().find(|(n, _)| *n == name) else {
                continue;
            };
            let wgsl = literal(module, constant);
            assert_eq!(wgsl, Some(*rust), "{label}: `{name}`");
            seen.insert(name.to_string());
        }
    }
    // NOTE: MOMENT_MIPS is Rust's only (a compile-time assertion ties it to
    // MAX_PENUMBRA_TEXELS); PCF is what a light without another filter code gets in WGSL.
    let rust_only = ["MOMENT_MIPS", "SHADOW_FILTER_PCF"];
    let unused: Vec<_> = CONSTANTS
        .iter()
        .map(|(n, _)| *n)
        .filter(|n| !seen.contains(*n) && !rust_only.contains(n))
        .collect();
    assert!(unused.is_empty(), "shared constants no shader reads: {unused:?}");
    println!("{} shared constants checked", seen.len());
}

#[test]
fn no_shipped_wgsl_file_declares_a_shared_constant() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut files = 0;
    let mut stack = vec![root];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            for (name, _) in CONSTANTS {
                let declared = text
                    .lines()
                    .any(|l| l.trim_start().starts_with(&format!("const {name}:")));
                assert!(
                    !declared,
                    "{} declares `{name}`: import it from penumbra::contract",
                    path.display()
                );
            }
            files += 1;
        }
    }
    assert!(files >= 20, "only {files} WGSL files read");
}
