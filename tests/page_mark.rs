//! The paged clipmap's marking on a real wgpu device (lavapipe in CI) against its CPU mirror
//! (`math::pages::mark_receiver`), on a camera depth of a ground and a wall: every page the
//! mirror marks for a pixel (with a footprint a twentieth of a texel narrower) is marked, and
//! no page that no pixel reads (with one that much wider).

use std::collections::BTreeSet;

use penumbra::math::light_space::light_rotation;
use penumbra::math::pages::{MarkRule, PageKey, PageLayout, PagedLevel, mark_receiver, snap_to_pages};
use penumbra::render::GpuContext;
use penumbra::render::shadows::page_allocate::PageAllocator;
use penumbra::render::shadows::page_mark::{MarkInput, PageMark};
use penumbra::render::shadows::storage::read_depth_layer;
use penumbra::shader::ShaderLibrary;

/// A depth-only pipeline drawing triangles of world positions with `view_proj` (reverse-Z).
const DEPTH_SHADER: &str = "
@group(0) @binding(0) var<uniform> view_proj: mat4x4<f32>;
@vertex fn vs(@location(0) p: vec3<f32>) -> @builtin(position) vec4<f32> {
    return view_proj * vec4<f32>(p, 1.0);
}";

/// A ground 400 m wide reaching 400 m ahead and a wall 6 m ahead, as the camera at 2 m sees
/// them: its depth (`width` × `height`, reverse-Z) and its world-from-clip matrix.
fn camera_depth(gpu: &GpuContext, (width, height): (u32, u32)) -> (wgpu::Texture, Vec<f32>, glam::Mat4) {
    use wgpu::util::DeviceExt;
    let device = &gpu.device;
    let eye = glam::Vec3::new(0.0, 2.0, 0.0);
    let view = glam::camera::rh::view::look_at_mat4(eye, glam::Vec3::new(0.3, 1.0, -10.0), glam::Vec3::Y);
    let proj = glam::camera::rh::proj::directx::perspective_infinite_reverse(1.0, width as f32 / height as f32, 0.1);
    let view_proj = proj * view;
    let quads: [[f32; 3]; 8] = [
        [-200.0, 0.0, 10.0],
        [200.0, 0.0, 10.0],
        [200.0, 0.0, -400.0],
        [-200.0, 0.0, -400.0],
        [-2.0, 0.0, -6.0],
        [2.0, 0.0, -6.0],
        [2.0, 3.0, -6.0],
        [-2.0, 3.0, -6.0],
    ];
    let triangles: Vec<[f32; 3]> = [0, 4]
        .iter()
        .flat_map(|&q| [q, q + 1, q + 2, q, q + 2, q + 3].map(|i| quads[i]))
        .collect();
    let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(&triangles),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::bytes_of(&view_proj),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: None,
        source: wgpu::ShaderSource::Wgsl(DEPTH_SHADER.into()),
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: None,
        layout: None,
        vertex: wgpu::VertexState {
            module: &shader,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3],
            })],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Greater),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: None,
        multiview_mask: None,
        cache: None,
    });
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let target = texture.create_view(&Default::default());
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: uniform.as_entire_binding(),
        }],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &target,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.draw(0..triangles.len() as u32, 0..1);
    }
    gpu.queue.submit([encoder.finish()]);
    let depth = read_depth_layer(&gpu.device, &gpu.queue, &texture, 0).expect("the depth");
    (texture, depth, view_proj.inverse())
}

/// The pages `needed` (a bit per table entry, level by level) marks.
fn marked(bits: &[u32], layout: &PageLayout, levels: &[PagedLevel]) -> BTreeSet<PageKey> {
    let per_level = layout.entries();
    let mut out = BTreeSet::new();
    for (level, paged) in levels.iter().enumerate() {
        let window = layout.window(paged.first_texel);
        for page in window.pages() {
            let i = level * per_level + layout.entry(page);
            if bits[i / 32] >> (i % 32) & 1 == 1 {
                out.insert(PageKey::new(level as u32, page));
            }
        }
    }
    out
}

