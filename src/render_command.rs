//! `penumbra render` (part of the `penumbra` binary): renders a scene file headless to a PNG,
//! with the shadow settings the command line overrides, and prints the frame's GPU and CPU
//! timings, the shadow account and the work the shadow passes did.

use std::path::PathBuf;

use clap::Args;
use clap::builder::TypedValueParser;

use crate::cli_values::{Deferred, Fit, Layout, Mode, Precision, Prepass, Quality};
use crate::{render_json, render_text};
use penumbra::app::{CameraMotion, RenderError, RenderRequest, render_scene_with};
use penumbra::ecs::shadow_memory::MIB;
use penumbra::ecs::view_lod::CameraLod;
use penumbra::export::{OutputKind, prepare_output, write_color_image, write_scalar_image};
use penumbra::render::limits::MAX_TEXTURE_SIDE;
use penumbra::render::{DeferredLighting, DepthPrepass, Msaa, RenderOptions, SunDepth};
use penumbra::scene::{DEFAULT_MAX_INSTANCES, SceneDesc, SceneLimits};
use penumbra::settings::{
    ContactShadows, DEFAULT_PAGE_SIZE, DEFAULT_POOL_PAGES, DEFAULT_VIRTUAL_RESOLUTION, MomentFormat, PcssQuality,
    ShadowDebugView, ShadowMode, ShadowSettings, SunLayout,
};

