//! The shadow-settings section: every [`ShadowSettings`] field, with the ranges of the
//! runtime table (filter mode, cascades, resolution, split λ, max distance, biases, PCF
//! radius, PCSS quality and switches, the moment techniques' parameters, blend and fade
//! widths) and the cascade debug view.

use egui::{ComboBox, Slider, Ui};

use crate::settings::{
    CascadeFit, MAX_CASCADES, MAX_CLIPMAP_LEVELS, MAX_EVSM_EXPONENT, MAX_PCF_RADIUS, MAX_VSM_BLUR, MomentFormat,
    PcssQuality, ShadowDebugView, ShadowMode, ShadowSettings, SunLayout,
};

/// The shadow-map resolutions offered (the seed's runtime table, and 256 for point-light faces).
pub(crate) const RESOLUTIONS: [u32; 5] = [256, 512, 1024, 2048, 4096];

/// Draws the controls for `s`; the caller writes the copy back when it changed.
pub(crate) fn settings_ui(ui: &mut Ui, s: &mut ShadowSettings) {
    filter_ui(ui, s, true);
    layout_ui(ui, s);
    resolution_ui(ui, s);
    bias_ui(ui, s);
    ui.add(Slider::new(&mut s.map.cascades.blend_width, 0.0..=0.5).text("cascade blend"));
    ui.add(Slider::new(&mut s.filter.distance_fade_width, 0.0..=0.5).text("distance fade"));
    ui.checkbox(&mut s.map.depth_clamp, "depth clamp");
    let mut debug = s.filter.debug_view == ShadowDebugView::Cascades;
    if ui.checkbox(&mut debug, "debug: cascade colours").changed() {
        s.filter.debug_view = if debug {
            ShadowDebugView::Cascades
        } else {
            ShadowDebugView::None
        };
    }
}

/// The sun's layout: cascades (count, fit, split λ, max distance) or a clipmap (levels and
/// the finest level's side).
fn layout_ui(ui: &mut Ui, s: &mut ShadowSettings) {
    let clipmap = matches!(s.map.layout, SunLayout::Clipmap { .. });
    let mut chosen = clipmap;
    ComboBox::from_label("layout")
        .selected_text(if clipmap { "Clipmap" } else { "Cascades" })
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut chosen, false, "Cascades");
            ui.selectable_value(&mut chosen, true, "Clipmap");
        });
    if chosen != clipmap {
        s.map.layout = if chosen {
            SunLayout::Clipmap {
                levels: 6,
                level0_extent: 32.0,
            }
        } else {
            SunLayout::Cascades
        };
    }
    if let SunLayout::Clipmap { levels, level0_extent } = &mut s.map.layout {
        ui.add(Slider::new(levels, 1..=MAX_CLIPMAP_LEVELS).text("clipmap levels"));
        ui.add(
            Slider::new(level0_extent, 0.5..=1000.0)
                .logarithmic(true)
                .text("finest level m"),
        );
        return;
    }
    ui.add(Slider::new(&mut s.map.cascades.count, 1..=MAX_CASCADES as u32).text("cascades"));
    ComboBox::from_label("fit")
        .selected_text(format!("{:?}", s.map.cascades.fit))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut s.map.cascades.fit, CascadeFit::Tight, "Tight");
            ui.selectable_value(&mut s.map.cascades.fit, CascadeFit::Stable, "Stable");
            ui.selectable_value(&mut s.map.cascades.fit, CascadeFit::DepthBounds, "Depth bounds");
        });
    ui.add(Slider::new(&mut s.map.cascades.split_lambda, 0.0..=1.0).text("split λ"));
    ui.add(
        Slider::new(&mut s.map.max_distance, 1.0..=2000.0)
            .logarithmic(true)
            .text("max distance m"),
    );
}

