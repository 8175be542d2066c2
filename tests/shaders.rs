//! Every WGSL variant composes with naga_oil and passes naga's validator.

use penumbra::shader::{ForwardVariant, ShaderLibrary};

#[test]
fn every_forward_variant_validates() {
    let mut library = ShaderLibrary::new().expect("shared modules compose");
    let variants = ForwardVariant::all();
    assert_eq!(
        variants.len(),
        64,
        "PCF + 3 PCSS qualities, each with and without spot shadows, debug view, alpha mask and analysis outputs"
    );
    for variant in variants {
        let module = library
            .forward(variant)
            .unwrap_or_else(|e| panic!("{}: {e}", variant.label()));
        let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(entry_points, ["vs_main", "fs_main"], "{}", variant.label());
    }
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
fn the_resolve_shader_validates_for_every_filter_variant() {
    let mut library = ShaderLibrary::new().unwrap();
    let mut composed = 0;
    for variant in ForwardVariant::all() {
        if variant.analysis || variant.alpha_mask || variant.debug_cascades {
            continue;
        }
        let module = library
            .resolve(variant)
            .unwrap_or_else(|e| panic!("{}: {e}", variant.label()));
        let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(entry_points, ["main"], "{}", variant.label());
        composed += 1;
    }
    assert!(composed >= 8, "only {composed} filter variants");
}

#[test]
fn prepass_shader_validates_with_both_entry_points() {
    let mut library = ShaderLibrary::new().unwrap();
    let module = library.prepass().unwrap_or_else(|e| panic!("{e}"));
    let entry_points: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(entry_points, ["vs_main", "fs_masked", "fs_normal", "fs_masked_normal"]);
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