/// Options of `penumbra render`.
#[derive(Args)]
pub struct RenderArgs {
    /// Scene file (RON).
    scene: PathBuf,
    /// Output PNG (checked, and its folder created, before rendering).
    #[arg(long, default_value = "out/render.png")]
    out: PathBuf,
    /// Image width in pixels (at most the adapter's largest texture side).
    #[arg(long, default_value_t = 1280, value_parser = side())]
    width: u32,
    /// Image height in pixels (at most the adapter's largest texture side).
    #[arg(long, default_value_t = 720, value_parser = side())]
    height: u32,
    /// Shadow filter (default: the scene's).
    #[arg(long)]
    mode: Option<Mode>,
    /// PCSS quality (default: the scene's).
    #[arg(long)]
    quality: Option<Quality>,
    /// PCF radius 0-5 (default: the scene's).
    #[arg(long)]
    pcf_radius: Option<u32>,
    /// Storage of a sun's EVSM or MSM moments (default: the scene's).
    #[arg(long)]
    moment_precision: Option<Precision>,
    /// Contact hardening of a sun's EVSM or MSM moments, true or false (default: the scene's,
    /// on unless it turns it off); false filters every pixel with `moment_blur`.
    #[arg(long)]
    moment_contact_hardening: Option<bool>,
    /// The sun's angular diameter in degrees, 0-30 (default: the scene's).
    #[arg(long, value_parser = sun_degrees)]
    sun_diameter: Option<f32>,
    /// How the sun's cascades are fitted (default: the scene's): tight, stable, or
    /// depth-bounds (to the depths the camera saw, a frame or two late).
    #[arg(long, value_enum)]
    fit: Option<Fit>,
    /// Fewest cells per side of the grid the sun's cascade boxes snap to, 0-64 (default: the
    /// scene's, else 0: cells of the texels a box's rounded-up extent leaves spare): a moving
    /// camera redraws a cascade only when its box crosses a cell; N makes cells at least 1/N
    /// of a box, which grows by a cell.
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=64))]
    snap_cells: Option<u32>,
    /// Whether the sun's cascades scroll, true or false (default: the scene's): a cascade
    /// whose box moved by whole texels keeps its map and draws only the texels it newly
    /// covers (not with moment filters).
    #[arg(long)]
    cascade_scroll: Option<bool>,
    /// Texels per side of every light's shadow maps (cascades, clipmap levels, spot maps, cube
    /// faces), 256-4096 (default: the scene's).
    #[arg(long, value_parser = clap::value_parser!(u32).range(256..=4096))]
    resolution: Option<u32>,
    /// How the sun's shadow is divided into maps (default: the scene's): cascades, or a
    /// clipmap of `--clipmap-levels` levels around the camera, the finest
    /// `--clipmap-extent` metres wide.
    #[arg(long, value_enum)]
    layout: Option<Layout>,
    /// Clipmap levels, 1-8 (with `--layout clipmap`; default: the scene's, else 6).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=8))]
    clipmap_levels: Option<u32>,
    /// Side of the finest clipmap level in metres, 0.5-1e5 (with `--layout clipmap`;
    /// default: the scene's, else 32).
    #[arg(long, value_parser = clipmap_extent)]
    clipmap_extent: Option<f32>,
    /// Texels per side of each virtual clipmap level, a power of two 4096-16384 (with
    /// `--layout virtual-clipmap`; default 16384).
    #[arg(long)]
    virtual_resolution: Option<u32>,
    /// Texels per side of a virtual clipmap's page: 64, 128, 256 or 512 (default 128).
    #[arg(long)]
    page_size: Option<u32>,
    /// Pages of the virtual clipmap's pool (default 2048; the pool's memory is printed).
    #[arg(long)]
    pool_pages: Option<u32>,
    /// Tint pixels by the cascade (or clipmap level) they sample.
    #[arg(long)]
    debug_cascades: bool,
    /// Contact shadows for every light: `LENGTH,STEPS,THICKNESS,INTENSITY` (metres, 0-64,
    /// metres, 0-1); alone, the defaults `0.3,16,0.02,1`; `0,0,0,0` turns them off.
    #[arg(long, value_parser = contact_values, num_args = 0..=1, default_missing_value = "0.3,16,0.02,1")]
    contact_shadows: Option<ContactShadows>,
    /// Show the contact shadows of the sun (or the first light) alone, in grey.
    #[arg(long)]
    debug_contact: bool,
    /// Folder every file the scene names must stay inside (default: the nearest enclosing
    /// folder named `assets`, else the scene's folder).
    #[arg(long)]
    asset_root: Option<PathBuf>,
    /// Most instances the scene may place (grid copies and glTF primitives counted).
    #[arg(long, default_value_t = DEFAULT_MAX_INSTANCES)]
    max_instances: u64,
    /// Frames to render; timings are the median over frames after the first.
    #[arg(long, default_value_t = 5)]
    frames: u32,
    /// Also write the per-pixel sun shadow factor (the visibility the material multiplied in,
    /// 1 where not evaluated), aligned with the colour image: a `.png` path gives 16-bit
    /// greyscale, a `.pfm` path 32-bit float (Portable Float Map).
    #[arg(long)]
    shadow_out: Option<PathBuf>,
    /// Depth prepass: auto (on while the view has fewer triangles than the image has
    /// pixels), on, or off (the lighting pass then writes depth itself).
    #[arg(long, value_enum, default_value_t = Prepass::Auto)]
    depth_prepass: Prepass,
    /// Draw every shadow map every frame, as when everything moves (by default a shadow map
    /// whose view and casters did not change is kept).
    #[arg(long)]
    no_shadow_cache: bool,
    /// Filter the shadows in the lighting pass itself instead of in a compute pass after the
    /// depth prepass (by default they are resolved in compute whenever the prepass runs).
    #[arg(long)]
    no_visibility_resolve: bool,
    /// Draw every batch with its own `draw_indexed` instead of one multi-draw per run of
    /// batches that bind nothing between them.
    #[arg(long)]
    no_multi_draw: bool,
    /// Draw every instance in the camera's frustum, hidden or not (by default instances
    /// hidden behind others are culled on the GPU, around the depth prepass).
    #[arg(long)]
    no_occlusion_culling: bool,
    /// Cull the camera view's instances and the cascades' casters on the CPU, one by one (by
    /// default the CPU only tests culling chunks and the GPU tests their members, in views of
    /// 16 384 instances or more and scenes of 16 384 casters or more).
    #[arg(long)]
    no_gpu_culling: bool,
    /// Draw the depth prepass every frame, even where nothing it draws changed since the last
    /// (by default a still camera over a still scene keeps the last frame's).
    #[arg(long)]
    no_prepass_reuse: bool,
    /// Draw opaque shadow casters from each mesh's own indices instead of its position-only
    /// list (by default corners at the same position are shaded once: a box's 8 vertices,
    /// not 24).
    #[arg(long)]
    no_position_indices: bool,
    /// Light the prepass's pixels of opaque, untextured materials in one compute pass instead
    /// of drawing them again: auto (on, where the frame allows it: a prepass with normals, no
    /// MSAA, no `--shadow-out`), on or off.
    #[arg(long, value_enum, default_value_t = Deferred::Auto)]
    deferred_lighting: Deferred,
    /// The camera view's largest geometric error of a coarser mesh level, in pixels (default
    /// 0.25; 0 draws every mesh whole; at most 16).
    #[arg(long, value_parser = lod_pixels)]
    camera_lod: Option<f32>,
    /// Render each sun's cascades in one multiview pass where the GPU supports it (`true`),
    /// or one pass per cascade (`false`).
    #[arg(long, action = clap::ArgAction::Set, default_value_t = RenderOptions::default().single_pass_cascades)]
    single_pass_cascades: bool,
    /// Move the camera by this many metres along world x, y, z before each frame after the
    /// first (`--camera-step 0,0,-1`: a metre a frame towards −z): the cost of moving frames,
    /// with the shadow cache on.
    #[arg(long, value_parser = metres_xyz, allow_negative_numbers = true)]
    camera_step: Option<glam::Vec3>,
    /// Turn the camera by this many degrees about the vertical before each frame after the
    /// first.
    #[arg(long, allow_negative_numbers = true)]
    camera_turn: Option<f32>,
    /// Multiply the speed of every glTF object's animation by this factor (0 holds each
    /// skinned mesh in its first pose: the cost of a still frame of a skinned scene).
    #[arg(long, allow_negative_numbers = true, value_parser = finite_factor)]
    animation_speed: Option<f32>,
    /// Count the lighting pass's fragment-shader invocations (pipeline statistics) and print
    /// them per pixel of the image.
    #[arg(long)]
    count_fragments: bool,
    /// Samples per pixel of the image (MSAA): 1 (off), 2 or 4; falls back, with a warning,
    /// to what the GPU supports. With `--shadow-out` the image is rendered with 1.
    #[arg(long, default_value = "1")]
    msaa: Msaa,
    /// Bits of depth of the suns' cascade and clipmap layers: 16 (unorm: half the memory and
    /// bandwidth; a depth rounds to 1/65 536 of the view's depth range) or 32 (float).
    #[arg(long, default_value = "16")]
    sun_depth: SunDepth,
    /// Most MiB of the scene's decoded images together, with their mip chains: an image that
    /// would pass it is downscaled to fit, with a warning.
    #[arg(long, value_parser = mebibytes(), default_value = "256")]
    texture_budget: u64,
    /// Most MiB of shadow maps, their moments and blur scratch (default: 2048 on a discrete
    /// GPU, 512 on software Vulkan, 1024 otherwise): the lights smallest on screen are
    /// lowered to fit, with a warning; a light that cannot fit even at 256² is an error.
    #[arg(long, value_parser = mebibytes())]
    shadow_budget: Option<u64>,
    /// Print the summary (timings, counts, memory) as one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

