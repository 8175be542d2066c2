//! The shadow-settings section: every [`ShadowSettings`] field, with the ranges of the
//! runtime table (filter mode, cascades, resolution, split λ, max distance, biases, PCF
//! radius, PCSS quality and switches, the moment techniques' parameters, blend and fade
//! widths) and the cascade debug view.

use egui::{ComboBox, Slider, Ui};

use crate::settings::{
    CascadeFit, MAX_CASCADES, MAX_EVSM_EXPONENT, MAX_PCF_RADIUS, MAX_VSM_BLUR, MomentFormat, PcssQuality,
    ShadowDebugView, ShadowMode, ShadowSettings,
};

/// The shadow-map resolutions offered (the seed's runtime table, and 256 for point-light faces).
pub(crate) const RESOLUTIONS: [u32; 5] = [256, 512, 1024, 2048, 4096];

/// Draws the controls for `s`; the caller writes the copy back when it changed.
pub(crate) fn settings_ui(ui: &mut Ui, s: &mut ShadowSettings) {
    filter_ui(ui, s, true);
    ui.add(Slider::new(&mut s.cascade_count, 1..=MAX_CASCADES as u32).text("cascades"));
    resolution_ui(ui, s);
    ComboBox::from_label("fit")
        .selected_text(format!("{:?}", s.fit))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut s.fit, CascadeFit::Tight, "Tight");
            ui.selectable_value(&mut s.fit, CascadeFit::Stable, "Stable");
            ui.selectable_value(&mut s.fit, CascadeFit::DepthBounds, "Depth bounds");
        });
    ui.add(Slider::new(&mut s.split_lambda, 0.0..=1.0).text("split λ"));
    ui.add(
        Slider::new(&mut s.max_distance, 1.0..=2000.0)
            .logarithmic(true)
            .text("max distance m"),
    );
    bias_ui(ui, s);
    ui.add(Slider::new(&mut s.blend_width, 0.0..=0.5).text("cascade blend"));
    ui.add(Slider::new(&mut s.distance_fade_width, 0.0..=0.5).text("distance fade"));
    ui.checkbox(&mut s.depth_clamp, "depth clamp");
    let mut debug = s.debug_view == ShadowDebugView::Cascades;
    if ui.checkbox(&mut debug, "debug: cascade colours").changed() {
        s.debug_view = if debug {
            ShadowDebugView::Cascades
        } else {
            ShadowDebugView::None
        };
    }
}

/// The shadow-map side.
pub(crate) fn resolution_ui(ui: &mut Ui, s: &mut ShadowSettings) {
    ComboBox::from_label("resolution")
        .selected_text(s.resolution.to_string())
        .show_ui(ui, |ui| {
            for r in RESOLUTIONS {
                ui.selectable_value(&mut s.resolution, r, r.to_string());
            }
        });
}

/// Slope bias, its clamp and the normal offset.
pub(crate) fn bias_ui(ui: &mut Ui, s: &mut ShadowSettings) {
    ui.add(Slider::new(&mut s.slope_bias, 0.0..=10.0).text("slope bias"));
    ui.add(Slider::new(&mut s.bias_clamp, 0.0..=0.05).text("bias clamp"));
    ui.add(Slider::new(&mut s.normal_offset, 0.0..=5.0).text("normal offset"));
}

