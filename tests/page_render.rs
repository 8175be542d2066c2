//! The paged clipmap's page drawing on a real wgpu device (lavapipe in CI): the pages of two
//! levels, allocated and drawn on the GPU into the pool atlas, hold what the whole levels
//! drawn by the engine's caster pipeline hold at those texels. Each caster is drawn on its own
//! here (the path of devices without indirect first instances); the multi-draw path is the
//! renderer's on lavapipe (`tests/pages.rs`).

use glam::I64Vec2;
use penumbra::math::pages::{PageKey, PageLayout, PageRect, PagedLevel, atlas_tiles, snap_to_pages};
use penumbra::mesh::{MeshData, cuboid, plane, sphere};
use penumbra::render::GpuContext;
use penumbra::render::layouts::Layouts;
use penumbra::render::shadows::page_allocate::PageAllocator;
use penumbra::render::shadows::storage::{DepthArray, SHADOW_FORMAT, read_depth_layer};
use penumbra::shader::ShaderLibrary;

/// A 60 m ground with boxes and a sphere on it.
fn page_scene() -> Vec<(MeshData, glam::Mat4)> {
    let mut scene = vec![(plane(glam::Vec2::splat(60.0)), glam::Mat4::IDENTITY)];
    for (i, (x, z, h)) in [
        (-3.0, -2.0, 1.0),
        (2.5, 1.0, 2.5),
        (0.5, -6.0, 0.6),
        (-8.0, 4.0, 4.0),
        (6.0, -9.0, 1.5),
    ]
    .into_iter()
    .enumerate()
    {
        let size = glam::Vec3::new(0.6 + 0.3 * i as f32, h, 0.8);
        scene.push((
            cuboid(size),
            glam::Mat4::from_translation(glam::Vec3::new(x, h / 2.0, z)),
        ));
    }
    scene.push((
        sphere(1.2, 24, 12),
        glam::Mat4::from_translation(glam::Vec3::new(-1.0, 1.2, 5.0)),
    ));
    scene
}

