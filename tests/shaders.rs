//! Every WGSL variant composes with naga_oil and passes naga's validator.

use penumbra::layout::group::{Slot, binding};
use penumbra::shader::{ForwardVariant, ShaderLibrary};

#[test]
fn every_forward_variant_validates() {
    let mut library = ShaderLibrary::new().expect("shared modules compose");
    let variants = ForwardVariant::all();
    assert_eq!(
        variants.len(),
        768,
        "PCF and PCSS, each with and without spot shadows, point shadows, sun moments, debug view, transmission, analysis outputs and the lights past the uniform list, and opaque, alpha-masked or alpha-to-coverage"
    );
    let more_lights_binding = binding(Slot::MoreLights);
    let mut covered = 0;
    for variant in variants {
        let module = library
            .forward(variant)
            .unwrap_or_else(|e| panic!("{}: {e}", variant.label()));
        let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(entry_points, ["vs_main", "fs_main"], "{}", variant.label());
        // The storage list of the lights past the uniform one is bound only where asked for.
        let more_lights = module.global_variables.iter().any(|(_, g)| {
            g.binding
                .as_ref()
                .is_some_and(|b| (b.group, b.binding) == (3, more_lights_binding))
        });
        assert_eq!(more_lights, variant.many_lights, "{}", variant.label());
        // The alpha-to-coverage variants never discard; the alpha-tested ones do.
        let discards = has_kill(&module.entry_points[1].function);
        assert_eq!(
            discards,
            variant.alpha_mask && !variant.alpha_to_coverage,
            "{}",
            variant.label()
        );
        covered += variant.alpha_to_coverage as u32;
    }
    assert_eq!(covered, 256);
    // The transmission code is compiled in only when asked for.
    let base = ForwardVariant::all()[0];
    assert!(!base.transmission);
    let mut size = |v: ForwardVariant| {
        let module = library.forward(v).unwrap();
        let functions: usize = module.functions.iter().map(|(_, f)| f.expressions.len()).sum();
        functions + module.entry_points[1].function.expressions.len()
    };
    let without = size(base);
    let with = size(ForwardVariant {
        transmission: true,
        ..base
    });
    assert!(with > without + 10, "transmission adds {with} − {without} expressions");
}

#[test]
fn every_deferred_variant_validates_and_binds_only_its_groups() {
    let mut library = ShaderLibrary::new().expect("shared modules compose");
    // NOTE: the deferred pass lights opaque pixels of single-sample frames without analysis
    // outputs; every other axis of the forward variants applies.
    let variants: Vec<ForwardVariant> = ForwardVariant::all()
        .into_iter()
        .filter(|v| !v.alpha_mask && !v.alpha_to_coverage && !v.analysis)
        .collect();
    assert_eq!(
        variants.len(),
        128,
        "PCF and PCSS × spot × point × moments × debug × transmission × many lights"
    );
    for (variant, compute) in variants.into_iter().flat_map(|v| [(v, false), (v, true)]) {
        let module = library
            .deferred(variant, compute)
            .unwrap_or_else(|e| panic!("{}: {e}", variant.label()));
        let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
        let expected: &[&str] = if compute {
            &["vs_main", "fs_main", "main"]
        } else {
            &["vs_main", "fs_main"]
        };
        assert_eq!(entry_points, expected, "{}", variant.label());
        let mut bindings: Vec<(u32, u32)> = module
            .global_variables
            .iter()
            .filter_map(|(_, g)| g.binding.as_ref().map(|b| (b.group, b.binding)))
            .collect();
        let count = bindings.len();
        bindings.sort_unstable();
        bindings.dedup();
        assert_eq!(
            bindings.len(),
            count,
            "{}: two globals share a binding",
            variant.label()
        );
        // Group 2: depth, normals, shading ids and the instances, and for the compute entry
        // the target's storage view and the clear colour (group 1 at most declares the mesh
        // module's instances, unused).
        for group in [1, 2] {
            let slots: Vec<u32> = bindings.iter().filter(|b| b.0 == group).map(|b| b.1).collect();
            let expected: &[u32] = match (group, compute) {
                (1, _) => &[0, 1],
                (_, false) => &[0, 1, 2, 3],
                (_, true) => &[0, 1, 2, 3, 4, 5],
            };
            assert!(
                slots.iter().all(|s| expected.contains(s)),
                "{}: group {group} binds {slots:?}",
                variant.label()
            );
        }
        assert!(
            bindings.contains(&(2, 2)),
            "{}: the shading ids are read",
            variant.label()
        );
        assert!(
            bindings.contains(&(2, 3)),
            "{}: the instances are read",
            variant.label()
        );
    }
}

/// Whether `function` has a `discard` anywhere in its body.
fn has_kill(function: &naga::Function) -> bool {
    fn block(b: &naga::Block) -> bool {
        b.iter().any(|s| match s {
            naga::Statement::Kill => true,
            naga::Statement::Block(inner) => block(inner),
            naga::Statement::If { accept, reject, .. } => block(accept) || block(reject),
            naga::Statement::Loop { body, continuing, .. } => block(body) || block(continuing),
            naga::Statement::Switch { cases, .. } => cases.iter().any(|c| block(&c.body)),
            _ => false,
        })
    }
    block(&function.body)
}