/// The filter: PCF with its radius, PCSS with its quality and switches, and the moment
/// techniques of the light's kind: for a `sun` EVSM2, EVSM4 and MSM with their precision,
/// exponent, blur, bleed reduction and variance floor; for spot and point lights VSM with its
/// blur, bleed reduction and variance floor.
pub(crate) fn filter_ui(ui: &mut Ui, s: &mut ShadowSettings, sun: bool) {
    let moments: &[ShadowMode] = if sun {
        &[ShadowMode::Evsm, ShadowMode::Evsm4, ShadowMode::Msm]
    } else {
        &[ShadowMode::Vsm]
    };
    ComboBox::from_label("mode")
        .selected_text(mode_name(s.mode.effective(sun)))
        .show_ui(ui, |ui| {
            for &mode in [ShadowMode::Pcf, ShadowMode::Pcss].iter().chain(moments) {
                ui.selectable_value(&mut s.mode, mode, mode_name(mode));
            }
        });
    match s.mode.effective(sun) {
        ShadowMode::Pcf => {
            let kernel = 2 * s.pcf_radius + 1;
            let text = if s.pcf_radius == 0 {
                "PCF radius (off)".to_owned()
            } else {
                format!("PCF radius ({kernel}×{kernel})")
            };
            ui.add(Slider::new(&mut s.pcf_radius, 0..=MAX_PCF_RADIUS).text(text));
        }
        ShadowMode::Pcss => {
            ComboBox::from_label("PCSS quality")
                .selected_text(format!("{:?}", s.pcss_quality))
                .show_ui(ui, |ui| {
                    for q in [PcssQuality::Low, PcssQuality::Medium, PcssQuality::High] {
                        let text = format!("{q:?} ({}+{} taps)", q.blocker_samples(), q.filter_samples());
                        ui.selectable_value(&mut s.pcss_quality, q, text);
                    }
                });
            ui.checkbox(&mut s.blocker_early_out, "blocker early-out");
            ui.checkbox(&mut s.receiver_plane_bias, "receiver-plane bias");
            ui.checkbox(&mut s.temporal_rotation, "temporal rotation");
        }
        ShadowMode::Vsm => {
            ui.checkbox(&mut s.moment_contact_hardening, "contact hardening");
            ui.add(Slider::new(&mut s.vsm_blur, 0..=MAX_VSM_BLUR).text("VSM blur (texels)"));
            ui.add(Slider::new(&mut s.vsm_bleed_reduction, 0.0..=0.95).text("light-bleed reduction"));
            ui.add(
                Slider::new(&mut s.vsm_min_variance, 0.0..=0.01)
                    .logarithmic(true)
                    .text("minimum variance"),
            );
        }
        ShadowMode::Evsm | ShadowMode::Evsm4 | ShadowMode::Msm => sun_moments_ui(ui, s),
    }
}

/// A sun's moment parameters (EVSM2, EVSM4, MSM).
fn sun_moments_ui(ui: &mut Ui, s: &mut ShadowSettings) {
    ComboBox::from_label("precision")
        .selected_text(format!("{:?}", s.moment_precision))
        .show_ui(ui, |ui| {
            for p in [MomentFormat::Auto, MomentFormat::Fp16, MomentFormat::Fp32] {
                ui.selectable_value(&mut s.moment_precision, p, format!("{p:?}"));
            }
        });
    if s.mode != ShadowMode::Msm {
        ui.add(Slider::new(&mut s.evsm_exponent, 0.0..=MAX_EVSM_EXPONENT).text("exponent (0: format's)"));
    }
    ui.checkbox(&mut s.moment_contact_hardening, "contact hardening");
    if !s.moment_contact_hardening {
        ui.add(
            Slider::new(&mut s.moment_blur, 0.0..=1.0)
                .logarithmic(true)
                .text("blur (m)"),
        );
    }
    ui.add(Slider::new(&mut s.moment_bleed_reduction, 0.0..=0.95).text("light-bleed reduction"));
    if s.mode != ShadowMode::Msm {
        ui.add(
            Slider::new(&mut s.moment_min_variance, 0.0..=0.01)
                .logarithmic(true)
                .text("minimum variance (m²)"),
        );
    }
}

fn mode_name(mode: ShadowMode) -> &'static str {
    match mode {
        ShadowMode::Pcf => "PCF",
        ShadowMode::Pcss => "PCSS",
        ShadowMode::Vsm => "VSM",
        ShadowMode::Evsm => "EVSM2",
        ShadowMode::Evsm4 => "EVSM4",
        ShadowMode::Msm => "MSM",
    }
}
