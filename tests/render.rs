//! Reference-image tests on a real wgpu device (Mesa's lavapipe in CI): shadows land under
//! casters and not on open ground, the PCSS penumbra widens with the caster's height, the
//! cascade debug view orders cascades by distance, and the default scene matches its
//! reference image within a tolerance.
//!
//! Regenerate the reference image with `PENUMBRA_BLESS=1 cargo test --test render`.

use glam::{Vec3, Vec4};
use image::RgbaImage;
use penumbra::app::{HeadlessFrame, render_scene};
use penumbra::math::frustum::CameraView;
use penumbra::scene::SceneDesc;

/// Renders, or fails with the driver-install hint when there is no adapter.
fn render(desc: &SceneDesc, width: u32, height: u32) -> HeadlessFrame {
    render_scene(desc, width, height, 2, None).unwrap_or_else(|e| panic!("rendering failed: {e}"))
}

fn scene(text: &str) -> SceneDesc {
    SceneDesc::from_str(text, "test.ron").unwrap_or_else(|e| panic!("{e}"))
}

/// Pixel position of a world point for the scene's camera.
fn project(desc: &SceneDesc, width: u32, height: u32, p: Vec3) -> (u32, u32) {
    let c = &desc.camera;
    let forward = (c.target - c.position).normalize();
    let right = forward.cross(c.up).normalize();
    let up = right.cross(forward);
    let world_from_view = glam::Mat4::from_cols(
        right.extend(0.0),
        up.extend(0.0),
        (-forward).extend(0.0),
        c.position.extend(1.0),
    );
    let view = CameraView {
        world_from_view,
        fov_y: c.fov.to_radians(),
        aspect: width as f32 / height as f32,
        near: c.near,
        far: c.far,
    };
    let clip = view.clip_from_world() * Vec4::new(p.x, p.y, p.z, 1.0);
    let ndc = clip.truncate() / clip.w;
    let x = ((ndc.x * 0.5 + 0.5) * width as f32) as u32;
    let y = ((0.5 - ndc.y * 0.5) * height as f32) as u32;
    (x.min(width - 1), y.min(height - 1))
}

fn luma(image: &RgbaImage, (x, y): (u32, u32)) -> f32 {
    lum(image.get_pixel(x, y))
}

const SHADOW_SCENE: &str = r#"Scene(
    camera: (position: (0, 12, 10), target: (0, 0, 0), fov: 50, near: 0.1, far: 100),
    sun: (direction: (0, -1, 0), illuminance: 2.0, angular_diameter: 0.53),
    ambient: (0.1, 0.1, 0.1),
    shadows: (mode: Pcf, pcf_radius: 1, cascade_count: 2, resolution: 1024, max_distance: 40),
    materials: { "ground": (base_color: (0.7, 0.7, 0.7, 1)), "box": (base_color: (0.8, 0.3, 0.2, 1)) },
    objects: [
        (shape: Plane(size: (40, 40)), material: "ground", cast_shadows: false),
        (shape: Cuboid(size: (2, 0.2, 2)), material: "box", translation: (0, 2, 0)),
    ],
)"#;

#[test]
fn shadow_falls_under_the_caster_and_not_on_open_ground() {
    let desc = scene(SHADOW_SCENE);
    let (w, h) = (160, 120);
    let frame = render(&desc, w, h);
    // The slab hovers 2 m above the ground and the sun is overhead: its shadow is the 2×2 m
    // square under it. The camera looks down from the front, so the ground at z = +0.9 is
    // in shadow but visible past the slab's front edge.
    let shadowed = luma(&frame.image, project(&desc, w, h, Vec3::new(0.0, 0.0, 0.9)));
    let open = luma(&frame.image, project(&desc, w, h, Vec3::new(5.0, 0.0, 3.0)));
    assert!(open > 0.5, "open ground should be lit, luma {open}");
    assert!(
        shadowed < 0.25 * open,
        "ground under the slab should be shadowed: {shadowed} vs lit {open}"
    );
    // The ground under the slab lies in cascade 1, which draws it; cascade 0's slice (nearer
    // the camera) holds no receiver its shadow can reach, so receiver culling leaves it out.
    assert_eq!(
        frame.stats.casters_per_view,
        [0, 1],
        "the slab is drawn into the cascade its shadow lands in, and only there"
    );
    assert!(frame.warnings.is_empty(), "{:?}", frame.warnings);
}