#[test]
fn caster_shader_validates_with_both_entry_points_single_and_multiview() {
    let mut library = ShaderLibrary::new().unwrap();
    for multiview in [false, true] {
        let module = library.caster(multiview).unwrap_or_else(|e| panic!("{e}"));
        let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(entry_points, ["vs_main", "fs_masked"]);
        let view_index = module.entry_points[0]
            .function
            .arguments
            .iter()
            .any(|a| a.binding == Some(naga::Binding::BuiltIn(naga::BuiltIn::ViewIndex)));
        assert_eq!(view_index, multiview, "multiview {multiview}");
    }
}

#[test]
fn the_shadow_clear_shader_validates() {
    let mut library = ShaderLibrary::new().unwrap();
    let module = library.shadow_clear().unwrap_or_else(|e| panic!("{e}"));
    let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(entry_points, ["vs_main"]);
}

#[test]
fn the_clipmap_shift_shader_validates() {
    let mut library = ShaderLibrary::new().unwrap();
    let module = library.shadow_shift().unwrap_or_else(|e| panic!("{e}"));
    let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(entry_points, ["vs_main", "fs_main"]);
}

#[test]
fn the_page_marking_allocation_and_drawing_shaders_validate() {
    let mut library = ShaderLibrary::new().unwrap();
    let modules = [
        (library.pages_mark(false), &["main"][..]),
        (library.pages_mark(true), &["main"][..]),
        (library.pages_allocate(), &["main", "still", "invalidate"][..]),
    ];
    for (module, expected) in modules {
        let module = module.unwrap_or_else(|e| panic!("{e}"));
        let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(entry_points, expected);
    }
    for (cull, expected) in [
        (true, &["cull"][..]),
        (false, &["clear_vs", "caster_vs", "fs_masked"][..]),
    ] {
        let module = library
            .pages_render(cull)
            .unwrap_or_else(|e| panic!("cull {cull}: {e}"));
        let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(entry_points, expected);
    }
}

#[test]
fn the_depth_bounds_shader_validates_single_sample_and_multisampled() {
    let mut library = ShaderLibrary::new().unwrap();
    for multisampled in [false, true] {
        let module = library
            .depth_bounds(multisampled)
            .unwrap_or_else(|e| panic!("multisampled {multisampled}: {e}"));
        let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(entry_points, ["main"]);
    }
}

#[test]
fn the_moments_shader_validates_for_spot_and_point_lights_in_both_formats() {
    let mut library = ShaderLibrary::new().unwrap();
    for point in [false, true] {
        for fp32 in [false, true] {
            let module = library
                .shadow_moments(point, fp32)
                .unwrap_or_else(|e| panic!("point {point}, fp32 {fp32}: {e}"));
            let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
            assert_eq!(entry_points, ["resolve", "blur"]);
        }
    }
}

#[test]
fn the_cascade_and_page_moments_shaders_validate_in_every_moments_format() {
    let mut library = ShaderLibrary::new().unwrap();
    for format in [
        wgpu::TextureFormat::Rg32Float,
        wgpu::TextureFormat::Rgba32Float,
        wgpu::TextureFormat::Rgba16Unorm,
        wgpu::TextureFormat::Rgba16Float,
    ] {
        let module = library
            .cascade_moments(format)
            .unwrap_or_else(|e| panic!("{format:?}: {e}"));
        let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(entry_points, ["resolve", "blur", "downsample"]);
        let module = library
            .page_moments(format)
            .unwrap_or_else(|e| panic!("pages, {format:?}: {e}"));
        let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(entry_points, ["page_bake", "page_downsample"]);
    }
}

#[test]
fn the_resolve_shader_validates_for_every_filter_variant_and_sample_count() {
    let mut library = ShaderLibrary::new().unwrap();
    let mut composed = 0;
    for variant in ForwardVariant::all() {
        if variant.analysis || variant.alpha_mask || variant.debug_cascades {
            continue;
        }
        for samples in [1, 2, 4] {
            let module = library
                .resolve_multisampled(variant, samples)
                .unwrap_or_else(|e| panic!("{} at {samples} samples: {e}", variant.label()));
            let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
            assert_eq!(entry_points, ["main"], "{}", variant.label());
            // The depth it reads is multisampled exactly when the frame is.
            let multisampled = module.global_variables.iter().any(|(_, g)| {
                matches!(
                    module.types[g.ty].inner,
                    naga::TypeInner::Image {
                        class: naga::ImageClass::Depth { multi: true },
                        ..
                    }
                )
            });
            assert_eq!(multisampled, samples > 1, "{} at {samples} samples", variant.label());
            composed += 1;
        }
    }
    assert!(composed >= 24, "only {composed} filter variants");
    // The single-sample entry point is the one-sample variant.
    let variant = ForwardVariant::all()[0];
    assert_eq!(
        format!("{:?}", library.resolve(variant).unwrap()),
        format!("{:?}", library.resolve_multisampled(variant, 1).unwrap())
    );
}

