//! The interactive viewer: a window on a RON scene with a fly camera and the egui inspector.
//!
//! ```text
//! cargo run --release --example viewer -- assets/scenes/garden.ron
//! ```
//!
//! Right mouse button + drag looks around, W/A/S/D/Q/E move, Shift is faster, the mouse
//! wheel changes the speed. Edits to the scene file (and to `--settings` / `--shader` files)
//! are applied within a second; an invalid edit shows its error and keeps the last good
//! scene. `--help` lists every option.

use clap::Parser;
use penumbra::viewer::ViewerArgs;

/// Command line of the example: the viewer's own arguments.
#[derive(Parser)]
#[command(about = "penumbra's interactive shadow viewer")]
struct Cli {
    #[command(flatten)]
    args: ViewerArgs,
}

fn main() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    match penumbra::viewer::run(&cli.args.scene, cli.args.options()) {
        Ok(summary) => {
            println!("{} frames drawn on {}", summary.frames, summary.adapter);
            if let Some(path) = summary.screenshot {
                println!("screenshot written to {}", path.display());
            }
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
