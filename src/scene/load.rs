//! Reading a scene from a file or a string: parse with ron, then validate.

use std::path::{Path, PathBuf};

use ron::extensions::Extensions;
use ron::options::Options;
use serde::de::DeserializeOwned;

use crate::scene::desc::SceneDesc;
use crate::scene::error::{SceneError, parse_error};
use crate::scene::limits::SceneLimits;
use crate::scene::report::problem_lines;
use crate::scene::validate::validate;

impl SceneDesc {
    /// Reads, parses and validates the scene file at `path`. Relative texture and model
    /// paths in it are relative to its directory, which becomes
    /// [`base_dir`](SceneDesc::base_dir); textures and models must exist inside the asset
    /// root. The default [`SceneLimits`] apply.
    pub fn load(path: impl AsRef<Path>) -> Result<SceneDesc, SceneError> {
        Self::load_with(path, &SceneLimits::default())
    }

    /// [`load`](Self::load) with other budgets than the default ones.
    pub fn load_with(path: impl AsRef<Path>, limits: &SceneLimits) -> Result<SceneDesc, SceneError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
            path: path.to_owned(),
            source,
        })?;
        let base_dir = path.parent().map(Path::to_owned).unwrap_or_default();
        parse(&text, &path.display().to_string(), Some(base_dir), limits)
    }

    /// Parses and validates scene text; `origin` names it in error messages (a file name,
    /// say). Texture files are not checked, and [`base_dir`](SceneDesc::base_dir) is empty.
    /// The default [`SceneLimits`] apply.
    pub fn from_str(text: &str, origin: &str) -> Result<SceneDesc, SceneError> {
        Self::from_str_with(text, origin, &SceneLimits::default())
    }

    /// [`from_str`](Self::from_str) with other budgets than the default ones.
    pub fn from_str_with(text: &str, origin: &str, limits: &SceneLimits) -> Result<SceneDesc, SceneError> {
        parse(text, origin, None, limits)
    }
}

/// Parses RON text (after a byte-order mark, if any) into `T`, with located errors; returns
/// the value and the text it was read from, for locating later problems.
pub(crate) fn parse_ron<'t, T: DeserializeOwned>(text: &'t str, origin: &str) -> Result<(T, &'t str), SceneError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // `implicit_some` lets optional fields be written without `Some(...)`.
    let options = Options::default().with_default_extension(Extensions::IMPLICIT_SOME);
    let value = options.from_str(text).map_err(|err| parse_error(origin, text, &err))?;
    Ok((value, text))
}

fn parse(text: &str, origin: &str, base_dir: Option<PathBuf>, limits: &SceneLimits) -> Result<SceneDesc, SceneError> {
    let (mut scene, text): (SceneDesc, &str) = parse_ron(text, origin)?;
    let problems = validate(&scene, text, base_dir.as_deref(), limits);
    if !problems.is_empty() {
        return Err(SceneError::Invalid {
            origin: origin.to_owned(),
            source_lines: problem_lines(text, &problems),
            problems,
        });
    }
    scene.base_dir = base_dir.unwrap_or_default();
    scene.limits = limits.clone();
    Ok(scene)
}
