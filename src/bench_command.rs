//! `penumbra bench` (part of the `penumbra` binary): its options, the runs (one, or one per
//! sun diameter with the sweep) and the summary it prints.

use std::error::Error;
use std::path::PathBuf;

use clap::Args;

use penumbra::export::{OutputKind, prepare_output};
use penumbra::render::SunDepth;
use penumbra::settings::ContactShadows;

use super::cli_values::Fit;
use crate::render_command::{contact_values, side, sun_degrees};

/// Options of `penumbra bench`.
#[derive(Args)]
pub struct BenchArgs {
    /// Scene files (default: the contact-hardening pillars, the benchmark field, the thin
    /// casters under a grazing sun, the spot-light and the point-light scenes). A scene with
    /// no directional light is scored on its first shadowed spot light, else its first
    /// shadowed point light; any other on its first sun.
    #[arg(long, num_args = 1..)]
    scenes: Vec<PathBuf>,
    /// Folder for report.md and plot.png.
    #[arg(long, default_value = "out/bench")]
    out: PathBuf,
    /// Resolution of the GPU timings.
    #[arg(long, default_value_t = 1920, value_parser = side())]
    width: u32,
    /// Resolution of the GPU timings.
    #[arg(long, default_value_t = 1080, value_parser = side())]
    height: u32,
    /// Width at which errors are scored (height follows the timing aspect ratio).
    #[arg(long, default_value_t = 480, value_parser = side())]
    analysis_width: u32,
    /// Most reference rays per point (adaptive from 16).
    #[arg(long, default_value_t = 256)]
    samples: u32,
    /// Frames timed per preset.
    #[arg(long, default_value_t = 30)]
    frames: u32,
    /// Only these presets (comma-separated names).
    #[arg(long, value_delimiter = ',')]
    presets: Vec<String>,
    /// A fast, rough run: small analysis image, few rays, few frames.
    #[arg(long)]
    quick: bool,
    /// Override every scene's normal offset (texels), for tuning.
    #[arg(long)]
    normal_offset: Option<f32>,
    /// Override every scene's hardware slope bias, for tuning.
    #[arg(long)]
    slope_bias: Option<f32>,
    /// Override every scene's shadow-map resolution (texels per side, 256-4096), for
    /// attributing error to resolution.
    #[arg(long, value_parser = clap::value_parser!(u32).range(256..=4096))]
    resolution: Option<u32>,
    /// Contact shadows for every light, `LENGTH,STEPS,THICKNESS,INTENSITY` (as `render
    /// --contact-shadows`); the `-contact` presets use them instead of the defaults.
    #[arg(long, value_parser = contact_values)]
    contact_shadows: Option<ContactShadows>,
    /// Texels per side of each level of the paged presets' virtual clipmap (`pages-*`), a
    /// power of two 4096-16384 (default 16384), for plotting error against memory.
    #[arg(long)]
    virtual_resolution: Option<u32>,
    /// Pages of the paged presets' pool (default 2048).
    #[arg(long)]
    pool_pages: Option<u32>,
    /// Override how every scene's cascades are fitted: tight, stable or depth-bounds.
    #[arg(long, value_enum)]
    fit: Option<Fit>,
    /// Override the fewest cells per side of the grid every scene's cascade boxes snap to,
    /// 0-64.
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=64))]
    snap_cells: Option<u32>,
    /// Override whether every scene's cascades scroll, true or false.
    #[arg(long)]
    cascade_scroll: Option<bool>,
    /// Bits of depth of the suns' cascade and clipmap layers, timed and scored: 16 (unorm) or
    /// 32 (float).
    #[arg(long, default_value = "16")]
    sun_depth: SunDepth,
    /// Override every scene sun's angular diameter, degrees 0-30 (sweeps of penumbra width).
    #[arg(long, value_parser = sun_degrees, conflicts_with = "sun_diameters")]
    sun_diameter: Option<f32>,
    /// Run the whole benchmark once per sun angular diameter (degrees, comma-separated), each
    /// report in its own folder `sun-<d>`, and write `sweep.md` and `sweep.png`: each
    /// preset's cost and error against the diameter.
    #[arg(long, value_delimiter = ',', value_parser = sun_degrees)]
    sun_diameters: Vec<f32>,
    /// Also write a gallery: DIR/gallery.md and, under DIR/gallery/, for every scene and
    /// preset the render, the technique's shadow, the ray-traced truth and the error, cropped
    /// to the window with the most penumbra, plus hero.png.
    #[arg(long, value_name = "DIR", conflicts_with = "sun_diameters")]
    gallery: Option<PathBuf>,
    /// The two presets the gallery's hero picture compares with the truth.
    #[arg(long, value_delimiter = ',', num_args = 2, default_values = ["pcf2", "pcss-high"])]
    hero: Vec<String>,
}

