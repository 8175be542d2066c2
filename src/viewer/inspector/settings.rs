//! The shadow-settings section: every [`ShadowSettings`] field, with the ranges of the
//! runtime table (filter mode, cascades, resolution, split λ, max distance, biases, PCF
//! radius, PCSS quality and switches, the moment techniques' parameters, blend and fade
//! widths) and the cascade debug view.

use egui::{ComboBox, Slider, Ui};

use crate::settings::{
    CascadeFit, ContactShadows, DEFAULT_PAGE_SIZE, DEFAULT_POOL_PAGES, DEFAULT_VIRTUAL_RESOLUTION, MAX_CASCADES,
    MAX_CLIPMAP_LEVELS, MAX_CONTACT_STEPS, MAX_EVSM_EXPONENT, MAX_PCF_RADIUS, MAX_SNAP_CELLS, MAX_VSM_BLUR,
    MomentFormat, PcssQuality, ShadowDebugView, ShadowMode, ShadowSettings, SunLayout, max_pool_pages,
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
    debug_view_ui(ui, &mut s.filter.debug_view);
}

/// The debug view shown for the focus light: none, cascade colours or contact shadows alone.
pub(crate) fn debug_view_ui(ui: &mut Ui, view: &mut ShadowDebugView) {
    let name = |v: ShadowDebugView| match v {
        ShadowDebugView::None => "no debug view",
        ShadowDebugView::Cascades => "cascade colours",
        ShadowDebugView::Contact => "contact shadows alone",
    };
    let views = [
        ShadowDebugView::None,
        ShadowDebugView::Cascades,
        ShadowDebugView::Contact,
    ];
    ComboBox::from_label("debug view")
        .selected_text(name(*view))
        .show_ui(ui, |ui| {
            for v in views {
                ui.selectable_value(view, v, name(v));
            }
        });
}

/// Contact shadows: on or off, and the march's length, steps, thickness and intensity.
fn contact_ui(ui: &mut Ui, c: &mut ContactShadows) {
    let mut on = c.steps > 0;
    if ui.checkbox(&mut on, "contact shadows").changed() {
        c.steps = if on { ContactShadows::ON.steps } else { 0 };
    }
    if on {
        ui.add(
            Slider::new(&mut c.length, 0.01..=5.0)
                .logarithmic(true)
                .text("contact length (m)"),
        );
        ui.add(Slider::new(&mut c.steps, 1..=MAX_CONTACT_STEPS).text("contact steps"));
        ui.add(
            Slider::new(&mut c.thickness, 0.001..=2.0)
                .logarithmic(true)
                .text("contact thickness (m)"),
        );
        ui.add(Slider::new(&mut c.intensity, 0.0..=1.0).text("contact intensity"));
    }
}

/// A clipmap's levels and the side of its finest level.
fn clipmap_ui(ui: &mut Ui, levels: &mut u32, level0_extent: &mut f32) {
    ui.add(Slider::new(levels, 1..=MAX_CLIPMAP_LEVELS).text("clipmap levels"));
    ui.add(
        Slider::new(level0_extent, 0.5..=1000.0)
            .logarithmic(true)
            .text("finest level m"),
    );
}

/// A power of two in `lo..=hi`, picked from a list.
fn power_of_two_ui(ui: &mut Ui, value: &mut u32, (lo, hi): (u32, u32), label: &str) {
    ComboBox::from_label(label)
        .selected_text(value.to_string())
        .show_ui(ui, |ui| {
            let mut v = lo;
            while v <= hi {
                ui.selectable_value(value, v, v.to_string());
                v *= 2;
            }
        });
}

/// The sun's layout: cascades (count, fit, split λ, max distance), a clipmap (levels and
/// the finest level's side) or a virtual clipmap (those, its virtual resolution, page size
/// and pool, whose memory it prints).
fn layout_ui(ui: &mut Ui, s: &mut ShadowSettings) {
    let name = |l: &SunLayout| match l {
        SunLayout::Cascades => "Cascades",
        SunLayout::Clipmap { .. } => "Clipmap",
        SunLayout::VirtualClipmap { .. } => "Virtual clipmap",
    };
    let current = name(&s.map.layout);
    let (levels, level0_extent) = s.map.layout.clipmap_levels().unwrap_or((6, 32.0));
    let choices = [
        SunLayout::Cascades,
        SunLayout::Clipmap { levels, level0_extent },
        SunLayout::VirtualClipmap {
            levels,
            level0_extent,
            virtual_resolution: DEFAULT_VIRTUAL_RESOLUTION,
            page_size: DEFAULT_PAGE_SIZE,
            pool_pages: DEFAULT_POOL_PAGES,
        },
    ];
    ComboBox::from_label("layout").selected_text(current).show_ui(ui, |ui| {
        for choice in choices {
            if ui.selectable_label(current == name(&choice), name(&choice)).clicked() && current != name(&choice) {
                s.map.layout = choice;
            }
        }
    });
    let pool = s.map.layout.pool_bytes();
    match &mut s.map.layout {
        SunLayout::Cascades => {}
        SunLayout::Clipmap { levels, level0_extent } => {
            clipmap_ui(ui, levels, level0_extent);
            return;
        }
        SunLayout::VirtualClipmap {
            levels,
            level0_extent,
            virtual_resolution,
            page_size,
            pool_pages,
        } => {
            clipmap_ui(ui, levels, level0_extent);
            power_of_two_ui(ui, virtual_resolution, (4096, 16384), "virtual texels");
            power_of_two_ui(ui, page_size, (64, 512), "page texels");
            let most = max_pool_pages(*page_size);
            ui.add(Slider::new(pool_pages, 1..=most).logarithmic(true).text("pool pages"));
            ui.label(format!(
                "pool memory {:.1} MiB of depth (moments add theirs)",
                pool as f64 / (1024.0 * 1024.0)
            ));
            return;
        }
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
    ui.add(Slider::new(&mut s.map.cascades.snap_cells, 0..=MAX_SNAP_CELLS).text("snap cells"))
        .on_hover_text("Cascades hold while the camera moves within a cell: 0 cells of the spare texels, N cells of at least 1/N of a box");
    ui.checkbox(&mut s.map.cascades.scroll, "scroll cascades")
        .on_hover_text("A cascade moved by whole texels keeps its map and draws only the texels it newly covers");
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
/// blur, bleed reduction and variance floor; then contact shadows.
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
    contact_ui(ui, &mut s.filter.contact);
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