/// Image sides accepted on the command line: 1 to the largest texture side of any adapter;
/// the adapter's own limit is checked when it is opened, before anything is rendered.
pub fn side() -> clap::builder::RangedI64ValueParser<u32> {
    clap::value_parser!(u32).range(1..=MAX_TEXTURE_SIDE as i64)
}

/// A budget on the command line: whole MiB from 0 to 1,048,576 (1 TiB), returned in bytes.
pub fn mebibytes() -> impl clap::builder::TypedValueParser<Value = u64> {
    clap::value_parser!(u64).range(0..=1 << 20).map(|mib| mib * MIB)
}

/// A step on the command line: three finite numbers of metres, `x,y,z`.
fn metres_xyz(text: &str) -> Result<glam::Vec3, String> {
    let parts: Vec<f32> = text.split(',').filter_map(|p| p.trim().parse::<f32>().ok()).collect();
    match parts[..] {
        [x, y, z] if parts.iter().all(|v| v.is_finite()) => Ok(glam::Vec3::new(x, y, z)),
        _ => Err(format!("expected three numbers of metres `x,y,z`, found `{text}`")),
    }
}

/// A finite factor (the animation speed's).
fn finite_factor(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(f) if f.is_finite() => Ok(f),
        _ => Err(format!("expected a finite number, found `{text}`")),
    }
}