/// Width in pixels of the transition from shadow to light along a horizontal row.
fn penumbra_width(image: &RgbaImage, y: u32, x0: u32, x1: u32, dark: f32, lit: f32) -> u32 {
    let lo = dark + 0.1 * (lit - dark);
    let hi = dark + 0.9 * (lit - dark);
    (x0..x1).filter(|&x| (lo..hi).contains(&luma(image, (x, y)))).count() as u32
}

#[test]
fn pcss_penumbra_grows_with_caster_height() {
    // Two boards with edges along z, under a 45° sun with a wide (4°) disc: shadows fall
    // towards +x, displaced by the board's height. The low board is 0.5 m up, the high one
    // 3 m: the high board's penumbra must be much wider.
    let text = r#"Scene(
        camera: (position: (0, 14, 0.01), target: (0, 0, 0), fov: 40, near: 0.5, far: 100),
        sun: (direction: (1, -1, 0), illuminance: 2.0, angular_diameter: 4.0),
        ambient: (0.05, 0.05, 0.05),
        shadows: (mode: Pcss, pcss_quality: High, cascade_count: 1, resolution: 2048, max_distance: 30, blocker_early_out: false),
        materials: { "ground": (base_color: (0.8, 0.8, 0.8, 1)), "wall": (base_color: (0.5, 0.5, 0.5, 1)) },
        objects: [
            (shape: Plane(size: (40, 40)), material: "ground", cast_shadows: false),
            (shape: Cuboid(size: (2, 0.1, 3)), material: "wall", translation: (-3, 0.5, -2.5)),
            (shape: Cuboid(size: (2, 0.1, 3)), material: "wall", translation: (-3, 3.0, 2.5)),
        ],
    )"#;
    let desc = scene(text);
    let (w, h) = (256, 256);
    let frame = render(&desc, w, h);
    let img = &frame.image;
    let px = |x: f32, z: f32| project(&desc, w, h, Vec3::new(x, 0.0, z));
    let lit = luma(img, px(3.5, 0.0));
    // Low board: shadow spans x in [-3.5, -1.5], visible right of the board (x > -2).
    let dark_low = luma(img, px(-1.75, -2.5));
    let low = penumbra_width(img, px(0.0, -2.5).1, px(-1.7, 0.0).0, px(0.5, 0.0).0, dark_low, lit);
    // High board: shadow spans x in [-1, 1].
    let dark_high = luma(img, px(0.0, 2.5));
    let high = penumbra_width(img, px(0.0, 2.5).1, px(0.2, 0.0).0, px(3.0, 0.0).0, dark_high, lit);
    eprintln!("penumbra widths: low {low} px, high {high} px; lit {lit:.3}, umbrae {dark_low:.3} {dark_high:.3}");
    assert!(
        dark_low < 0.5 * lit && dark_high < 0.5 * lit,
        "umbrae dark: {dark_low} {dark_high} vs lit {lit}"
    );
    // 3 m above the ground along a 45° ray, a 4° disc spreads ≈ 0.42 m ≈ 10 px here;
    // 0.5 m gives ≈ 2 px.
    assert!(
        high >= 5,
        "high caster penumbra is {high} px wide, expected a visible penumbra"
    );
    assert!(
        high >= 2 * low.max(1),
        "penumbra should widen with height: low {low} px, high {high} px"
    );
}

/// Index of the debug colour a pixel is closest to: red, green, blue, yellow.
fn cascade_of(image: &RgbaImage, p: (u32, u32)) -> usize {
    let c = image.get_pixel(p.0, p.1).0;
    let (r, g, b) = (c[0] as f32, c[1] as f32, c[2] as f32);
    let scores = [r - g.max(b), g - r.max(b), b - r.max(g), r.min(g) - b];
    (0..4).max_by(|&a, &b| scores[a].total_cmp(&scores[b])).unwrap()
}

