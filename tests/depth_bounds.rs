//! The depth-bounds (SDSM) cascade fit on a real wgpu device (lavapipe in CI): the GPU's
//! reduction of the camera's depth comes back to the ECS and matches the depths and positions
//! of the pixels the frame covered (with and without the depth prepass); the next frames
//! split the seen range logarithmically, with finer texels near the camera, and cast the
//! same shadows as the tight fit; a sun that fits otherwise leaves the reduction culled.

mod common;

use bevy_app::App;
use common::still_scene;
use glam::Vec3;
use penumbra::ecs::{FrameLights, SeenByCamera};
use penumbra::math::seen_depths::band_of;
use penumbra::math::splits::pssm_splits;
use penumbra::render::target::AnalysisImage;
use penumbra::render::{DepthPrepass, RenderOptions, Renderer};
use penumbra::settings::{CascadeFit, ShadowSettings};

const SCENE: &str = "assets/scenes/default.ron";

/// Share of a pixel's depth by which the reduction (rebuilt from the depth buffer) and the
/// analysis target (interpolated) may disagree when choosing its band: twice the 5.1e-6
/// lavapipe measured between their farthest depths.
const EDGE: f32 = 1e-5;

/// How far outside its band's box a covered pixel may lie, as a share of its depth: three
/// times what lavapipe measured (2.6e-5).
const WORST_OUTSIDE: f32 = 8e-5;

/// The default scene at 320×180 with analysis targets, every sun fitted with `fit`, after
/// `frames` frames (each waiting for its depths to come back).
fn app(fit: CascadeFit, frames: usize) -> App {
    app_with(fit, frames, DepthPrepass::Auto)
}

/// [`app`] with the depth prepass `prepass` (off: the lighting pass writes the depth the
/// reduction reads).
fn app_with(fit: CascadeFit, frames: usize, prepass: DepthPrepass) -> App {
    let renderer = Renderer::headless_with_analysis(320, 180)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let mut app = still_scene(renderer, SCENE);
    app.insert_resource(RenderOptions {
        depth_prepass: prepass,
        ..RenderOptions::default()
    });
    let world = app.world_mut();
    let mut settings = world.query::<&mut ShadowSettings>();
    for mut s in settings.iter_mut(world) {
        s.map.cascades.fit = fit;
    }
    for _ in 0..frames {
        app.update();
        let world = app.world_mut();
        world.resource_mut::<Renderer>().wait_for_seen_depths();
        world.resource_scope(|world, renderer: bevy_ecs::change_detection::Mut<Renderer>| {
            penumbra::render::plugin::publish_seen_depths(world, &renderer);
        });
    }
    app
}

fn analysis(app: &App) -> AnalysisImage {
    app.world()
        .resource::<Renderer>()
        .read_analysis()
        .expect("analysis targets")
}

/// View depth of `p` (render-space) for the app's camera.
fn view_depth(app: &App, p: Vec3) -> f32 {
    let view = app.world().resource::<penumbra::ecs::ActiveView>();
    let (camera, _) = view.camera.expect("a camera");
    -(camera.world_from_view.inverse() * p.extend(1.0)).z
}

#[test]
fn the_reduction_holds_every_covered_pixel_with_and_without_the_prepass() {
    for prepass in [DepthPrepass::On, DepthPrepass::Off] {
        judge_reduction(&app_with(CascadeFit::DepthBounds, 1, prepass));
    }
}