#[test]
fn prepass_shader_validates_with_every_entry_point() {
    let mut library = ShaderLibrary::new().unwrap();
    let module = library.prepass().unwrap_or_else(|e| panic!("{e}"));
    let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(
        entry_points,
        [
            "vs_main",
            "fs_masked",
            "fs_normal",
            "fs_masked_normal",
            "fs_normal_id",
            "fs_masked_normal_id"
        ]
    );
}

#[test]
fn a_user_material_can_import_the_light_contract() {
    let mut library = ShaderLibrary::new().unwrap();
    let material = r#"
#import penumbra::lights::{get_light, light_count, make_surface, shadow_visibility}

@fragment
fn fs_main(@builtin(position) p: vec4<f32>, @location(0) world: vec3<f32>, @location(1) n: vec3<f32>) -> @location(0) vec4<f32> {
    let surface = make_surface(world, normalize(n), p.w, p.xy);
    var visibility = 1.0;
    for (var i = 0u; i < light_count(); i++) {
        visibility = min(visibility, shadow_visibility(get_light(i), surface));
    }
    return vec4<f32>(vec3<f32>(visibility), 1.0);
}
"#;
    for variant in ForwardVariant::all() {
        library
            .compose("my_material.wgsl", material, variant.shader_defs())
            .unwrap_or_else(|e| panic!("{}: {e}", variant.label()));
    }
}

#[test]
fn a_broken_shader_reports_the_file_and_the_problem() {
    let mut library = ShaderLibrary::new().unwrap();
    let err = library
        .compose(
            "broken.wgsl",
            "@fragment fn fs() -> @location(0) vec4<f32> { return vec4<f32>(undefined_name); }",
            Default::default(),
        )
        .unwrap_err()
        .to_string();
    assert!(err.contains("broken.wgsl"), "{err}");
    assert!(err.contains("undefined_name"), "{err}");
}

#[test]
fn the_poisson_uniforms_hold_the_generated_patterns() {
    use penumbra::math::poisson::{min_pairwise_distance, poisson_disk};
    use penumbra::render::gpu_types::{PoissonTapsGpu, normalized};

    let taps = PoissonTapsGpu::standard();
    let unpack = |pairs: &[glam::Vec4], n: usize| -> Vec<glam::Vec2> {
        pairs
            .iter()
            .flat_map(|p| [glam::Vec2::new(p.x, p.y), glam::Vec2::new(p.z, p.w)])
            .take(n)
            .collect()
    };
    for (packed, count, seed) in [
        (unpack(&taps.blocker_sixteen, 16), 16, 41),
        (unpack(&taps.blocker_thirty_two, 32), 32, 42),
        (unpack(&taps.filter_sixteen, 16), 16, 44),
        (unpack(&taps.filter_twenty_five, 25), 25, 47),
        (unpack(&taps.filter_forty_nine, 49), 49, 43),
    ] {
        let generated = poisson_disk(count, seed);
        assert_eq!(packed, normalized(&generated), "{count} taps, seed {seed}");
        let rms = (packed.iter().map(|t| t.length_squared()).sum::<f32>() / count as f32).sqrt();
        assert!((rms - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-5, "rms {rms}");
        // Scaling keeps the spacing property, relative to the scale.
        let scale = packed[0].length() / generated[0].length();
        assert!(min_pairwise_distance(&packed) >= scale * 0.7 / (count as f32).sqrt() - 1e-5);
        assert!((0.8..1.25).contains(&scale), "scale {scale}");
    }
}

#[test]
fn probe_shader_validates_for_every_filter() {
    let mut library = ShaderLibrary::new().unwrap();
    for variant in ForwardVariant::all()
        .into_iter()
        .filter(|v| !v.alpha_mask && !v.debug_cascades && !v.analysis)
    {
        let module = library
            .probe(variant)
            .unwrap_or_else(|e| panic!("{}: {e}", variant.label()));
        assert_eq!(module.entry_points[0].name, "main");
    }
}

#[test]
fn the_skinning_shader_validates() {
    let mut library = ShaderLibrary::new().unwrap();
    let module = library.skinning().unwrap_or_else(|e| panic!("{e}"));
    let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(entry_points, ["main"]);
}

#[test]
fn the_occlusion_culling_shaders_validate() {
    let mut library = ShaderLibrary::new().unwrap();
    for late in [false, true] {
        let module = library
            .occlusion_cull(late)
            .unwrap_or_else(|e| panic!("late {late}: {e}"));
        assert_eq!(module.entry_points[0].name, "main");
    }
    let module = library.shadow_cull().unwrap_or_else(|e| panic!("shadow culling: {e}"));
    assert_eq!(module.entry_points[0].name, "main");
    for first in [false, true] {
        let module = library
            .occlusion_pyramid(first)
            .unwrap_or_else(|e| panic!("first {first}: {e}"));
        assert_eq!(module.entry_points[0].name, "main");
    }
}
