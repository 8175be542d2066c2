//! Contact shadows on the GPU (lavapipe), scored against the ray-traced reference on the
//! contact bench scene (boxes and balls standing on and hovering above the ground) with a
//! coarse shadow map: the march must darken what the map leaks at the casters' bases without
//! closing the lit gaps under the hovering ones, must add nothing where the only caster is
//! off screen, and must give the same image whether the filter is resolved in compute or in
//! the lighting pass.

use penumbra::analysis::metrics::{ErrorMetrics, Thresholds, error_metrics};
use penumbra::bench::run::{Points, evaluated_points};
use penumbra::bench::session::SceneSession;
use penumbra::reference::{ReferenceSettings, near_casters, sun_visibility};
use penumbra::render::frame::FrameInputs;
use penumbra::render::target::AnalysisImage;
use penumbra::render::{RenderOptions, Renderer};
use penumbra::scene::SceneDesc;
use penumbra::settings::{ContactShadows, ShadowDebugView};

const WIDTH: u32 = 640;
const HEIGHT: u32 = 360;
/// The contact band: points within this distance of a caster, metres.
const BAND: f32 = 0.3;
/// The march the tests run: 16 steps over 0.3 m, 5 cm thick.
const CONTACT: ContactShadows = ContactShadows {
    length: 0.3,
    steps: 16,
    thickness: 0.05,
    intensity: 1.0,
};

/// The contact scene with a 512² map, contact shadows as given.
fn scene(contact: ContactShadows) -> SceneDesc {
    let mut desc = SceneDesc::load("assets/bench/contact.ron").expect("contact scene loads");
    desc.shadows.map.resolution = 512;
    desc.shadows.filter.contact = contact;
    desc
}

/// Renders one frame of `desc` with `options` and returns its analysis image and session.
fn render(desc: &SceneDesc, options: RenderOptions) -> (AnalysisImage, Vec<[u8; 4]>, SceneSession) {
    let mut session = SceneSession::new(desc, WIDTH, HEIGHT).expect("scene spawns");
    session.app.insert_resource(options);
    let mut renderer = Renderer::headless_with_analysis(WIDTH, HEIGHT)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    session.update();
    renderer.render(&FrameInputs::from_world(session.app.world(), 0));
    let analysis = renderer.read_analysis().expect("analysis targets");
    let image = renderer.read_image().pixels().map(|p| p.0).collect();
    (analysis, image, session)
}

#[test]
fn contact_shadows_close_the_leak_at_bases_and_keep_the_gaps_lit() {
    let (off, _, session) = render(&scene(ContactShadows::OFF), RenderOptions::default());
    let (on, _, _) = render(&scene(CONTACT), RenderOptions::default());
    let Points { pixels, reference, .. } = evaluated_points(&off);
    assert_eq!(
        evaluated_points(&on).pixels,
        pixels,
        "contact shadows changed the evaluated pixels"
    );
    let sun = session.sun_disc().expect("the scene has a sun");
    let settings = ReferenceSettings {
        max_samples: 64,
        min_samples: 16,
        seed: 7,
    };
    let scene = session.reference_scene();
    let truth: Vec<f32> = sun_visibility(&scene, &sun, &reference, &settings, &|_| {})
        .iter()
        .map(|v| v.value)
        .collect();
    let band = near_casters(&scene, &reference, BAND);
    let t = Thresholds::default();
    let score = |image: &AnalysisImage, include: &dyn Fn(usize) -> bool| -> ErrorMetrics {
        let shadow: Vec<f32> = pixels.iter().map(|&i| image.shadow[i]).collect();
        error_metrics(&shadow, &truth, include, &t)
    };
    let in_band = |k: usize| band[k];
    // PENUMBRA_PIXELS lists the band's leaks left with contact shadows.
    if std::env::var_os("PENUMBRA_PIXELS").is_some() {
        for k in 0..pixels.len() {
            if band[k] && truth[k] <= 0.02 && on.shadow[pixels[k]] > 0.1 {
                let i = pixels[k];
                eprintln!(
                    "leak {} {} pos {:?} n {:?} truth {:.2} off {:.2} on {:.2}",
                    i % WIDTH as usize,
                    i / WIDTH as usize,
                    on.position[i],
                    on.normal[i],
                    truth[k],
                    off.shadow[i],
                    on.shadow[i]
                );
            }
        }
    }
    let (band_off, band_on) = (score(&off, &in_band), score(&on, &in_band));
    let (all_off, all_on) = (score(&off, &|_| true), score(&on, &|_| true));
    eprintln!(
        "band: {} points ({} lit, {} umbra); leak {:.4} -> {:.4}, acne {:.4} -> {:.4}, MAE {:.4} -> {:.4}",
        band_on.pixels,
        band_on.lit_pixels,
        band_on.shadowed_pixels,
        band_off.leak_rate,
        band_on.leak_rate,
        band_off.acne_rate,
        band_on.acne_rate,
        band_off.mae,
        band_on.mae
    );
    eprintln!(
        "frame: {} points; leak {:.4} -> {:.4}, acne {:.4} -> {:.4}",
        all_on.pixels, all_off.leak_rate, all_on.leak_rate, all_off.acne_rate, all_on.acne_rate
    );
    assert!(
        band_on.shadowed_pixels > 300,
        "only {} umbra points in the band",
        band_on.shadowed_pixels
    );
    assert!(
        band_on.lit_pixels > 1000,
        "only {} lit points in the band",
        band_on.lit_pixels
    );
    assert!(
        band_on.leak_rate < 0.8 * band_off.leak_rate,
        "contact shadows left the band's leaks at {:.4} (without: {:.4})",
        band_on.leak_rate,
        band_off.leak_rate
    );
    assert!(
        band_on.mae < band_off.mae,
        "band MAE {:.4} with, {:.4} without",
        band_on.mae,
        band_off.mae
    );
    // The lit gaps under hovering casters and everything else lit stay lit.
    assert!(
        band_on.acne_rate <= band_off.acne_rate + 0.005,
        "contact shadows darkened {:.4} of the band's lit points (without: {:.4})",
        band_on.acne_rate,
        band_off.acne_rate
    );
    assert!(
        all_on.acne_rate <= all_off.acne_rate + 0.0003,
        "frame acne {:.4} with, {:.4} without",
        all_on.acne_rate,
        all_off.acne_rate
    );
}