/// A sun's angular diameter on the command line: degrees from 0 to 30, as in scene files.
pub fn sun_degrees(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(d) if (0.0..=30.0).contains(&d) => Ok(d),
        _ => Err(format!("expected degrees from 0 to 30, found `{text}`")),
    }
}

/// Contact shadows on the command line: `length,steps,thickness,intensity`, each in its
/// range (`0,0,0,0`: off).
pub fn contact_values(text: &str) -> Result<ContactShadows, String> {
    let expected = || {
        format!(
            "expected `length,steps,thickness,intensity` (metres 0.01-5, 0-64, metres 0.001-2, 0-1), found `{text}`"
        )
    };
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [length, steps, thickness, intensity] = parts[..] else {
        return Err(expected());
    };
    let float = |t: &str| t.parse::<f32>().ok().filter(|v| v.is_finite());
    let contact = match (float(length), steps.parse::<u32>(), float(thickness), float(intensity)) {
        (Some(length), Ok(steps), Some(thickness), Some(intensity)) => ContactShadows {
            length,
            steps,
            thickness,
            intensity,
        },
        _ => return Err(expected()),
    };
    if !contact.enabled() {
        return Ok(ContactShadows::OFF);
    }
    let mut settings = ShadowSettings::default();
    settings.filter.contact = contact;
    match settings.problems().first() {
        Some(problem) => Err(problem.to_string()),
        None => Ok(contact),
    }
}

/// A camera LOD error on the command line: pixels from 0 to 16.
fn lod_pixels(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(p) if (0.0..=16.0).contains(&p) => Ok(p),
        _ => Err(format!("expected pixels from 0 to 16, found `{text}`")),
    }
}

/// The side of the finest clipmap level on the command line: metres from 0.5 to 1e5.
fn clipmap_extent(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(m) if (0.5..=1.0e5).contains(&m) => Ok(m),
        _ => Err(format!("expected metres from 0.5 to 1e5, found `{text}`")),
    }
}

