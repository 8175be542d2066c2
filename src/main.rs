//! The `penumbra` command: render a scene file headless to a PNG (printing GPU and CPU
//! timings), or check a scene file for errors.

use std::error::Error;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

mod bench_command;
mod check_command;
mod cli_values;
mod render_command;
mod render_json;
mod render_text;

use clap::{Parser, Subcommand, ValueEnum};

use bench_command::{BenchArgs, bench};
use check_command::check;
use render_command::{RenderArgs, mebibytes, render};

use penumbra::diagnostic::{ErrorStyle, render_error};
use penumbra::ecs::shadow_memory::ShadowMemoryBudget;
use penumbra::scene::{DEFAULT_MAX_INSTANCES, SceneLimits};

#[derive(Parser)]
#[command(name = "penumbra", version, about = "Cascaded soft shadows, rendered and measured")]
struct Cli {
    /// How errors are printed: `rich` shows each problem's line with a caret under it,
    /// `short` one line per problem (`file:line:column: ...`). Default: rich when stderr is a
    /// terminal (in colour), short otherwise.
    #[arg(long, global = true, value_enum)]
    error_format: Option<ErrorFormat>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, ValueEnum)]
enum ErrorFormat {
    Rich,
    Short,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene headless to a PNG and print per-pass GPU times and CPU times.
    Render(RenderArgs),
    /// Open a scene in a window with a fly camera and the egui inspector (needs the
    /// `viewer` feature).
    #[cfg(feature = "viewer")]
    View(penumbra::viewer::ViewerArgs),
    /// Score every shadow preset against a ray-traced reference and measure its GPU and CPU
    /// cost; writes report.md and plot.png.
    Bench(BenchArgs),
    /// Load scene files and everything they name (glTF models, textures), as `render` would
    /// but without a GPU, and report every problem.
    Check {
        /// Scene files (RON).
        #[arg(required = true)]
        scenes: Vec<PathBuf>,
        /// Folder every file the scenes name must stay inside (default: the nearest
        /// enclosing folder named `assets`, else each scene's folder).
        #[arg(long)]
        asset_root: Option<PathBuf>,
        /// Most instances a scene may place (grid copies and glTF primitives counted).
        #[arg(long, default_value_t = DEFAULT_MAX_INSTANCES)]
        max_instances: u64,
        /// Most MiB of a scene's decoded images together, with their mip chains: an image that
        /// would pass it is downscaled to fit, with a warning.
        #[arg(long, value_parser = mebibytes(), default_value = "256")]
        texture_budget: u64,
        /// Most MiB of shadow maps, their moments and blur scratch (default 2048, a discrete
        /// GPU's; software Vulkan's is 512): lights smallest on screen are lowered to fit.
        #[arg(long, value_parser = mebibytes())]
        shadow_budget: Option<u64>,
    },
}

#[cfg(feature = "viewer")]
fn view(args: penumbra::viewer::ViewerArgs) -> Result<(), penumbra::viewer::ViewerError> {
    let summary = penumbra::viewer::run(&args.scene, args.options())?;
    println!(
        "viewer: {} frames drawn in {} ticks on {}",
        summary.frames, summary.ticks, summary.adapter
    );
    if args.offscreen && summary.frames > 0 {
        let ms = summary.elapsed.as_secs_f64() * 1e3 / f64::from(summary.frames);
        let gpu = summary
            .median_gpu_ms(1)
            .map_or_else(|| "no GPU timings".to_owned(), |m| format!("GPU {m:.2} ms (median)"));
        println!(
            "offscreen: {:.1} ms a frame ({:.1} frames a second) over {:.2} s; {gpu}",
            ms,
            1e3 / ms,
            summary.elapsed.as_secs_f64()
        );
    }
    if let Some(path) = summary.screenshot {
        println!("screenshot written to {}", path.display());
    }
    Ok(())
}

/// Without `XDG_RUNTIME_DIR` there is no Wayland session, yet Mesa's implicit Vulkan layer
/// `VK_LAYER_MESA_device_select` tries to connect to one while listing GPUs, and libwayland
/// prints `error: XDG_RUNTIME_DIR is invalid or not set` twice. The layer only reorders GPUs
/// for a desktop session (penumbra picks its adapter itself), so it is turned off through its
/// manifest's own switch, unless the user set that switch.
fn quiet_device_select() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() && std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: called at the start of `main`, before any other thread exists.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
        log::debug!("XDG_RUNTIME_DIR is not set: Mesa's device-select layer turned off (NODEVICE_SELECT=1)");
    }
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    quiet_device_select();
    let cli = Cli::parse();
    let terminal = std::io::stderr().is_terminal();
    let style = match (cli.error_format, terminal) {
        (Some(ErrorFormat::Rich), _) | (None, true) => ErrorStyle::Rich { color: terminal },
        (Some(ErrorFormat::Short), _) | (None, false) => ErrorStyle::Short,
    };
    let result: Result<(), Box<dyn Error>> = match cli.command {
        Command::Render(args) => render(args).map_err(Into::into),
        #[cfg(feature = "viewer")]
        Command::View(args) => view(args).map_err(Into::into),
        Command::Bench(args) => bench(args),
        Command::Check {
            scenes,
            asset_root,
            max_instances,
            texture_budget,
            shadow_budget,
        } => {
            let limits = SceneLimits {
                asset_root,
                max_instances,
                max_texture_bytes: texture_budget,
            };
            let mut budget = ShadowMemoryBudget::default();
            budget.bytes = shadow_budget.unwrap_or(budget.bytes);
            check(scenes, limits, budget, style).map_err(Into::into)
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            match style {
                ErrorStyle::Short => eprintln!("error: {e}"),
                ErrorStyle::Rich { .. } => eprintln!("{}", render_error(&*e, style)),
            }
            ExitCode::FAILURE
        }
    }
}