#[test]
fn drawn_pages_hold_what_the_whole_level_holds_there() {
    use penumbra::math::aabb::Aabb;
    use penumbra::math::clipmap::{ClipmapInput, compute_clipmap, moved_level};
    use penumbra::render::shadows::page_render::{PageCaster, PageRenderer, PageScene};
    use penumbra::render::shadows::standalone::{ShadowCaster, StandaloneShadows};
    use penumbra::settings::ShadowSettings;
    use wgpu::util::DeviceExt;
    let gpu = GpuContext::headless()
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    assert!(
        gpu.clip_distances,
        "the device has no clip distances, which page drawing needs"
    );
    let (device, queue) = (&gpu.device, &gpu.queue);
    let layout = PageLayout::new(4096, 128).unwrap();
    let scene = page_scene();
    let bounds = scene
        .iter()
        .fold(Aabb::EMPTY, |b, (m, t)| b.union(m.bounds().transformed(t)));
    let set = compute_clipmap(&ClipmapInput {
        camera_position: glam::Vec3::new(0.0, 2.0, 0.0),
        light_direction: glam::Vec3::new(-0.45, -0.55, -0.7),
        levels: 2,
        level0_extent: 16.0,
        resolution: 4096,
        casters: bounds,
    });
    let camera = (set.light_rotation.as_dmat3() * glam::DVec3::new(0.0, 2.0, 0.0)).truncate();
    let levels: Vec<(glam::Mat4, PagedLevel)> = set
        .active()
        .iter()
        .map(|level| {
            let texel = f64::from(level.extent) / 4096.0;
            let first = snap_to_pages(camera / texel, &layout);
            let moved = moved_level(set.light_rotation, level, first, 4096);
            (
                moved.clip_from_world,
                PagedLevel {
                    first_texel: first,
                    texel,
                },
            )
        })
        .collect();
    // NOTE: the pages within 3 of each window's centre: 49 a level, 98 in a pool of 100.
    let mut needed = Vec::new();
    for (l, (_, paged)) in levels.iter().enumerate() {
        let window = layout.window(paged.first_texel);
        let centre = (window.min + window.max) / 2;
        let near = PageRect {
            min: centre - I64Vec2::splat(3),
            max: centre + I64Vec2::splat(3),
        };
        needed.extend(near.pages().map(|p| PageKey::new(l as u32, p)));
    }
    let mut library = ShaderLibrary::new().unwrap();
    let allocator = PageAllocator::new(device, queue, &mut library, layout, 2, 100);
    let mut bits = vec![0u32; (2 * layout.entries()).div_ceil(32)];
    for key in &needed {
        let i = key.level as usize * layout.entries() + layout.entry(key.grid());
        bits[i / 32] |= 1 << (i % 32);
    }
    queue.write_buffer(&allocator.needed, 0, bytemuck::cast_slice(&bits));
    // NOTE: both sides draw with the default slope-scaled bias.
    let settings = ShadowSettings::default();
    let side = atlas_tiles(100) * 128;
    let atlas = DepthArray::new(device, "page atlas", (side, 1), false, SHADOW_FORMAT);
    let layouts = Layouts::new(device);
    let mut pages = PageRenderer::new(
        (device, queue, false),
        (&mut library, &layouts.material),
        (&allocator, &atlas),
        16,
        &settings.bias,
        gpu.unclipped_depth,
    );
    let (mut vertices, mut indices, mut casters) = (Vec::new(), Vec::new(), Vec::new());
    for (mesh, transform) in &scene {
        let b = mesh.bounds().transformed(transform);
        casters.push(PageCaster {
            world_from_local: *transform,
            sphere: b.center().extend(b.half_extents().length()),
            indices: (indices.len() as u32, mesh.indices.len() as u32, vertices.len() as i32),
            masked: None,
        });
        vertices.extend_from_slice(&mesh.vertices);
        indices.extend_from_slice(&mesh.indices);
    }
    let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(&vertices),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(&indices),
        usage: wgpu::BufferUsages::INDEX,
    });
    let page_scene = PageScene {
        light_rotation: set.light_rotation,
        levels: &levels,
        casters: &casters,
        materials: &[],
        geometry: (&vertex_buffer, &index_buffer),
    };
    let mut encoder = device.create_command_encoder(&Default::default());
    let windows: Vec<I64Vec2> = levels.iter().map(|(_, p)| layout.page_of(p.first_texel)).collect();
    allocator.record(queue, &mut encoder, (1, &windows), None);
    pages.record((queue, &mut encoder), &allocator, &page_scene, None);
    queue.submit([encoder.finish()]);
    let (_, _, allocation) = allocator.read(device, queue).expect("the allocation reads back");
    assert_eq!(allocation.draws.len(), 98, "every needed page is drawn");
    let atlas_side = pages.tiles * 128;
    let atlas = read_depth_layer(device, queue, &atlas.texture, 0).expect("the atlas");
    let shadow_casters: Vec<ShadowCaster<'_>> = scene
        .iter()
        .map(|(mesh, transform)| ShadowCaster {
            mesh,
            world_from_local: *transform,
        })
        .collect();
    let mut standalone = StandaloneShadows::new(&gpu);
    let n = i64::from(layout.pages_per_side());
    let (mut judged, mut covered, mut coverage, mut edges, mut worst) = (0usize, 0usize, 0usize, 0usize, 0.0f32);
    for (l, (clip_from_world, paged)) in levels.iter().enumerate() {
        let whole = standalone.render_ortho(&gpu, &shadow_casters, *clip_from_world, 4096, &settings);
        let whole = read_depth_layer(device, queue, &whole, 0).expect("the level");
        let first_page = layout.page_of(paged.first_texel);
        for &(key, physical) in allocation.draws.iter().filter(|d| d.0 >> 24 == l as u32) {
            let entry = (key & 0xff_ffff) as i64;
            let local = (I64Vec2::new(entry % n, entry / n) - first_page).rem_euclid(I64Vec2::splat(n));
            let (x0, y0) = (local.x as usize * 128, (n - 1 - local.y) as usize * 128);
            let tile = (physical % pages.tiles, physical / pages.tiles);
            let (tx, ty) = (tile.0 as usize * 128, tile.1 as usize * 128);
            for j in 0..128 {
                for i in 0..128 {
                    let a = atlas[(ty + j) * atlas_side as usize + tx + i];
                    let b = whole[(y0 + j) * 4096 + x0 + i];
                    judged += 1;
                    covered += usize::from(b > 0.0);
                    if (a > 0.0) != (b > 0.0) {
                        coverage += 1;
                    } else if (a - b).abs() > 1e-4 {
                        edges += 1;
                    } else {
                        worst = worst.max((a - b).abs());
                    }
                }
            }
        }
    }
    println!(
        "{judged} texels judged, {covered} hold a caster; coverage differs at {coverage}, another caster's depth at {edges}, the rest by up to {worst:e}"
    );
    assert_eq!(judged, 98 * 128 * 128);
    assert!(covered > judged / 2, "only {covered} of {judged} texels hold a caster");
    // NOTE: a texel whose centre lies on a caster's edge may fall on either side once the
    // page's vertices are moved onto its tile (lavapipe: 1 texel of 1.6 M).
    assert!(
        coverage + edges <= 3,
        "{coverage} texels differ in coverage, {edges} in which caster they hold"
    );
    // NOTE: depth interpolated over a moved viewport, which varies with the tile a page
    // takes (lavapipe: up to 2.3e-6 with the coarsest level's pages served first).
    assert!(worst <= 7e-6, "depth differs by {worst:e}");
}