/// Runs the benchmark with `args` and writes its reports; a scene's error is kept whole, for
/// printing it with its line.
pub fn bench(args: BenchArgs) -> Result<(), Box<dyn Error>> {
    let scenes = if args.scenes.is_empty() {
        [
            "assets/scenes/pillars.ron",
            "assets/bench/field.ron",
            "assets/scenes/thin.ron",
            "assets/scenes/spot.ron",
            "assets/scenes/point.ron",
        ]
        .map(PathBuf::from)
        .to_vec()
    } else {
        args.scenes
    };
    let mut presets = penumbra::bench::presets();
    if !args.presets.is_empty() {
        let known: Vec<&str> = presets.iter().map(|p| p.name).collect();
        if let Some(unknown) = args.presets.iter().find(|n| !known.contains(&n.as_str())) {
            return Err(format!("unknown preset `{unknown}`; expected one of {}", known.join(", ")).into());
        }
        presets.retain(|p| args.presets.iter().any(|n| n == p.name));
    }
    let quick = args.quick;
    let analysis_width = if quick {
        args.analysis_width.min(240)
    } else {
        args.analysis_width
    }
    .max(16);
    let analysis_height = (analysis_width as u64 * args.height.max(1) as u64 / args.width.max(1) as u64).max(9) as u32;
    let config = penumbra::bench::BenchConfig {
        scenes,
        presets,
        width: args.width.max(1),
        height: args.height.max(1),
        analysis_width,
        analysis_height,
        timing_frames: if quick { args.frames.min(5) } else { args.frames }.max(1),
        warmup_frames: if quick { 2 } else { 5 },
        reference: penumbra::reference::ReferenceSettings {
            max_samples: if quick { args.samples.min(64) } else { args.samples }.max(16),
            min_samples: 16,
            seed: 1,
        },
        shimmer_steps: if quick { 4 } else { 8 },
        max_probes: if quick { 4_000 } else { 20_000 },
        progress: true,
        pages: (args.virtual_resolution.is_some() || args.pool_pages.is_some()).then_some(
            penumbra::bench::PagesOverride {
                virtual_resolution: args.virtual_resolution,
                pool_pages: args.pool_pages,
            },
        ),
        sun_depth: args.sun_depth,
    };
    let overrides = penumbra::bench::SettingsOverrides {
        normal_offset: args.normal_offset,
        slope_bias: args.slope_bias,
        sun_diameter: args.sun_diameter,
        fit: args.fit.map(Into::into),
        snap_cells: args.snap_cells,
        cascade_scroll: args.cascade_scroll,
        resolution: args.resolution,
        contact: args.contact_shadows,
    };
    if !args.sun_diameters.is_empty() {
        for name in ["sweep.md", "sweep.png"] {
            prepare_output(&args.out.join(name), OutputKind::Any).map_err(|e| e.to_string())?;
        }
        let mut runs = Vec::new();
        for &d in &args.sun_diameters {
            let overrides = penumbra::bench::SettingsOverrides {
                sun_diameter: Some(d),
                ..overrides
            };
            let report = penumbra::bench::run_bench_with(&config, &overrides)?;
            let dir = args.out.join(format!("sun-{d}"));
            let path = penumbra::bench::write_report(&report, &dir).map_err(|e| e.to_string())?;
            println!("sun        {d}°");
            print_report(&report, &path);
            runs.push((d, report));
        }
        let path = penumbra::bench::write_sweep(&runs, &args.out).map_err(|e| e.to_string())?;
        println!("sweep      {}", path.display());
        return Ok(());
    }
    for name in ["report.md", "report.json", "plot.png"] {
        prepare_output(&args.out.join(name), OutputKind::Any).map_err(|e| e.to_string())?;
    }
    if let Some(dir) = &args.gallery {
        prepare_output(&dir.join("gallery.md"), OutputKind::Any).map_err(|e| e.to_string())?;
        let run: Vec<&str> = config.presets.iter().map(|p| p.name).collect();
        if let Some(missing) = args.hero.iter().find(|h| !run.contains(&h.as_str())) {
            eprintln!("warning: the gallery has no hero picture: preset `{missing}` (--hero) is not run");
        }
    }
    let mut shots = Vec::new();
    let gallery = args.gallery.is_some().then_some(&mut shots);
    let report = penumbra::bench::run_bench_collecting(&config, &overrides, gallery)?;
    let path = penumbra::bench::write_report(&report, &args.out).map_err(|e| e.to_string())?;
    print_report(&report, &path);
    if let Some(dir) = &args.gallery {
        let hero = (args.hero[0].as_str(), args.hero[1].as_str());
        let page = penumbra::bench::write_gallery(dir, &report, &shots, hero).map_err(|e| e.to_string())?;
        println!("gallery    {}", page.display());
    }
    Ok(())
}

/// Prints a bench report's summary: the adapter and each preset's means.
fn print_report(report: &penumbra::analysis::BenchReport, path: &std::path::Path) {
    println!("adapter    {} ({}, {})", report.adapter, report.backend, report.driver);
    println!(
        "{:<22} {:>9} {:>9} {:>12} {:>8}",
        "preset", "gpu ms", "cpu ms", "penumbra MAE", "acne %"
    );
    for p in &report.presets {
        let cpu = p.scenes.iter().map(|s| s.cpu_ms).sum::<f64>() / p.scenes.len().max(1) as f64;
        let acne = p.scenes.iter().map(|s| s.errors.acne_rate).sum::<f64>() / p.scenes.len().max(1) as f64;
        println!(
            "{:<22} {:>9.3} {:>9.3} {:>12.4} {:>8.2}",
            p.preset,
            p.mean_gpu_ms(),
            cpu,
            p.mean_penumbra_mae(),
            acne * 100.0
        );
    }
    println!("report     {}", path.display());
}