/// The shadow-map side.
pub(crate) fn resolution_ui(ui: &mut Ui, s: &mut ShadowSettings) {
    ComboBox::from_label("resolution")
        .selected_text(s.map.resolution.to_string())
        .show_ui(ui, |ui| {
            for r in RESOLUTIONS {
                ui.selectable_value(&mut s.map.resolution, r, r.to_string());
            }
        });
}

/// Slope bias, its clamp and the normal offset.
pub(crate) fn bias_ui(ui: &mut Ui, s: &mut ShadowSettings) {
    ui.add(Slider::new(&mut s.bias.slope_bias, 0.0..=10.0).text("slope bias"));
    ui.add(Slider::new(&mut s.bias.bias_clamp, 0.0..=0.05).text("bias clamp"));
    ui.add(Slider::new(&mut s.bias.normal_offset, 0.0..=5.0).text("normal offset"));
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
        .selected_text(mode_name(s.filter.mode.effective(sun)))
        .show_ui(ui, |ui| {
            for &mode in [ShadowMode::Pcf, ShadowMode::Pcss].iter().chain(moments) {
                ui.selectable_value(&mut s.filter.mode, mode, mode_name(mode));
            }
        });
    match s.filter.mode.effective(sun) {
        ShadowMode::Pcf => {
            let kernel = 2 * s.filter.pcf_radius + 1;
            let text = if s.filter.pcf_radius == 0 {
                "PCF radius (off)".to_owned()
            } else {
                format!("PCF radius ({kernel}×{kernel})")
            };
            ui.add(Slider::new(&mut s.filter.pcf_radius, 0..=MAX_PCF_RADIUS).text(text));
        }
        ShadowMode::Pcss => {
            ComboBox::from_label("PCSS quality")
                .selected_text(format!("{:?}", s.filter.pcss_quality))
                .show_ui(ui, |ui| {
                    for q in [PcssQuality::Low, PcssQuality::Medium, PcssQuality::High] {
                        let text = format!("{q:?} ({}+{} taps)", q.blocker_samples(), q.filter_samples());
                        ui.selectable_value(&mut s.filter.pcss_quality, q, text);
                    }
                });
            ui.checkbox(&mut s.filter.blocker_early_out, "blocker early-out");
            ui.checkbox(&mut s.filter.receiver_plane_bias, "receiver-plane bias");
            ui.checkbox(&mut s.filter.temporal_rotation, "temporal rotation");
        }
        ShadowMode::Vsm => {
            ui.checkbox(&mut s.filter.moments.contact_hardening, "contact hardening");
            ui.add(Slider::new(&mut s.filter.vsm.blur, 0..=MAX_VSM_BLUR).text("VSM blur (texels)"));
            ui.add(Slider::new(&mut s.filter.vsm.bleed_reduction, 0.0..=0.95).text("light-bleed reduction"));
            ui.add(
                Slider::new(&mut s.filter.vsm.min_variance, 0.0..=0.01)
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
        .selected_text(format!("{:?}", s.filter.moments.precision))
        .show_ui(ui, |ui| {
            for p in [MomentFormat::Auto, MomentFormat::Fp16, MomentFormat::Fp32] {
                ui.selectable_value(&mut s.filter.moments.precision, p, format!("{p:?}"));
            }
        });
    if s.filter.mode != ShadowMode::Msm {
        ui.add(
            Slider::new(&mut s.filter.moments.evsm_exponent, 0.0..=MAX_EVSM_EXPONENT).text("exponent (0: format's)"),
        );
    }
    ui.checkbox(&mut s.filter.moments.contact_hardening, "contact hardening");
    if !s.filter.moments.contact_hardening {
        ui.add(
            Slider::new(&mut s.filter.moments.blur, 0.0..=1.0)
                .logarithmic(true)
                .text("blur (m)"),
        );
    }
    ui.add(Slider::new(&mut s.filter.moments.bleed_reduction, 0.0..=0.95).text("light-bleed reduction"));
    if s.filter.mode != ShadowMode::Msm {
        ui.add(
            Slider::new(&mut s.filter.moments.min_variance, 0.0..=0.01)
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