pub fn render(args: RenderArgs) -> Result<(), RenderError> {
    let RenderArgs {
        scene,
        out,
        width,
        height,
        mode,
        quality,
        pcf_radius,
        moment_precision,
        moment_contact_hardening,
        sun_diameter,
        fit,
        snap_cells,
        cascade_scroll,
        resolution,
        layout,
        clipmap_levels,
        clipmap_extent,
        virtual_resolution,
        page_size,
        pool_pages,
        debug_cascades,
        contact_shadows,
        debug_contact,
        asset_root,
        max_instances,
        frames,
        shadow_out,
        depth_prepass,
        no_shadow_cache,
        no_visibility_resolve,
        single_pass_cascades,
        no_multi_draw,
        no_occlusion_culling,
        no_gpu_culling,
        no_prepass_reuse,
        no_position_indices,
        deferred_lighting,
        camera_lod,
        count_fragments,
        camera_step,
        camera_turn,
        animation_speed,
        msaa,
        sun_depth,
        texture_budget,
        shadow_budget,
        json,
    } = args;
    prepare_output(&out, OutputKind::ColorImage)?;
    if let Some(path) = &shadow_out {
        prepare_output(path, OutputKind::ScalarImage)?;
    }
    let limits = SceneLimits {
        asset_root,
        max_instances,
        max_texture_bytes: texture_budget,
    };
    let mut desc = SceneDesc::load_with(&scene, &limits)?;
    if let (Some(d), Some(sun)) = (sun_diameter, desc.sun.as_mut()) {
        sun.angular_diameter = d;
    }
    if let Some(factor) = animation_speed {
        desc.scale_animation_speed(factor);
    }
    let tweak = |s: &mut ShadowSettings| {
        if let Some(m) = mode {
            s.filter.mode = match m {
                Mode::Pcf => ShadowMode::Pcf,
                Mode::Pcss => ShadowMode::Pcss,
                Mode::Vsm => ShadowMode::Vsm,
                Mode::Evsm => ShadowMode::Evsm,
                Mode::Evsm4 => ShadowMode::Evsm4,
                Mode::Msm => ShadowMode::Msm,
            };
        }
        if let Some(p) = moment_precision {
            s.filter.moments.precision = match p {
                Precision::Auto => MomentFormat::Auto,
                Precision::Fp16 => MomentFormat::Fp16,
                Precision::Fp32 => MomentFormat::Fp32,
            };
        }
        if let Some(q) = quality {
            s.filter.pcss_quality = match q {
                Quality::Low => PcssQuality::Low,
                Quality::Medium => PcssQuality::Medium,
                Quality::High => PcssQuality::High,
            };
        }
        if let Some(r) = pcf_radius {
            s.filter.pcf_radius = r;
        }
        if let Some(on) = moment_contact_hardening {
            s.filter.moments.contact_hardening = on;
        }
        if let Some(fit) = fit {
            s.map.cascades.fit = fit.into();
        }
        if let Some(cells) = snap_cells {
            s.map.cascades.snap_cells = cells;
        }
        if let Some(on) = cascade_scroll {
            s.map.cascades.scroll = on;
        }
        if let Some(side) = resolution {
            s.map.resolution = side;
        }
        let (levels, extent) = s.map.layout.clipmap_levels().unwrap_or((6, 32.0));
        let (levels, level0_extent) = (clipmap_levels.unwrap_or(levels), clipmap_extent.unwrap_or(extent));
        s.map.layout = match layout {
            Some(Layout::Cascades) => SunLayout::Cascades,
            Some(Layout::Clipmap) => SunLayout::Clipmap { levels, level0_extent },
            Some(Layout::VirtualClipmap) => SunLayout::VirtualClipmap {
                levels,
                level0_extent,
                virtual_resolution: virtual_resolution.unwrap_or(DEFAULT_VIRTUAL_RESOLUTION),
                page_size: page_size.unwrap_or(DEFAULT_PAGE_SIZE),
                pool_pages: pool_pages.unwrap_or(DEFAULT_POOL_PAGES),
            },
            None => s.map.layout,
        };
        if debug_cascades {
            s.filter.debug_view = ShadowDebugView::Cascades;
        }
        if let Some(contact) = contact_shadows {
            s.filter.contact = contact;
        }
        if debug_contact {
            s.filter.debug_view = ShadowDebugView::Contact;
        }
    };
    let request = RenderRequest {
        width,
        height,
        frames,
        tweak: Some(&tweak),
        analysis: shadow_out.is_some(),
        options: RenderOptions {
            depth_prepass: match depth_prepass {
                Prepass::Auto => DepthPrepass::Auto,
                Prepass::On => DepthPrepass::On,
                Prepass::Off => DepthPrepass::Off,
            },
            shadow_cache: !no_shadow_cache,
            visibility_resolve: !no_visibility_resolve,
            single_pass_cascades,
            msaa,
            multi_draw: !no_multi_draw,
            occlusion_culling: !no_occlusion_culling,
            gpu_culling: !no_gpu_culling,
            prepass_reuse: !no_prepass_reuse,
            position_indices: !no_position_indices,
            sun_depth,
            deferred_lighting: match deferred_lighting {
                Deferred::Auto => DeferredLighting::Auto,
                Deferred::On => DeferredLighting::On,
                Deferred::Off => DeferredLighting::Off,
            },
        },
        shadow_budget,
        count_fragments,
        camera_lod: camera_lod.map(|max_error_pixels| CameraLod { max_error_pixels }),
        camera_motion: CameraMotion {
            step: camera_step.unwrap_or(glam::Vec3::ZERO),
            turn_degrees: camera_turn.unwrap_or(0.0),
        },
    };
    let result = render_scene_with(&desc, &request)?;
    if let (Some(path), Some(analysis)) = (&shadow_out, &result.analysis) {
        write_scalar_image(path, analysis.width, analysis.height, &analysis.shadow)?;
    }
    write_color_image(&out, &result.image)?;

    // The settings the sun was rendered with: the scene's, with the command line's changes.
    let mut s = desc.shadows;
    tweak(&mut s);
    if json {
        let sun = desc.sun.is_some().then_some(&s);
        let summary = render_json::summary_json(&scene, &out, (width, height, frames), sun, &result);
        println!("{summary:#}");
        return Ok(());
    }
    render_text::print_summary(&scene, &out, (width, height, frames), (desc.sun.is_some(), &s), &result);
    Ok(())
}
