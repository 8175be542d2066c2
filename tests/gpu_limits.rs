//! Sizes from user data against the device's limits: an oversized target is an error before
//! any GPU work, an oversized texture is downscaled with a warning, instance and mesh data
//! beyond a binding are refused (the frame is not drawn, the error says why), and a device
//! error that slips through every check is reported, never a panic.

mod common;

use bevy_app::App;
use penumbra::app::{RenderError, RenderRequest, headless_app, render_scene_with, spawn_scene};
use penumbra::ecs::assets::{ImageData, Images, Materials};
use penumbra::render::{GpuContext, GpuError, Renderer};
use penumbra::scene::{GridDesc, SceneDesc};
use penumbra::shader::instance::InstanceGpu;

const NO_GPU: &str = "no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)";

fn scene() -> SceneDesc {
    SceneDesc::load("assets/scenes/default.ron").expect("default scene loads")
}

fn app() -> App {
    let mut app = headless_app(Renderer::headless(64, 48).expect(NO_GPU));
    spawn_scene(app.world_mut(), &scene()).expect("default scene spawns");
    app
}

fn renderer(app: &mut App) -> bevy_ecs::world::Mut<'_, Renderer> {
    app.world_mut().resource_mut::<Renderer>()
}

#[test]
fn target_sizes_outside_the_device_limits_are_errors() {
    let max = GpuContext::headless().expect(NO_GPU).limits.max_texture_side;
    for (width, height, side, found) in [(max + 1, 4, "width", max + 1), (4, 0, "height", 0)] {
        let err = match Renderer::headless(width, height) {
            Ok(_) => panic!("{width}×{height} accepted"),
            Err(e) => e,
        };
        assert!(matches!(err, GpuError::Limit(_)), "{err:?}");
        assert_eq!(
            err.to_string(),
            format!("the render target {side} is {found}; this GPU allows 1 to {max}")
        );
    }
}

#[test]
fn textures_larger_than_the_device_allows_are_downscaled_with_a_warning() {
    let mut app = app();
    app.update();
    assert_eq!(renderer(&mut app).take_warnings(), Vec::<String>::new());
    // A 40×2 texture on a device that pretends to allow 16 texels a side.
    renderer(&mut app).gpu.limits.max_texture_side = 16;
    let world = app.world_mut();
    let handle = world.resource_mut::<Images>().add(ImageData {
        width: 40,
        height: 2,
        rgba: vec![255; 40 * 2 * 4],
    });
    let mut materials = world.resource_mut::<Materials>();
    let first = materials.as_slice()[0].clone();
    materials.add(penumbra::ecs::assets::Material {
        base_color_texture: Some(handle),
        ..first
    });
    app.update();
    let warnings = renderer(&mut app).take_warnings();
    let ours = format!(
        "image {}: 40×2 is larger than this GPU's largest texture (16); downscaled to 16×1",
        handle.0
    );
    assert!(warnings.contains(&ours), "{warnings:?}");
    // The scene's own 128×128 texture is downscaled too; nothing else is reported.
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    assert_eq!(renderer(&mut app).take_errors(), Vec::<String>::new());
}

#[test]
fn instances_beyond_a_storage_binding_are_refused_and_the_frame_not_drawn() {
    let mut app = app();
    app.update();
    let drawn = renderer(&mut app).last_report.draw_calls;
    assert!(drawn > 0, "the default scene draws");
    assert_eq!(renderer(&mut app).take_errors(), Vec::<String>::new());
    // Room for 3 instances only: the scene has more.
    renderer(&mut app).gpu.limits.max_storage_binding_bytes = 3 * 160;
    // Moving every instance makes the instance buffer upload again (scene objects are
    // static until unmarked).
    let world = app.world_mut();
    common::unmark_static(world);
    let mut q = world.query::<&mut penumbra::ecs::Transform>();
    for mut t in q.iter_mut(world) {
        t.translation += glam::Vec3::X * 0.01;
    }
    app.update();
    let errors = renderer(&mut app).take_errors();
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(
        errors[0].starts_with("the frame is not drawn: the size in bytes of the instances buffer is "),
        "{errors:?}"
    );
    assert!(errors[0].ends_with("; this GPU allows 0 to 480"), "{errors:?}");
    assert_eq!(renderer(&mut app).last_report.draw_calls, 0);
    // Back within limits: drawn again, no new error.
    renderer(&mut app).gpu.limits.max_storage_binding_bytes = 1 << 27;
    app.update();
    assert_eq!(renderer(&mut app).take_errors(), Vec::<String>::new());
    assert_eq!(renderer(&mut app).last_report.draw_calls, drawn);
}

#[test]
fn a_scene_with_more_instances_than_a_binding_holds_is_refused_before_spawning() {
    let mut desc = scene();
    let limits = GpuContext::headless().expect(NO_GPU).limits;
    let most = limits.storage_elements(size_of::<InstanceGpu>() as u64);
    // Written here, not in a file: a scene file would stop at the scene's own instance cap.
    desc.objects[1].grid = Some(GridDesc {
        count: glam::UVec3::new(most as u32 + 1, 1, 1),
        spacing: glam::Vec3::ONE,
        jitter: None,
    });
    let request = RenderRequest {
        width: 32,
        height: 32,
        frames: 1,
        tweak: None,
        analysis: false,
        options: Default::default(),
        shadow_budget: None,
        count_fragments: false,
        camera_lod: None,
        camera_motion: Default::default(),
    };
    let err = match render_scene_with(&desc, &request) {
        Ok(_) => panic!("{} instances rendered", desc.instance_count()),
        Err(e) => e,
    };
    assert!(matches!(err, RenderError::Gpu(GpuError::Limit(_))), "{err:?}");
    assert_eq!(
        err.to_string(),
        format!(
            "the scene's instance count is {}; this GPU allows 0 to {most}",
            desc.instance_count()
        )
    );
}

#[test]
fn device_errors_are_collected_not_panics() {
    let mut app = app();
    app.update();
    // An invalid buffer: mappable for reading and usable as storage.
    let _bad = renderer(&mut app).gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("invalid on purpose"),
        size: 16,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let errors = renderer(&mut app).take_errors();
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(errors[0].contains("invalid on purpose"), "{errors:?}");
    assert_eq!(renderer(&mut app).take_errors(), Vec::<String>::new(), "taken once");
}
