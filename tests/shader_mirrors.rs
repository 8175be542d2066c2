//! WGSL functions run on a real wgpu device (lavapipe in CI) against their CPU mirrors: the
//! EVSM, moment and MSM bounds, the PCSS sample counts each light's quality packs, and the
//! contact march's jitter.

use penumbra::shader::ShaderLibrary;

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

/// Composes a compute shader whose `main` runs `body` after `imports` (WGSL `#import` lines),
/// writing `count` floats into `out`, runs it and returns them.
fn run_wgsl(file: &str, imports: &str, body: &str, count: usize) -> Vec<f32> {
    let source = format!(
        "{imports}\n\n@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n\n@compute @workgroup_size(1)\nfn main() {{\n{body}}}\n"
    );
    let mut library = ShaderLibrary::new().unwrap();
    let module = library
        .compose(file, &source, Default::default())
        .unwrap_or_else(|e| panic!("{e}"));
    run_compute(module, count)
}

/// Asserts each GPU value is within `relative` of its CPU mirror (absolutely below 1).
fn assert_close(gpu: &[f32], cpu: &[f32], relative: f32) {
    assert_eq!(gpu.len(), cpu.len());
    for (k, (g, c)) in gpu.iter().zip(cpu).enumerate() {
        let tolerance = relative * c.abs().max(1.0);
        assert!((g - c).abs() <= tolerance, "value {k}: GPU {g}, CPU {c}");
    }
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
    let gpu = run_wgsl(
        "evsm_test.wgsl",
        "#import penumbra::shadows::moments::{evsm2_covered_visibility, evsm2_visibility, evsm4_visibility, negative_warp, positive_warp}",
        &body,
        cpu.len(),
    );
    assert_close(&gpu, &cpu, 1e-4);
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
    let gpu = run_wgsl(
        "moments_test.wgsl",
        "#import penumbra::shadows::moments::{chebyshev_upper_bound, moments_visibility, reduce_light_bleeding}",
        &body,
        cases.len() * 3,
    );
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
    let gpu = run_wgsl(
        "msm_test.wgsl",
        "#import penumbra::shadows::msm::{msm_dequantize, msm_moments, msm_quantize, msm_visibility}",
        &body,
        cpu.len(),
    );
    assert_close(&gpu, &cpu, 1e-3);
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
    let counts = run_wgsl(
        "pcss_samples.wgsl",
        "#import penumbra::shadows::common::{blocker_samples, filter_samples}\n#import penumbra::shadows::types::Light",
        &format!("    var light: Light;\n{body}"),
        6,
    );
    let expected: Vec<f32> = qualities
        .iter()
        .flat_map(|q| [q.blocker_samples() as f32, q.filter_samples() as f32])
        .collect();
    assert_eq!(counts, expected);
}

#[test]
fn the_contact_march_jitter_in_wgsl_matches_its_cpu_mirror() {
    use penumbra::math::contact::interleaved_gradient_noise;
    let pixels: Vec<glam::Vec2> = [(0, 0), (1, 0), (0, 1), (17, 5), (639, 359), (1919, 1079), (3840, 2160)]
        .iter()
        .map(|&(x, y)| glam::Vec2::new(x as f32, y as f32))
        .collect();
    let body: String = pixels
        .iter()
        .enumerate()
        .map(|(i, p)| {
            format!(
                "    out[{i}] = interleaved_gradient_noise(vec2<f32>({:?}, {:?}));\n",
                p.x, p.y
            )
        })
        .collect();
    let gpu = run_wgsl(
        "contact_jitter.wgsl",
        "#import penumbra::shadows::common::interleaved_gradient_noise",
        &body,
        pixels.len(),
    );
    let cpu: Vec<f32> = pixels.iter().map(|&p| interleaved_gradient_noise(p)).collect();
    assert_close(&gpu, &cpu, 1e-3);
}
