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
fn the_cascade_moments_shader_validates_in_every_moments_format() {
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

/// Runs `main` of a composed compute shader that writes `count` floats into binding 0 and
/// returns them.
fn run_compute(module: naga::Module, count: usize) -> Vec<f32> {
    let renderer = penumbra::render::Renderer::headless(8, 8)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let (device, queue) = (&renderer.gpu.device, &renderer.gpu.queue);
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: None,
        source: wgpu::ShaderSource::Naga(std::borrow::Cow::Owned(module)),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: None,
        module: &shader,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let size = (count * 4) as u64;
    let buffer = |usage| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size,
            usage,
            mapped_at_creation: false,
        })
    };
    let out = buffer(wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
    let readback = buffer(wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: out.as_entire_binding(),
        }],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
    }
    encoder.copy_buffer_to_buffer(&out, 0, &readback, 0, size);
    queue.submit([encoder.finish()]);
    let bytes = penumbra::render::readback::read_buffer(device, &readback, size).expect("read back");
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

#[test]
fn the_evsm_tests_in_wgsl_match_their_cpu_mirror() {
    use penumbra::math::evsm::{
        MomentPrecision, evsm2_covered_moments, evsm2_covered_visibility, evsm2_visibility, evsm4_visibility,
        negative_warp, positive_warp,
    };
    use penumbra::math::moments::moments_of;
    // (depths of the footprint, receiver depth, exponent) cases: lit, flat umbra, stacked
    // occluders, a penumbra; with both formats' exponents.
    let fp16 = MomentPrecision::Fp16.exponent();
    let fp32 = MomentPrecision::Fp32.exponent();
    let cases: [(&[f32], f32, f32); 5] = [
        (&[0.4], 0.39, fp32),
        (&[0.4], 0.45, fp32),
        (&[0.2, 0.7], 0.8, fp16),
        (&[0.3, 0.31, 0.6], 0.5, fp16),
        (&[0.5, 0.52], 0.6, 20.0),
    ];
    let (floor, bleed) = (1e-6, 0.1);
    let mut body = String::new();
    let mut cpu = Vec::new();
    for (i, &(depths, receiver, c)) in cases.iter().enumerate() {
        let weights = vec![1.0; depths.len()];
        let p: Vec<f32> = depths.iter().map(|&d| positive_warp(d, c)).collect();
        let n: Vec<f32> = depths.iter().map(|&d| negative_warp(d, c)).collect();
        let (mp, mn) = (moments_of(&p, &weights), moments_of(&n, &weights));
        let m4 = glam::Vec4::new(mp.x, mp.y, mn.x, mn.y);
        let v = i * 5;
        body += &format!(
            "    out[{v}] = evsm2_visibility(vec2<f32>({:?}, {:?}), {receiver:?}, {c:?}, {floor:?}, {bleed:?});
",
            mp.x, mp.y
        );
        body += &format!(
            "    out[{}] = evsm4_visibility(vec4<f32>({:?}, {:?}, {:?}, {:?}), {receiver:?}, {c:?}, {c:?}, {floor:?}, {bleed:?});
",
            v + 1,
            m4.x,
            m4.y,
            m4.z,
            m4.w
        );
        body += &format!(
            "    out[{}] = positive_warp({receiver:?}, {c:?});
",
            v + 2
        );
        body += &format!(
            "    out[{}] = negative_warp({receiver:?}, {c:?});
",
            v + 3
        );
        // The same footprint with a quarter of it empty, as covered moments.
        let covered = depths
            .iter()
            .map(|&d| evsm2_covered_moments(d, c, true))
            .chain(std::iter::repeat_n(
                evsm2_covered_moments(1.0, c, false),
                depths.len().div_ceil(3),
            ))
            .collect::<Vec<_>>();
        let mc = covered.iter().sum::<glam::Vec4>() / covered.len() as f32;
        body += &format!(
            "    out[{}] = evsm2_covered_visibility(vec4<f32>({:?}, {:?}, {:?}, {:?}), {receiver:?}, {c:?}, {floor:?}, {bleed:?});
",
            v + 4,
            mc.x,
            mc.y,
            mc.z,
            mc.w
        );
        cpu.extend([
            evsm2_visibility(mp, receiver, c, floor, bleed),
            evsm4_visibility(m4, receiver, c, c, floor, bleed),
            positive_warp(receiver, c),
            negative_warp(receiver, c),
            evsm2_covered_visibility(mc, receiver, c, floor, bleed),
        ]);
    }
    let source = format!(
        "#import penumbra::shadows::moments::{{evsm2_covered_visibility, evsm2_visibility, evsm4_visibility, negative_warp, positive_warp}}\n\n@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n\n@compute @workgroup_size(1)\nfn main() {{\n{body}}}\n"
    );
    let mut library = ShaderLibrary::new().unwrap();
    let module = library
        .compose("evsm_test.wgsl", &source, Default::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let gpu = run_compute(module, cpu.len());
    for (k, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
        let tolerance = 1e-4 * c.abs().max(1.0);
        assert!((g - c).abs() <= tolerance, "value {k}: GPU {g}, CPU {c}");
    }
    // The cases span lit, dark and between.
    let visibilities: Vec<f32> = (0..cases.len()).map(|i| cpu[i * 5]).collect();
    assert!(visibilities.contains(&1.0) && visibilities.iter().any(|&v| v < 0.05));
    // A covered footprint with empty texels is never darker than its occupied share allows.
    let covered: Vec<f32> = (0..cases.len()).map(|i| cpu[i * 5 + 4]).collect();
    assert!(covered.iter().all(|&v| v >= 0.2), "{covered:?}");
    assert!(visibilities.iter().any(|&v| v > 0.05 && v < 0.95), "{visibilities:?}");
}

#[test]
fn the_moment_tests_in_wgsl_match_their_cpu_mirror() {
    use penumbra::math::moments::{chebyshev_upper_bound, moments_of, moments_visibility, reduce_light_bleeding};
    // (moments, depth, floor, bleed) cases: lit, penumbra, flat occluder, stacked occluders.
    let cases = [
        (moments_of(&[0.4], &[1.0]), 0.3, 1e-5, 0.0),
        (moments_of(&[0.3, 0.6], &[0.5, 0.5]), 0.55, 1e-5, 0.2),
        (moments_of(&[0.5; 2], &[1.0; 2]), 0.5001, 1e-5, 0.0),
        (moments_of(&[0.2, 0.7], &[0.5, 0.5]), 0.8, 1e-5, 0.7),
        (moments_of(&[0.2, 0.7], &[0.5, 0.5]), 0.8, 1e-5, 0.0),
    ];
    let mut body = String::new();
    for (i, (m, depth, floor, bleed)) in cases.iter().enumerate() {
        let (m, v) = (format!("vec2<f32>({:?}, {:?})", m.x, m.y), i * 3);
        body += &format!(
            "    out[{v}] = chebyshev_upper_bound({m}, {depth:?}, {floor:?});\n    out[{}] = reduce_light_bleeding({:?}, {bleed:?});\n    out[{}] = moments_visibility({m}, {depth:?}, {floor:?}, {bleed:?});\n",
            v + 1,
            0.5 + 0.1 * i as f32,
            v + 2,
        );
    }
    let source = format!(
        "#import penumbra::shadows::moments::{{chebyshev_upper_bound, moments_visibility, reduce_light_bleeding}}\n\n@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n\n@compute @workgroup_size(1)\nfn main() {{\n{body}}}\n"
    );
    let mut library = ShaderLibrary::new().unwrap();
    let module = library
        .compose("moments_test.wgsl", &source, Default::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let gpu = run_compute(module, cases.len() * 3);
    for (i, &(m, depth, floor, bleed)) in cases.iter().enumerate() {
        let cpu: [f32; 3] = [
            chebyshev_upper_bound(m, depth, floor),
            reduce_light_bleeding(0.5 + 0.1 * i as f32, bleed),
            moments_visibility(m, depth, floor, bleed),
        ];
        for (k, c) in cpu.iter().enumerate() {
            let g = gpu[i * 3 + k];
            assert!((g - c).abs() < 1e-5, "case {i} value {k}: GPU {g}, CPU {c}");
        }
    }
    // The cases span the bound's range, so the comparison judged something.
    let bounds: Vec<f32> = (0..cases.len()).map(|i| gpu[i * 3]).collect();
    assert!(bounds.contains(&1.0) && bounds.iter().any(|&p| p > 0.05 && p < 0.95));
    assert_eq!(gpu[3 * 3 + 2], 0.0, "bleed reduction darkens the stacked umbra");
}

#[test]
fn the_msm_tests_in_wgsl_match_their_cpu_mirror() {
    use penumbra::math::msm::{MSM_BIAS_16, MSM_BIAS_32, dequantize, hamburger_visibility, msm_moments, quantize};
    // (depths of the footprint, receiver depth, bias): lit, flat umbra, stacked occluders, a
    // half-covered footprint, a single depth (the degenerate case).
    let cases: [(&[f32], f32, f32); 5] = [
        (&[0.4], 0.39, MSM_BIAS_32),
        (&[0.3, 0.31], 0.6, MSM_BIAS_16),
        (&[0.2, 0.5], 0.8, MSM_BIAS_16),
        (&[0.3, 1.0], 0.9, MSM_BIAS_32),
        (&[0.5], 0.7, 0.0),
    ];
    let mut body = String::new();
    let mut cpu = Vec::new();
    for (i, &(depths, receiver, bias)) in cases.iter().enumerate() {
        let mean = depths.iter().map(|&d| msm_moments(d)).sum::<glam::Vec4>() / depths.len() as f32;
        let stored = quantize(mean);
        let v = i * 2;
        let m = format!("vec4<f32>({:?}, {:?}, {:?}, {:?})", mean.x, mean.y, mean.z, mean.w);
        body += &format!("    out[{v}] = msm_visibility({m}, {receiver:?}, {bias:?});\n");
        // The quantisation round trip, summed so one value checks all four channels.
        body += &format!(
            "    out[{}] = dot(msm_dequantize(msm_quantize(msm_moments({:?}))), vec4<f32>(1.0, 10.0, 100.0, 1000.0));\n",
            v + 1,
            depths[0]
        );
        cpu.push(hamburger_visibility(mean, receiver, bias));
        let trip = dequantize(quantize(msm_moments(depths[0])));
        cpu.push(trip.dot(glam::Vec4::new(1.0, 10.0, 100.0, 1000.0)));
        assert!(stored.is_finite());
    }
    let source = format!(
        "#import penumbra::shadows::msm::{{msm_dequantize, msm_moments, msm_quantize, msm_visibility}}\n\n@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n\n@compute @workgroup_size(1)\nfn main() {{\n{body}}}\n"
    );
    let mut library = ShaderLibrary::new().unwrap();
    let module = library
        .compose("msm_test.wgsl", &source, Default::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let gpu = run_compute(module, cpu.len());
    for (k, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
        let tolerance = 1e-3 * c.abs().max(1.0);
        assert!((g - c).abs() <= tolerance, "value {k}: GPU {g}, CPU {c}");
    }
    // The cases span lit, dark and between.
    let visibilities: Vec<f32> = (0..cases.len()).map(|i| cpu[i * 2]).collect();
    assert!(visibilities.iter().any(|&v| v > 0.99) && visibilities.iter().any(|&v| v < 0.01));
    assert!(visibilities.iter().any(|&v| v > 0.3 && v < 0.7), "{visibilities:?}");
}

#[test]
fn each_light_samples_the_pcss_taps_of_its_own_quality() {
    use penumbra::render::shadows::gpu::pcss_samples;
    use penumbra::settings::{PcssQuality, ShadowSettings};
    let qualities = [PcssQuality::Low, PcssQuality::Medium, PcssQuality::High];
    let mut body = String::new();
    for (i, quality) in qualities.iter().enumerate() {
        let mut settings = ShadowSettings::default();
        settings.filter.pcss_quality = *quality;
        let packed = pcss_samples(&settings);
        body += &format!(
            "    light.pcss_samples = {packed}u;\n    out[{}] = f32(blocker_samples(light));\n    out[{}] = f32(filter_samples(light));\n",
            2 * i,
            2 * i + 1
        );
    }
    let source = format!(
        "#import penumbra::shadows::common::{{blocker_samples, filter_samples}}\n#import penumbra::shadows::types::Light\n\n@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n\n@compute @workgroup_size(1)\nfn main() {{\n    var light: Light;\n{body}}}\n"
    );
    let mut library = ShaderLibrary::new().unwrap();
    let module = library
        .compose("pcss_samples.wgsl", &source, Default::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let counts = run_compute(module, 6);
    let expected: Vec<f32> = qualities
        .iter()
        .flat_map(|q| [q.blocker_samples() as f32, q.filter_samples() as f32])
        .collect();
    assert_eq!(counts, expected);
}