/// Asserts the depths `app` saw hold every pixel its last frame covered.
fn judge_reduction(app: &App) {
    let seen = app.world().resource::<SeenByCamera>();
    let depths = seen.depths.expect("the frame's depths came back");
    let image = analysis(app);
    let (mut near, mut far, mut covered) = (f32::INFINITY, 0.0f32, 0usize);
    // How far (relative to its depth) a pixel lies outside the box of its band, or of a band
    // next to it when its depth sits at a band's edge.
    let outside = |b: &penumbra::math::aabb::Aabb, p: Vec3| (b.min - p).max(p - b.max).max(Vec3::ZERO).max_element();
    let mut worst = 0.0f32;
    for p in image.position.iter().filter(|p| p.is_finite()) {
        let d = view_depth(app, *p);
        near = near.min(d);
        far = far.max(d);
        covered += 1;
        let band = |depth: f32| depths.bands[band_of(depth, depths.band_near, depths.band_far)];
        let excess = [d, d * (1.0 - EDGE), d * (1.0 + EDGE)]
            .into_iter()
            .map(|depth| outside(&band(depth), *p))
            .fold(f32::INFINITY, f32::min);
        worst = worst.max(excess / d);
    }
    println!("the worst pixel lies {worst:.2e} of its depth outside its band's box");
    assert!(
        worst <= WORST_OUTSIDE,
        "a pixel lies {worst:.2e} of its depth outside its band's box"
    );
    println!(
        "covered {covered} pixels: depths {near}..{far}, reduced {}..{}",
        depths.near, depths.far
    );
    assert!(covered > 20_000, "only {covered} covered pixels judged");
    // NOTE: the reduction rebuilds depths from the depth buffer, the analysis target
    // interpolates positions: lavapipe measured them 3.4e-7 (near) and 5.1e-6 (far) apart,
    // relative to the depth.
    let (dn, df) = ((depths.near - near).abs() / near, (depths.far - far).abs() / far);
    assert!(dn <= 1.5e-5, "near {} against {near}: {dn:.2e} apart", depths.near);
    assert!(df <= 1.5e-5, "far {} against {far}: {df:.2e} apart", depths.far);
}

#[test]
fn cascades_split_the_seen_depths_and_cast_the_tight_fits_shadows() {
    let fitted = app(CascadeFit::DepthBounds, 3);
    let tight = app(CascadeFit::Tight, 3);
    let sets = |app: &App| app.world().resource::<FrameLights>().suns[0].cascades;
    let (a, b) = (sets(&fitted), sets(&tight));
    let depths = fitted.world().resource::<SeenByCamera>().depths.expect("depths");
    println!(
        "splits: depth bounds {:?}, tight {:?}; seen {}..{}",
        a.splits, b.splits, depths.near, depths.far
    );
    assert_eq!(a.end, b.end, "shadows end where the tight fit ends them");
    // Logarithmic splits between the nearest and farthest depths seen (guarded), the first
    // cascade from the near plane.
    let (lo, hi) = depths.guarded_range();
    let mut expected = pssm_splits(lo, hi.min(a.end), a.count, 1.0);
    expected[0] = b.splits[0];
    assert_eq!(a.splits, expected, "the splits follow the seen depths");
    assert!(
        a.splits[a.count] >= depths.far.min(a.end),
        "the last split covers every depth seen that shadows reach"
    );
    let texels = |set: &penumbra::math::cascades::CascadeSet| {
        set.active().iter().map(|c| c.texel_world_size).collect::<Vec<_>>()
    };
    println!("texels: depth bounds {:?}, tight {:?}", texels(&a), texels(&b));
    // Nothing nearer than 2.7 m was seen: the first cascade's texels are finer.
    assert!(texels(&a)[0] < texels(&b)[0], "cascade 0's texels are not finer");
    let (fa, fb) = (analysis(&fitted), analysis(&tight));
    let judged: Vec<usize> = (0..fa.shadow.len())
        .filter(|&i| fa.evaluated[i] && fb.evaluated[i])
        .collect();
    let dark = |f: &AnalysisImage| judged.iter().filter(|&&i| f.shadow[i] < 0.5).count();
    let (da, db) = (dark(&fa), dark(&fb));
    let differ = judged
        .iter()
        .filter(|&&i| (fa.shadow[i] < 0.5) != (fb.shadow[i] < 0.5))
        .count();
    println!(
        "{} judged: {da} shadowed (depth bounds), {db} (tight), {differ} differ",
        judged.len()
    );
    assert!(
        judged.len() > 20_000 && db > 2_000,
        "{} judged, {db} shadowed",
        judged.len()
    );
    // NOTE: lavapipe measured 145 of 32 381 (0.45 %): the boxes' texels differ, so the
    // edges move by up to a texel.
    assert!(
        differ * 100 <= judged.len(),
        "{differ} of {} pixels change sides",
        judged.len()
    );
}

#[test]
fn other_fits_leave_the_reduction_culled() {
    let app = app(CascadeFit::Tight, 2);
    let renderer = app.world().resource::<Renderer>();
    assert!(
        renderer.graph_culled().contains(&"depth bounds"),
        "{:?}",
        renderer.graph_culled()
    );
    assert_eq!(app.world().resource::<SeenByCamera>().depths, None);
}
