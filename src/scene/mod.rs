//! Scene files: the RON description of a test scene (camera, sun, shadow settings,
//! materials, objects and object grids), loaded with precise `file:line:column` errors.
//!
//! ```no_run
//! # use penumbra::scene::SceneDesc;
//! let scene = SceneDesc::load("assets/scenes/default.ron")?;
//! for instance in scene.instances() {
//!     let material = &scene.materials[instance.material];
//!     let _ = (instance.shape, instance.matrix(), material.base_color);
//! }
//! # Ok::<(), penumbra::scene::SceneError>(())
//! ```
//!
//! The format is described in `docs/scene-format.md`.

mod animation;
mod desc;
mod error;
mod grid;
mod limits;
mod load;
mod locate;
mod report;
mod settings_file;
mod suggest;
mod validate;
mod values;

pub use animation::AnimationDesc;
pub use desc::{
    AlphaMode, CameraDesc, GridDesc, Jitter, LightDesc, MaterialDesc, MaterialLookup, ObjectDesc, SceneDesc, Shape,
    SunDesc,
};
pub use error::{Problem, SceneError};
pub use grid::ObjectInstance;
pub use limits::{DEFAULT_MAX_INSTANCES, MAX_GRID_INSTANCES, MAX_LISTED_PROBLEMS, SceneLimits};
pub use settings_file::{load_settings, save_settings, settings_from_str, settings_to_ron};