#[test]
fn cascade_debug_colours_follow_distance() {
    let text = r#"Scene(
        camera: (position: (0, 3, 0), target: (0, 2.2, -20), fov: 60, near: 0.1, far: 300),
        sun: (direction: (0.3, -1, 0.2)),
        ambient: (0.3, 0.3, 0.3),
        shadows: (cascade_count: 4, resolution: 512, max_distance: 120, split_lambda: 0.7, debug_view: Cascades, blend_width: 0.0),
        materials: { "ground": (base_color: (0.8, 0.8, 0.8, 1)) },
        objects: [ (shape: Plane(size: (400, 400)), material: "ground", cast_shadows: false) ],
    )"#;
    let desc = scene(text);
    let (w, h) = (96, 160);
    let frame = render(&desc, w, h);
    let mut seen = Vec::new();
    for z in [2.0f32, 5.0, 9.0, 16.0, 28.0, 45.0, 70.0, 100.0] {
        let p = project(&desc, w, h, Vec3::new(0.0, 0.0, -z));
        seen.push(cascade_of(&frame.image, p));
    }
    assert!(
        seen.windows(2).all(|w| w[0] <= w[1]),
        "cascade index must not decrease with distance: {seen:?}"
    );
    assert_eq!(seen.first(), Some(&0), "{seen:?}");
    assert_eq!(seen.last(), Some(&3), "{seen:?}");
    for c in 0..4 {
        assert!(seen.contains(&c), "cascade {c} never seen: {seen:?}");
    }
}

/// Mean absolute difference and the fraction of channels differing by more than 16/255.
fn image_difference(a: &RgbaImage, b: &RgbaImage) -> (f64, f64) {
    let mut sum = 0.0;
    let mut big = 0usize;
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        for c in 0..3 {
            let d = (pa.0[c] as i32 - pb.0[c] as i32).abs();
            sum += d as f64;
            big += (d > 16) as usize;
        }
    }
    let n = (a.width() * a.height() * 3) as f64;
    (sum / n / 255.0, big as f64 / n)
}

#[test]
fn default_scene_matches_its_reference_image() {
    use penumbra::app::{RenderRequest, render_scene_with};
    use penumbra::render::{Msaa, RenderOptions};

    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/default.ron");
    let desc = SceneDesc::load(path).unwrap_or_else(|e| panic!("{e}"));
    // NOTE: one sample per pixel, as the reference was made before MSAA (on by default now,
    // it antialiases every edge: mean 0.0102, 3.5 % of channels off by more than 16; MSAA's
    // edges are tested in tests/foliage.rs). The mip chains of base-colour textures, which
    // the foliage cards' alpha test reads at a distance, moved this image by a mean 0.0038,
    // 0.83 % of channels.
    let tweak = |s: &mut penumbra::settings::ShadowSettings| s.map.resolution = 1024;
    let request = RenderRequest {
        width: 320,
        height: 180,
        frames: 2,
        tweak: Some(&tweak),
        analysis: false,
        options: RenderOptions {
            msaa: Msaa::Off,
            ..RenderOptions::default()
        },
        shadow_budget: None,
        count_fragments: false,
        camera_lod: None,
        camera_motion: Default::default(),
    };
    let frame = render_scene_with(&desc, &request).unwrap_or_else(|e| panic!("rendering failed: {e}"));
    let reference_path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/reference/default_320x180.png");
    if std::env::var_os("PENUMBRA_BLESS").is_some() {
        frame.image.save(reference_path).unwrap();
    }
    let reference = image::open(reference_path)
        .unwrap_or_else(|e| panic!("{reference_path}: {e}; run with PENUMBRA_BLESS=1 to create it"))
        .to_rgba8();
    assert_eq!(reference.dimensions(), frame.image.dimensions());
    let (mean, big) = image_difference(&frame.image, &reference);
    if mean > 0.01 || big > 0.01 {
        let out = std::env::temp_dir().join("penumbra_default_actual.png");
        frame.image.save(&out).unwrap();
        panic!(
            "image differs from the reference: mean {mean:.4}, {:.2}% channels off by >16; actual saved to {}",
            big * 100.0,
            out.display()
        );
    }
}

/// Renders a scene file twice, with and without the shadows of its suns, spot and point
/// lights.
fn render_with_and_without_shadows(path: &std::path::Path, width: u32, height: u32) -> (RgbaImage, RgbaImage) {
    use penumbra::app::{headless_app, spawn_scene};
    use penumbra::ecs::DirectionalLight;
    use penumbra::ecs::lights::{PointLight, SpotLight};
    use penumbra::render::Renderer;

    let mut desc = SceneDesc::load(path).unwrap_or_else(|e| panic!("{e}"));
    desc.shadows.map.resolution = 1024;
    let mut images = Vec::new();
    for shadows in [true, false] {
        let renderer = Renderer::headless(width, height).unwrap_or_else(|e| panic!("{e}"));
        let mut app = headless_app(renderer);
        spawn_scene(app.world_mut(), &desc).unwrap_or_else(|e| panic!("{e}"));
        let world = app.world_mut();
        let mut lights = world.query::<&mut DirectionalLight>();
        for mut light in lights.iter_mut(world) {
            light.shadows_enabled = shadows;
        }
        let mut spots = world.query::<&mut SpotLight>();
        for mut light in spots.iter_mut(world) {
            light.shadows_enabled = shadows;
        }
        let mut points = world.query::<&mut PointLight>();
        for mut light in points.iter_mut(world) {
            light.shadows_enabled = shadows;
        }
        app.update();
        images.push(app.world().resource::<Renderer>().read_image());
    }
    let without = images.pop().unwrap();
    (images.pop().unwrap(), without)
}

