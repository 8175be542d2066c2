//! The render-wide switches of [`RenderOptions`]: the depth prepass, the shadow cache, the
//! compute visibility resolve, single-pass cascades, multi-draw, GPU and occlusion culling,
//! deferred lighting and MSAA; and the camera view's LOD ([`CameraLod`]).

use egui::Ui;

use crate::ecs::view_lod::CameraLod;
use crate::render::{DeferredLighting, DepthPrepass, Msaa, RenderOptions};

/// Draws the switches over `options`; true when one changed.
pub fn render_options_ui(ui: &mut Ui, options: &mut RenderOptions) -> bool {
    let before = *options;
    let edited = options;
    ui.horizontal(|ui| {
        ui.label("depth prepass").on_hover_text(
            "write depth first, so the lighting pass shades each pixel once; auto: while the view has fewer triangles than pixels",
        );
        for (value, name) in [
            (DepthPrepass::Auto, "auto"),
            (DepthPrepass::On, "on"),
            (DepthPrepass::Off, "off"),
        ] {
            ui.radio_value(&mut edited.depth_prepass, value, name);
        }
    });
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
    ui.checkbox(&mut edited.occlusion_culling, "occlusion culling")
        .on_hover_text("skip instances hidden behind others (two phases around the depth prepass)");
    ui.horizontal(|ui| {
        ui.label("deferred lighting").on_hover_text(
            "light the prepass's pixels of untextured opaque materials in one full-screen pass instead of drawing them again; auto: while the view has at least as many triangles as pixels",
        );
        for (value, name) in [
            (DeferredLighting::Auto, "auto"),
            (DeferredLighting::On, "on"),
            (DeferredLighting::Off, "off"),
        ] {
            ui.radio_value(&mut edited.deferred_lighting, value, name);
        }
    });
    ui.horizontal(|ui| {
        ui.label("MSAA").on_hover_text(
            "samples per pixel: smooth edges, and alpha-to-coverage for alpha-masked materials; 1× alpha-tests them",
        );
        for (value, name) in [(Msaa::Off, "1×"), (Msaa::Sample2, "2×"), (Msaa::Sample4, "4×")] {
            ui.radio_value(&mut edited.msaa, value, name);
        }
    });
    *edited != before
}

/// Draws the camera view's LOD slider over `lod`; true when it changed.
pub fn camera_lod_ui(ui: &mut Ui, lod: &mut CameraLod) -> bool {
    ui.add(egui::Slider::new(&mut lod.max_error_pixels, 0.0..=4.0).text("camera LOD error (px)"))
        .on_hover_text("the largest geometric error of a coarser mesh level on screen; 0 draws every mesh whole")
        .changed()
}
