//! The render-wide switches of [`RenderOptions`]: the depth prepass, the shadow cache, the
//! compute visibility resolve, single-pass cascades, multi-draw, GPU and occlusion culling,
//! deferred lighting and MSAA; and the camera view's LOD ([`CameraLod`]).

use egui::Ui;

use crate::ecs::view_lod::CameraLod;
use crate::render::{DeferredLighting, DepthPrepass, Msaa, RenderOptions, SunDepth};

/// A labelled row of radio buttons (`label` with its hover text) choosing `value` among
/// `choices`.
fn radio_row<T: PartialEq, const N: usize>(
    ui: &mut Ui,
    (label, hover): (&str, &str),
    value: &mut T,
    choices: [(T, &str); N],
) {
    ui.horizontal(|ui| {
        ui.label(label).on_hover_text(hover);
        for (choice, name) in choices {
            ui.radio_value(value, choice, name);
        }
    });
}

/// Draws the switches over `options`; true when one changed.
pub fn render_options_ui(ui: &mut Ui, options: &mut RenderOptions) -> bool {
    let before = *options;
    let edited = options;
    radio_row(
        ui,
        (
            "depth prepass",
            "write depth first, so the lighting pass shades each pixel once; auto: while the view has fewer triangles than pixels",
        ),
        &mut edited.depth_prepass,
        [
            (DepthPrepass::Auto, "auto"),
            (DepthPrepass::On, "on"),
            (DepthPrepass::Off, "off"),
        ],
    );
    ui.checkbox(&mut edited.shadow_cache, "shadow cache")
        .on_hover_text("keep shadow maps whose view and casters did not change; off: draw every map every frame");
    ui.checkbox(&mut edited.visibility_resolve, "compute resolve")
        .on_hover_text("filter the shadows per pixel in a compute pass after the prepass");
    ui.checkbox(&mut edited.single_pass_cascades, "single-pass cascades")
        .on_hover_text("draw a sun's cascades in one multiview pass where the GPU supports it");
    ui.checkbox(&mut edited.multi_draw, "multi-draw").on_hover_text(
        "draw the batches a pass binds nothing between (meshes of any size) with one indirect multi-draw",
    );
    ui.checkbox(&mut edited.gpu_culling, "GPU culling").on_hover_text(
        "cull the camera view's instances and the cascades' casters on the GPU (the CPU tests culling chunks only); off: on the CPU",
    );
    ui.checkbox(&mut edited.prepass_reuse, "keep a still prepass").on_hover_text(
        "draw no depth prepass where the camera, the instances and these options are as last frame (keep its depth, normals and ids)",
    );
    ui.checkbox(&mut edited.position_indices, "position-only caster indices")
        .on_hover_text(
            "draw opaque shadow casters from index lists that shade each corner once (a box's 8 vertices, not 24)",
        );
    radio_row(
        ui,
        (
            "sun depth",
            "bits of the suns' cascade and clipmap depth: 16 halves their memory and the bandwidth of drawing them; a depth rounds to 1/65 536 of the view's range",
        ),
        &mut edited.sun_depth,
        [(SunDepth::Float32, "32-bit float"), (SunDepth::Unorm16, "16-bit")],
    );
    ui.checkbox(&mut edited.occlusion_culling, "occlusion culling")
        .on_hover_text("skip instances hidden behind others (two phases around the depth prepass)");
    radio_row(
        ui,
        (
            "deferred lighting",
            "light the prepass's pixels of untextured opaque materials in one full-screen pass instead of drawing them again; auto: while the view has at least as many triangles as pixels",
        ),
        &mut edited.deferred_lighting,
        [
            (DeferredLighting::Auto, "auto"),
            (DeferredLighting::On, "on"),
            (DeferredLighting::Off, "off"),
        ],
    );
    radio_row(
        ui,
        (
            "MSAA",
            "samples per pixel: smooth edges, and alpha-to-coverage for alpha-masked materials; 1× alpha-tests them",
        ),
        &mut edited.msaa,
        [(Msaa::Off, "1×"), (Msaa::Sample2, "2×"), (Msaa::Sample4, "4×")],
    );
    *edited != before
}

/// Draws the camera view's LOD slider over `lod`; true when it changed.
pub fn camera_lod_ui(ui: &mut Ui, lod: &mut CameraLod) -> bool {
    ui.add(egui::Slider::new(&mut lod.max_error_pixels, 0.0..=4.0).text("camera LOD error (px)"))
        .on_hover_text("the largest geometric error of a coarser mesh level on screen; 0 draws every mesh whole")
        .changed()
}