#[test]
fn every_shipped_scene_renders_with_visible_shadows() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes");
    let mut paths: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    paths.sort();
    assert!(paths.len() >= 4);
    for path in paths {
        let (with, without) = render_with_and_without_shadows(&path, 192, 108);
        let mut darker = 0;
        let mut brighter = 0;
        for (a, b) in with.pixels().zip(without.pixels()) {
            let (la, lb) = (lum(a), lum(b));
            if la < lb - 0.1 {
                darker += 1;
            }
            if la > lb + 2.0 / 255.0 {
                brighter += 1;
            }
        }
        let n = (with.width() * with.height()) as f64;
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        assert!(darker as f64 / n > 0.01, "{name}: only {darker} pixels are shadowed");
        assert_eq!(brighter, 0, "{name}: shadows must only darken");
    }
}

fn lum(p: &image::Rgba<u8>) -> f32 {
    (0.2126 * p.0[0] as f32 + 0.7152 * p.0[1] as f32 + 0.0722 * p.0[2] as f32) / 255.0
}

#[test]
fn analysis_targets_and_probes_agree_with_the_image() {
    use penumbra::app::spawn_scene;
    use penumbra::ecs::ShadowPlugin;
    use penumbra::render::Renderer;
    use penumbra::render::frame::FrameInputs;
    use penumbra::render::probe::ProbeGpu;

    for mode in ["Pcf", "Pcss"] {
        let desc = scene(&SHADOW_SCENE.replace("mode: Pcf", &format!("mode: {mode}")));
        let (w, h) = (96, 72);
        let mut renderer = Renderer::headless_with_analysis(w, h).unwrap_or_else(|e| panic!("{e}"));
        let mut app = bevy_app::App::new();
        app.add_plugins(ShadowPlugin);
        app.world_mut()
            .insert_resource(penumbra::ecs::ViewportSize { width: w, height: h });
        spawn_scene(app.world_mut(), &desc).unwrap();
        app.update();
        renderer.render(&FrameInputs::from_world(app.world(), 0));
        let a = renderer.read_analysis().expect("analysis targets");
        let at = |p: Vec3| {
            let (x, y) = project(&desc, w, h, p);
            (y * w + x) as usize
        };
        let under = at(Vec3::new(0.0, 0.0, 0.9));
        let open = at(Vec3::new(5.0, 0.0, 3.0));
        assert!(a.evaluated[under] && a.evaluated[open], "{mode}");
        assert!(
            a.shadow[under] < 0.05,
            "{mode}: shadow factor under the slab is {}",
            a.shadow[under]
        );
        assert!(
            a.shadow[open] > 0.95,
            "{mode}: shadow factor on open ground is {}",
            a.shadow[open]
        );
        assert!(
            (a.position[open] - Vec3::new(5.0, 0.0, 3.0)).length() < 0.3,
            "{:?}",
            a.position[open]
        );
        assert!(a.normal[open].abs_diff_eq(Vec3::Y, 1e-3));
        assert!(
            a.cascade[open] < 2 && a.cascade[under] < 2,
            "two cascades: {} {}",
            a.cascade[open],
            a.cascade[under]
        );
        // The probe pass evaluates the same function at the same points: same values.
        let pixels: Vec<usize> = (0..a.shadow.len()).filter(|&i| a.evaluated[i]).collect();
        let probes: Vec<ProbeGpu> = pixels
            .iter()
            .map(|&i| ProbeGpu::new(a.position[i], a.normal[i], ((i as u32) % w, (i as u32) / w)))
            .collect();
        let values = renderer.evaluate_probes(&FrameInputs::from_world(app.world(), 0), &probes);
        let worst = pixels
            .iter()
            .zip(&values)
            .map(|(&i, v)| (a.shadow[i] - v).abs())
            .fold(0.0f32, f32::max);
        assert!(
            worst < 0.02,
            "{mode}: probes differ from the fragment shader by up to {worst}"
        );
    }
}
