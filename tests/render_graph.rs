//! The render graph as a user meets it: built each frame, the shadow node culled when no light
//! casts a shadow, the camera's depth buffer a pooled transient created once (or, where the
//! prepass is kept from frame to frame, the renderer's own texture), and a custom
//! node that declares its reads and writes runs after the passes whose output it reads, while
//! a node whose output nothing reads is never recorded. The depth prepass changes no pixel.

mod common;

use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};

use bevy_app::App;
use common::still_scene;
use penumbra::app::{headless_app, spawn_scene};
use penumbra::ecs::{CameraLod, DirectionalLight};
use penumbra::render::frame::{FrameContext, FrameInputs};
use penumbra::render::graph::{FrameResources, GraphResources, PassBuilder, RenderNode, TextureDesc, TextureId};
use penumbra::render::{DepthPrepass, Msaa, RenderOptions, Renderer};
use penumbra::scene::SceneDesc;

/// The default scene at 320×180: more pixels than triangles, so `Auto` runs the prepass;
/// drawn every frame (not kept: its targets are then the graph's pooled transients).
fn app() -> App {
    let mut app = app_sized(320, 180);
    app.insert_resource(RenderOptions {
        prepass_reuse: false,
        ..RenderOptions::default()
    });
    app
}

fn app_sized(width: u32, height: u32) -> App {
    let renderer = Renderer::headless(width, height)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = headless_app(renderer);
    let desc = SceneDesc::load("assets/scenes/default.ron").expect("default scene loads");
    spawn_scene(app.world_mut(), &desc).expect("default scene spawns");
    app
}

fn renderer(app: &App) -> &Renderer {
    app.world().resource::<Renderer>()
}

/// Renders three frames of `app`; asserts the last ran the shadow, prepass, resolve and
/// lighting nodes.
fn three_shadowed_frames(app: &mut App) {
    for _ in 0..3 {
        app.update();
    }
    assert_eq!(
        renderer(app).graph_order(),
        ["shadow", "depth prepass", "visibility resolve", "forward"]
    );
}

fn renderer_mut(app: &mut App) -> bevy_ecs::world::Mut<'_, Renderer> {
    app.world_mut().resource_mut::<Renderer>()
}

#[test]
fn shadow_node_runs_only_when_a_light_casts_and_the_depth_buffer_is_pooled() {
    let mut app = app();
    three_shadowed_frames(&mut app);
    let r = renderer(&app);
    // No light filters moments and no sun fits to the depths seen: the moments nodes and the
    // depth-bounds reduction are culled.
    assert_eq!(
        r.graph_culled(),
        ["shadow moments", "shadow cascade moments", "pages", "depth bounds"]
    );
    // Three frames of one size: the camera depth was created once and reused.
    // The camera depth, normals (for the compute resolve) and shading ids (for the deferred
    // lighting), each created once (MSAA is off by default: no multisampled colour).
    assert_eq!(r.counters().transient_resources, 3, "{:?}", r.counters());

    let world = app.world_mut();
    let mut suns = world.query::<&mut DirectionalLight>();
    for mut sun in suns.iter_mut(world) {
        sun.shadows_enabled = false;
    }
    app.update();
    let r = renderer(&app);
    assert_eq!(
        r.graph_order(),
        ["depth prepass", "forward"],
        "no shadow view, yet the shadow node ran"
    );
    assert_eq!(
        r.graph_culled(),
        [
            "shadow",
            "shadow moments",
            "shadow cascade moments",
            "pages",
            "visibility resolve",
            "depth bounds"
        ]
    );
    // Nothing new: the pooled depth serves this frame too.
    assert_eq!(r.counters().transient_resources, 3);
}

/// Overwrites the colour target with one colour; counts its recordings.
struct Paint {
    color: Option<TextureId>,
    recorded: Arc<AtomicU32>,
}

impl RenderNode for Paint {
    fn name(&self) -> &'static str {
        "paint"
    }

    fn setup(&mut self, pass: &mut PassBuilder<'_>, frame: &mut FrameResources, _: &FrameInputs<'_>) {
        pass.read(frame.color);
        self.color = Some(pass.write(frame.color));
    }

    fn record(&mut self, _: &mut FrameContext<'_>, resources: &GraphResources, encoder: &mut wgpu::CommandEncoder) {
        self.recorded.fetch_add(1, Ordering::Relaxed);
        let Some(color) = self.color else { return };
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("paint"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: resources.view(color),
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: 1.0,
                        g: 0.0,
                        b: 1.0,
                        a: 1.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
    }
}

/// Makes a scratch texture nothing reads: culled, so never recorded.
struct Unread {
    recorded: Arc<AtomicU32>,
}

impl RenderNode for Unread {
    fn name(&self) -> &'static str {
        "unread"
    }

    fn setup(&mut self, pass: &mut PassBuilder<'_>, _: &mut FrameResources, _: &FrameInputs<'_>) {
        pass.create_texture(TextureDesc {
            label: "scratch",
            width: 16,
            height: 16,
            layers: 1,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            samples: 1,
        });
    }

    fn record(&mut self, _: &mut FrameContext<'_>, _: &GraphResources, _: &mut wgpu::CommandEncoder) {
        self.recorded.fetch_add(1, Ordering::Relaxed);
    }
}

