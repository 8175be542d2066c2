//! Shadow-settings files: a [`ShadowSettings`] on its own, in RON, as the viewer's "save
//! settings" button writes it and as `--settings` (and live reload) reads it. Errors are
//! located like scene errors: `file:line:column: expected …`.
//!
//! ```text
//! ShadowSettings(
//!     mode: Pcss,
//!     cascade_count: 3,
//!     resolution: 1024,
//! )
//! ```
//!
//! Every field is optional and defaults to [`ShadowSettings::default`].

use std::path::Path;

use ron::ser::PrettyConfig;

use crate::scene::error::{Problem, SceneError};
use crate::scene::load::parse_ron;
use crate::scene::locate::{Node, Seg};
use crate::scene::report::problem_lines;
use crate::settings::ShadowSettings;

/// Reads and checks a settings file.
pub fn load_settings(path: impl AsRef<Path>) -> Result<ShadowSettings, SceneError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: path.to_owned(),
        source,
    })?;
    settings_from_str(&text, &path.display().to_string())
}

/// Parses and checks settings text; `origin` names it in error messages. Out-of-range values
/// are errors here (a file is fixed by editing it), not clamped.
pub fn settings_from_str(text: &str, origin: &str) -> Result<ShadowSettings, SceneError> {
    let (settings, text): (ShadowSettings, &str) = parse_ron(text, origin)?;
    let found = settings.problems();
    if found.is_empty() {
        return Ok(settings);
    }
    let tree = Node::parse(text);
    let mut problems: Vec<Problem> = found
        .into_iter()
        .map(|p| {
            let path: Vec<Seg> = p.field.split('.').map(Seg::Field).collect();
            let pos = tree.find(&path);
            Problem {
                line: pos.line,
                column: pos.column,
                field: p.field.to_owned(),
                expected: p.expected.to_owned(),
                found: p.found,
                suggestion: None,
            }
        })
        .collect();
    problems.sort_by_key(|p| (p.line, p.column));
    Err(SceneError::Invalid {
        origin: origin.to_owned(),
        source_lines: problem_lines(text, &problems),
        problems,
    })
}

/// The settings as a RON file: every field, one per line, under a comment.
pub fn settings_to_ron(settings: &ShadowSettings) -> String {
    let config = PrettyConfig::new().struct_names(true);
    let body = ron::ser::to_string_pretty(settings, config).expect("settings always serialise");
    format!("// penumbra shadow settings; every field is optional.\n{body}\n")
}

/// Writes [`settings_to_ron`] to `path` (through a temporary file, so a reader never sees
/// half a file).
pub fn save_settings(path: impl AsRef<Path>, settings: &ShadowSettings) -> Result<(), SceneError> {
    let path = path.as_ref();
    let io = |source| SceneError::Io {
        path: path.to_owned(),
        source,
    };
    let mut temp = path.as_os_str().to_owned();
    temp.push(".tmp");
    std::fs::write(&temp, settings_to_ron(settings)).map_err(io)?;
    std::fs::rename(&temp, path).map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::ShadowMode;

    #[test]
    fn saved_settings_read_back_equal() {
        let settings = {
            let mut s = ShadowSettings::default();
            s.filter.mode = ShadowMode::Pcss;
            s.map.cascades.count = 3;
            s.map.cascades.split_lambda = 0.25;
            s
        };
        let text = settings_to_ron(&settings);
        assert_eq!(settings_from_str(&text, "s.ron").unwrap(), settings);
    }

    #[test]
    fn fields_are_optional() {
        let s = settings_from_str("ShadowSettings(cascade_count: 2)", "s.ron").unwrap();
        assert_eq!(s.map.cascades.count, 2);
        assert_eq!(s.map.resolution, ShadowSettings::default().map.resolution);
        assert_eq!(settings_from_str("()", "s.ron").unwrap(), ShadowSettings::default());
    }

    #[test]
    fn bad_values_are_located() {
        let err = settings_from_str("ShadowSettings(\n  mode: Pcss,\n  cascade_count: 9,\n)", "s.ron").unwrap_err();
        let text = err.to_string();
        assert!(text.starts_with("s.ron:3:18: expected"), "{text}");
        assert!(text.contains("cascade_count") && text.contains("found 9"), "{text}");
        let err = settings_from_str("ShadowSettings(mode: Soft)", "s.ron").unwrap_err();
        assert!(err.to_string().starts_with("s.ron:1:22:"), "{err}");
        let err = settings_from_str("ShadowSettings(cascades: 2)", "s.ron").unwrap_err();
        assert!(err.to_string().contains("cascades"), "{err}");
    }
}