#[test]
fn a_caster_off_screen_adds_no_contact_shadow() {
    // One tall box left of the view, its shadow falling across the visible ground.
    let text = r#"Scene(
        camera: (position: (0, 1.0, 3.0), target: (0, 0, 0), fov: 50, near: 0.05, far: 100),
        sun: (direction: (1, -0.35, 0), illuminance: 3.0, angular_diameter: 0.53),
        shadows: (mode: Pcf, pcf_radius: 1, resolution: 1024, max_distance: 20),
        materials: {"grey": (base_color: (0.6, 0.6, 0.6, 1))},
        objects: [
            (shape: Plane(size: (40, 40)), material: "grey", cast_shadows: false),
            (shape: Cuboid(size: (0.6, 2.0, 0.6)), material: "grey", translation: (-3.4, 1.0, 0)),
        ],
    )"#;
    let mut desc = SceneDesc::from_str(text, "off_screen.ron").expect("scene parses");
    let (off, _, _) = render(&desc, RenderOptions::default());
    desc.shadows.filter.contact = ContactShadows { length: 2.0, ..CONTACT };
    let (on, _, _) = render(&desc, RenderOptions::default());
    let shadowed = off.shadow.iter().filter(|&&v| v < 0.1).count();
    assert!(shadowed > 500, "the off-screen box shadows only {shadowed} pixels");
    let changed = off
        .shadow
        .iter()
        .zip(&on.shadow)
        .filter(|(a, b)| (*a - *b).abs() > 1e-4)
        .count();
    assert_eq!(changed, 0, "contact shadows changed {changed} pixels");
}

#[test]
fn resolving_in_compute_or_filtering_in_the_lighting_pass_gives_one_image() {
    let desc = scene(CONTACT);
    let resolved = RenderOptions::default();
    assert!(
        resolved.visibility_resolve,
        "the default resolves the filters in compute"
    );
    let (a, _, _) = render(&desc, resolved);
    let unresolved = RenderOptions {
        visibility_resolve: false,
        ..RenderOptions::default()
    };
    let (b, _, _) = render(&desc, unresolved);
    let darkened = a.shadow.iter().filter(|&&v| v < 0.5).count();
    assert!(darkened > 2000, "only {darkened} shadowed pixels compared");
    let (mut differ, mut worst) = (0, 0.0f32);
    for (x, y) in a.shadow.iter().zip(&b.shadow) {
        let d = (x - y).abs();
        worst = worst.max(d);
        differ += usize::from(d > 0.02);
    }
    eprintln!("largest difference {worst}, {differ} pixels over 0.02");
    assert!(
        worst <= 5e-4,
        "{differ} pixels differ by more than 0.02, the largest by {worst}"
    );
}

#[test]
fn the_contact_debug_view_shows_the_term_alone_in_grey() {
    let mut desc = scene(CONTACT);
    desc.shadows.filter.debug_view = ShadowDebugView::Contact;
    let (analysis, image, _) = render(&desc, RenderOptions::default());
    // The pixels where a surface was drawn (the sky keeps its colour).
    let drawn: Vec<[u8; 4]> = image
        .iter()
        .zip(&analysis.position)
        .filter(|(_, p)| p.is_finite())
        .map(|(c, _)| *c)
        .collect();
    assert!(drawn.len() > image.len() / 2, "only {} pixels drawn", drawn.len());
    let grey = drawn.iter().filter(|p| p[0] == p[1] && p[1] == p[2]).count();
    assert_eq!(
        grey,
        drawn.len(),
        "{} of {} drawn pixels are not grey",
        drawn.len() - grey,
        drawn.len()
    );
    let max = drawn.iter().map(|p| p[0]).max().unwrap_or(0);
    let dark = drawn.iter().filter(|p| p[0] < max / 4).count();
    eprintln!("{dark} dark pixels of {}, lit at {max}", drawn.len());
    assert!(max > 100, "the lit contact term is drawn at {max}");
    assert!(
        (200..drawn.len() / 10).contains(&dark),
        "{dark} dark pixels: the contact term should darken the bases alone"
    );
}