#[test]
fn a_custom_node_runs_after_what_it_reads_and_an_unread_one_is_culled() {
    let mut app = app();
    let (painted, unread) = (Arc::new(AtomicU32::new(0)), Arc::new(AtomicU32::new(0)));
    // Added before nothing in particular: the graph puts "paint" after "forward", which
    // writes the colour it reads.
    renderer_mut(&mut app).add_node(Box::new(Unread {
        recorded: Arc::clone(&unread),
    }));
    renderer_mut(&mut app).add_node(Box::new(Paint {
        color: None,
        recorded: Arc::clone(&painted),
    }));
    app.update();
    app.update();
    let r = renderer(&app);
    assert_eq!(
        r.graph_order(),
        ["shadow", "depth prepass", "visibility resolve", "forward", "paint"]
    );
    assert_eq!(
        r.graph_culled(),
        [
            "shadow moments",
            "shadow cascade moments",
            "pages",
            "depth bounds",
            "unread"
        ]
    );
    assert_eq!(painted.load(Ordering::Relaxed), 2);
    assert_eq!(unread.load(Ordering::Relaxed), 0, "a culled node was recorded");
    // The culled node's transient was never allocated: only the camera depth, normals and
    // shading ids were.
    assert_eq!(r.counters().transient_resources, 3);
    let image = r.read_image();
    let magenta = image.pixels().filter(|p| p.0 == [255, 0, 255, 255]).count();
    assert_eq!(magenta, 320 * 180, "the custom node did not paint the whole frame last");
}

/// `scene` in a headless app at 160×90 (with analysis targets) rendering with `options`, the
/// filter taps not rotated per frame (identical frames), one frame rendered; asserts the
/// device reported no error.
fn render_scene(scene: &str, options: RenderOptions) -> App {
    let gpu = Renderer::headless_with_analysis(160, 90)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = still_scene(gpu, scene);
    *app.world_mut().resource_mut::<RenderOptions>() = options;
    app.update();
    let errors = app.world_mut().resource_mut::<Renderer>().take_errors();
    assert!(errors.is_empty(), "{scene}: {errors:?}");
    app
}

/// Renders `scene` with the depth prepass on or off (shadows filtered in the lighting pass
/// either way); returns the image and the graph's order.
fn render_with_prepass(scene: &str, prepass: DepthPrepass) -> (image::RgbaImage, Vec<&'static str>) {
    let app = render_scene(
        scene,
        RenderOptions {
            depth_prepass: prepass,
            visibility_resolve: false,
            ..RenderOptions::default()
        },
    );
    let r = renderer(&app);
    (r.read_image(), r.graph_order())
}

#[test]
fn the_depth_prepass_changes_no_pixel() {
    // The garden has alpha-masked, double-sided fern leaves over the ground.
    for scene in ["assets/scenes/default.ron", "assets/scenes/garden.ron"] {
        let (with, order) = render_with_prepass(scene, DepthPrepass::On);
        assert_eq!(order, ["shadow", "depth prepass", "forward"], "{scene}");
        let (without, order) = render_with_prepass(scene, DepthPrepass::Off);
        assert_eq!(order, ["shadow", "forward"], "{scene}");
        let differing = with.pixels().zip(without.pixels()).filter(|(a, b)| a != b).count();
        // The frames judged something: most pixels are geometry, not sky.
        let sky = with.get_pixel(0, 0).0;
        let drawn = with.pixels().filter(|p| p.0 != sky).count();
        assert!(drawn > 160 * 90 / 3, "{scene}: only {drawn} pixels of geometry");
        assert_eq!(
            differing, 0,
            "{scene}: {differing} of {drawn} drawn pixels differ with the prepass"
        );
    }
}

#[test]
fn a_kept_prepass_draws_into_no_transient() {
    let mut app = app_sized(320, 180);
    three_shadowed_frames(&mut app);
    let r = renderer(&app);
    assert!(r.last_report.prepass_kept, "a still frame kept the prepass");
    // The camera depth, normals and ids are the renderer's kept textures, imported.
    assert_eq!(r.counters().transient_resources, 0, "{:?}", r.counters());
}

#[test]
fn the_automatic_prepass_runs_only_below_one_triangle_per_pixel() {
    // The default scene has tens of thousands of triangles drawn whole: more than 64×40
    // pixels, fewer than 320×180. (With its LOD the camera draws its spheres coarser at 64×40,
    // under one triangle a pixel.) Occlusion culling off: it runs the prepass whatever the count.
    let mut small = app_sized(64, 40);
    small.insert_resource(CameraLod { max_error_pixels: 0.0 });
    // NOTE: the occlusion culling would turn the automatic prepass on.
    small.insert_resource(RenderOptions {
        occlusion_culling: false,
        ..RenderOptions::default()
    });
    small.update();
    assert_eq!(renderer(&small).graph_order(), ["shadow", "forward"]);
    assert_eq!(
        renderer(&small).graph_culled(),
        [
            "shadow moments",
            "shadow cascade moments",
            "depth prepass",
            "pages",
            "visibility resolve",
            "depth bounds"
        ]
    );
    let mut large = app();
    large.update();
    assert_eq!(
        renderer(&large).graph_order(),
        ["shadow", "depth prepass", "visibility resolve", "forward"]
    );
}