#[test]
fn the_gpu_marks_the_pages_its_cpu_mirror_marks() {
    let gpu = GpuContext::headless()
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let (width, height) = (160, 90);
    let (texture, depth, world_from_clip) = camera_depth(&gpu, (width, height));
    let layout = PageLayout::new(4096, 128).unwrap();
    let light_rotation = light_rotation(glam::Vec3::new(-0.45, -0.55, -0.7));
    let camera = (light_rotation.as_dmat3() * glam::DVec3::new(0.0, 2.0, 0.0)).truncate();
    let levels: Vec<PagedLevel> = (0..4)
        .map(|i| {
            let texel = 16.0 * f64::from(1 << i) / 4096.0;
            PagedLevel {
                first_texel: snap_to_pages(camera / texel, &layout),
                texel,
            }
        })
        .collect();
    let rule = MarkRule {
        radius: 20.0,
        margin: 40.0,
        blend: 0.1,
        pixel: 0.0,
    };
    let mut library = ShaderLibrary::new().unwrap();
    let mark = PageMark::new(&gpu.device, &mut library, false);
    let allocator = PageAllocator::new(&gpu.device, &gpu.queue, &mut library, layout, 4, 64);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let input = MarkInput {
        world_from_clip,
        light_rotation,
        layout,
        levels: &levels,
        rule,
    };
    let view = texture.create_view(&Default::default());
    let size = glam::UVec2::new(width, height);
    let group = mark.group(&gpu.device, &view, &allocator.needed);
    mark.record(
        (&gpu.queue, &mut encoder),
        (&group, size),
        &input,
        &allocator.needed,
        None,
    );
    gpu.queue.submit([encoder.finish()]);
    let bits: Vec<u32> = allocator
        .read_needed(&gpu.device, &gpu.queue)
        .expect("the bitset reads back");
    let got = marked(&bits, &layout, &levels);
    // NOTE: the GPU works in f32: each pixel's pages are bounded by the mirror's with the
    // footprint a twentieth of a texel narrower (and margins and band that much stricter)
    // and wider; a pixel whose level differs between the two is not held to the first.
    let eps = 0.05;
    let narrow = MarkRule {
        radius: rule.radius - eps,
        margin: rule.margin + eps,
        blend: rule.blend - 1e-4,
        pixel: 0.0,
    };
    let wide = MarkRule {
        radius: rule.radius + eps,
        margin: rule.margin - eps,
        blend: rule.blend + 1e-4,
        pixel: 0.0,
    };
    let (mut covered, mut ambiguous) = (0, 0);
    let mut upper = BTreeSet::new();
    let wfc = world_from_clip.as_dmat4();
    let mut lo = Vec::new();
    let mut hi = Vec::new();
    for (i, &d) in depth.iter().enumerate() {
        if d <= 0.0 {
            continue;
        }
        covered += 1;
        let (x, y) = ((i % width as usize) as f64, (i / width as usize) as f64);
        let ndc = glam::DVec2::new(
            (x + 0.5) / f64::from(width) * 2.0 - 1.0,
            1.0 - (y + 0.5) / f64::from(height) * 2.0,
        );
        let world = wfc * glam::DVec4::new(ndc.x, ndc.y, f64::from(d), 1.0);
        let xy = (light_rotation.as_dmat3() * (world.truncate() / world.w)).truncate();
        // NOTE: the rule reads every level (pixel 0), so the view depth is not used.
        let xy = (xy, 1.0 / world.w);
        lo.clear();
        hi.clear();
        mark_receiver(&layout, &levels, xy, &narrow, &mut lo);
        mark_receiver(&layout, &levels, xy, &wide, &mut hi);
        let strict = MarkRule {
            margin: wide.margin,
            blend: narrow.blend,
            ..wide
        };
        mark_receiver(&layout, &levels, xy, &strict, &mut hi);
        let loose = MarkRule {
            margin: narrow.margin,
            blend: wide.blend,
            ..wide
        };
        mark_receiver(&layout, &levels, xy, &loose, &mut hi);
        upper.extend(hi.iter().copied());
        let level_of = |keys: &[PageKey]| keys.iter().map(|k| k.level).collect::<BTreeSet<_>>();
        if level_of(&lo) != level_of(&hi) {
            ambiguous += 1;
            continue;
        }
        for key in &lo {
            assert!(got.contains(key), "pixel ({x}, {y}): page {key:?} not marked");
        }
    }
    let extra: Vec<_> = got.difference(&upper).collect();
    let per_level: Vec<usize> = (0..4).map(|l| got.iter().filter(|k| k.level == l).count()).collect();
    println!("{covered} pixels covered, {ambiguous} at a level's edge; pages marked per level {per_level:?}");
    assert!(extra.is_empty(), "pages no receiver reads: {extra:?}");
    assert!(covered > 4000, "only {covered} pixels covered");
    // NOTE: lavapipe: none; at most a thousandth of the pixels may escape the first bound.
    assert!(
        ambiguous * 1000 < covered,
        "{ambiguous} of {covered} pixels at a level's edge"
    );
    assert!(
        per_level.iter().filter(|&&n| n > 0).count() >= 3,
        "pages marked per level {per_level:?}"
    );
}
