//! Budgets that bound what a scene file can make penumbra do: how many instances it may
//! place, which folder its files must stay in, how much memory its textures may take, and how
//! many problems an error message lists.

use std::path::PathBuf;

use crate::asset_io::DEFAULT_MAX_TEXTURE_BYTES;

/// The default of [`SceneLimits::max_instances`]: one million instances.
///
/// Each instance becomes an entity with a transform, bounds and draw data on the CPU (a few
/// hundred bytes) and an entry of the GPU instance buffer, so a million costs a few hundred
/// megabytes and still draws at interactive rates on a desktop GPU; the shipped `field`
/// scene has 100 000. Raise it with [`SceneDesc::from_str_with`] or
/// [`SceneDesc::load_with`] for bigger scenes.
///
/// [`SceneDesc::from_str_with`]: crate::scene::SceneDesc::from_str_with
/// [`SceneDesc::load_with`]: crate::scene::SceneDesc::load_with
pub const DEFAULT_MAX_INSTANCES: u64 = 1_000_000;

/// The most copies one grid may hold, whatever the instance budget: also the ceiling of
/// [`SceneLimits::max_instances`] for a single grid.
pub const MAX_GRID_INSTANCES: u64 = 10_000_000;

/// The most problems an error message lists; the rest are counted (`and 12 more problems`).
/// [`SceneError::Invalid`](crate::scene::SceneError::Invalid) still holds every problem.
pub const MAX_LISTED_PROBLEMS: usize = 50;

/// Budgets checked when a scene is validated; a scene over one is rejected with a located
/// problem. `SceneLimits::default()` is what [`SceneDesc::load`](crate::scene::SceneDesc::load)
/// and `penumbra check` use. A loaded scene keeps them in
/// [`SceneDesc::limits`](crate::scene::SceneDesc::limits), and spawning it holds to them too
/// (a glTF object counts one instance per drawn primitive there).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneLimits {
    /// The most instances (objects, with every grid copy counted) a scene may place in all.
    /// Default [`DEFAULT_MAX_INSTANCES`]. One grid may hold at most this many copies, and at
    /// most [`MAX_GRID_INSTANCES`].
    pub max_instances: u64,
    /// The folder every file the scene names (textures, models, their buffers and images)
    /// must stay inside; None for the default: the nearest enclosing folder named `assets`,
    /// else the scene's folder (see [`AssetIo`](crate::asset_io::AssetIo)).
    pub asset_root: Option<PathBuf>,
    /// Most bytes of all the scene's decoded images together (RGBA8 with their mip chains);
    /// an image that would pass it is downscaled to fit, with a warning. Default
    /// [`DEFAULT_MAX_TEXTURE_BYTES`].
    pub max_texture_bytes: u64,
}

impl Default for SceneLimits {
    fn default() -> Self {
        SceneLimits {
            max_instances: DEFAULT_MAX_INSTANCES,
            asset_root: None,
            max_texture_bytes: DEFAULT_MAX_TEXTURE_BYTES,
        }
    }
}

impl SceneLimits {
    /// The most copies one grid may hold under these limits.
    pub fn max_grid_instances(&self) -> u64 {
        self.max_instances.min(MAX_GRID_INSTANCES)
    }
}