/// Renders `scene` with or without the compute resolve (prepass on); returns the image, the
/// analysis shadow factors and the graph's order.
fn render_resolved(scene: &str, resolve: bool) -> (image::RgbaImage, Vec<f32>, Vec<&'static str>) {
    let app = render_scene(
        scene,
        RenderOptions {
            depth_prepass: DepthPrepass::On,
            visibility_resolve: resolve,
            ..RenderOptions::default()
        },
    );
    let r = renderer(&app);
    let analysis = r.read_analysis().expect("analysis targets");
    (r.read_image(), analysis.shadow, r.graph_order())
}

#[test]
fn the_compute_resolve_matches_the_lighting_pass_filters() {
    // Suns with PCSS and PCF, alpha-masked ferns, and spot lights.
    for scene in [
        "assets/scenes/default.ron",
        "assets/scenes/garden.ron",
        "assets/scenes/lights.ron",
    ] {
        let (resolved, resolved_shadow, order) = render_resolved(scene, true);
        assert_eq!(
            order,
            ["shadow", "depth prepass", "visibility resolve", "forward"],
            "{scene}"
        );
        let (direct, direct_shadow, order) = render_resolved(scene, false);
        assert_eq!(order, ["shadow", "depth prepass", "forward"], "{scene}");
        // The shadow factor of the focus light, pixel by pixel.
        let judged = direct_shadow.iter().filter(|s| **s < 1.0).count();
        assert!(judged > 300, "{scene}: only {judged} shadowed pixels");
        let diffs: Vec<f32> = resolved_shadow
            .iter()
            .zip(&direct_shadow)
            .map(|(a, b)| (a - b).abs())
            .collect();
        let mean = diffs.iter().sum::<f32>() / diffs.len() as f32;
        let off = diffs.iter().filter(|d| **d > 0.1).count();
        let colour_off = resolved
            .pixels()
            .zip(direct.pixels())
            .filter(|(a, b)| a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > 8))
            .count();
        // NOTE: the resolve rebuilds the position from depth, the lighting pass interpolates
        // it: a tap may land on the other side of a texel edge. Limits: three times what
        // lavapipe measured (mean 1.2e-6 at most, no value or colour off); a GPU whose
        // rounding differs may put a few pixels over them.
        let pixels = diffs.len();
        println!("{scene}: mean {mean}, {off} shadow values and {colour_off} colours of {pixels} off");
        assert!(mean <= 4e-6, "{scene}: mean shadow difference {mean}");
        assert_eq!(off, 0, "{scene}: {off} of {pixels} shadow values differ by > 0.1");
        assert_eq!(
            colour_off, 0,
            "{scene}: {colour_off} of {pixels} colours differ by > 8/255"
        );
    }
}

#[test]
fn the_lighting_pass_without_filters_shows_the_resolved_shadows() {
    // Without analysis targets, a resolved frame's lighting pass is built without the filters
    // (it only reads the resolved visibility): its image matches a frame that filters in the
    // lighting pass. Spot and point lights in every filter mode, and suns.
    for scene in [
        "assets/scenes/night.ron",
        "assets/scenes/point.ron",
        "assets/scenes/lights.ron",
    ] {
        let image = |resolve: bool| {
            let gpu = Renderer::headless(160, 90).expect(
                "no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)",
            );
            let mut app = still_scene(gpu, scene);
            // NOTE: one sample per pixel: with MSAA a pixel on an edge reads the shadow
            // resolved at its sample 0, which may be another surface's (tests/foliage.rs
            // checks that MSAA frames differ only there).
            *app.world_mut().resource_mut::<RenderOptions>() = RenderOptions {
                depth_prepass: DepthPrepass::On,
                visibility_resolve: resolve,
                msaa: Msaa::Off,
                ..RenderOptions::default()
            };
            app.update();
            let r = renderer(&app);
            assert_eq!(r.graph_order().contains(&"visibility resolve"), resolve, "{scene}");
            r.read_image()
        };
        let (resolved, direct) = (image(true), image(false));
        let pixels = (resolved.width() * resolved.height()) as usize;
        let colour_off = resolved
            .pixels()
            .zip(direct.pixels())
            .filter(|(a, b)| a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > 8))
            .count();
        // The frames judged something: most pixels are geometry, not sky.
        let sky = resolved.get_pixel(0, 0).0;
        let drawn = resolved.pixels().filter(|p| p.0 != sky).count();
        assert!(drawn > pixels / 3, "{scene}: only {drawn} pixels of geometry");
        assert!(
            colour_off * 200 <= pixels,
            "{scene}: {colour_off} of {pixels} colours differ by > 8/255"
        );
    }
}
