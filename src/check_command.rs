//! `penumbra check` (part of the `penumbra` binary): loads scene files and everything they
//! name as `render` would, without a GPU, reports every problem, and prints the memory of each
//! scene's textures and of the shadow storages its first frame takes, under their budgets.

use std::error::Error;
use std::path::PathBuf;

use penumbra::app::{PreparedScene, SpawnError, shadow_memory_of};
use penumbra::diagnostic::{ErrorStyle, render_error};
use penumbra::ecs::shadow_memory::ShadowMemoryBudget;
use penumbra::scene::{SceneDesc, SceneLimits};
use penumbra::text::format_bytes;

/// The view `check` fits the shadow memory for: `render`'s default image size.
const CHECK_VIEW: (u32, u32) = (1280, 720);

/// A scene that loaded but could not be prepared: the file, then the problem.
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", scene.display())]
struct InScene {
    scene: PathBuf,
    source: SpawnError,
}

/// A scene whose shadows the memory budget cannot hold: the file, then the lights.
#[derive(Debug, thiserror::Error)]
#[error("{}: {message}", scene.display())]
struct OverBudget {
    scene: PathBuf,
    message: String,
}

/// Loads each scene and everything it names (glTF models, textures) exactly as `render`
/// would, without a GPU, and reports every problem in `style`; prints the shadow memory of
/// each scene that loads (fitted to `budget`, as `render` fits it in a 1280×720 view).
pub fn check(
    scenes: Vec<PathBuf>,
    limits: SceneLimits,
    budget: ShadowMemoryBudget,
    style: ErrorStyle,
) -> Result<(), String> {
    let mut failed = 0;
    for path in &scenes {
        let loaded = SceneDesc::load_with(path, &limits)
            .map_err(Box::<dyn Error>::from)
            .and_then(|desc| {
                let scene = path.clone();
                let prepared = PreparedScene::new(&desc).map_err(|source| InScene { scene, source })?;
                Ok((desc, prepared))
            })
            .and_then(|(desc, prepared)| {
                let entities = prepared.entity_count();
                let textures = (
                    prepared.image_count(),
                    prepared.texture_bytes(),
                    prepared.warnings().to_vec(),
                );
                let memory = shadow_memory_of(prepared, CHECK_VIEW, budget);
                match &memory.error {
                    Some(message) => Err(Box::new(OverBudget {
                        scene: path.clone(),
                        message: message.clone(),
                    }) as Box<dyn Error>),
                    None => Ok((desc, entities, textures, memory)),
                }
            });
        match loaded {
            Ok((desc, entities, (images, texture_bytes, notes), memory)) => {
                println!(
                    "{}: ok ({} instances, {} mesh entities)",
                    path.display(),
                    desc.instance_count(),
                    entities
                );
                println!(
                    "  textures {images} images, {} with their mips of a {} budget",
                    format_bytes(texture_bytes),
                    format_bytes(desc.limits.max_texture_bytes)
                );
                for note in &notes {
                    println!("  warning: {note}");
                }
                let lines = memory.lines();
                println!("  shadow memory {}", lines[0]);
                for line in &lines[1..] {
                    println!("    {line}");
                }
                if let Some(warning) = &memory.warning {
                    println!("  warning: {warning}");
                }
            }
            Err(e) => {
                eprintln!("{}", render_error(&*e, style));
                failed += 1;
            }
        }
    }
    if failed > 0 {
        Err(format!("{failed} of {} scene files have errors", scenes.len()))
    } else {
        Ok(())
    }
}
