//! Error messages in two forms: **short**, the one line per problem that an error's
//! `Display` gives (`scene.ron:4:15: expected ..., found ...`), and **rich**, where each
//! problem of a scene, settings or glTF file is a diagnostic that shows the offending line
//! with the offending token underlined, in the style of rustc:
//!
//! ```text
//! error: expected one of the fields `mode`, ..., found unknown field `cascade_cont`
//!   --> scene.ron:4:15
//!   |
//! 4 |     shadows: (cascade_cont: 4),
//!   |               ^^^^^^^^^^^^
//!   |
//!   = help: did you mean `cascade_count`?
//! ```
//!
//! [`render_error`] writes any error in either form; errors that keep no source lines
//! (a missing file, a GPU error, a GLB file) are a plain `error: ...` line in the rich form.
//! An error keeps only the lines its problems are on ([`SourceLines`], cut around the
//! problem when long), never the whole text.
//! Pure text: nothing here touches the GPU or the file system.

mod excerpt;

use std::error::Error;

use codespan_reporting::diagnostic::{Diagnostic, Label};
use codespan_reporting::term::termcolor::Buffer;
use codespan_reporting::term::{Chars, Config, emit_into_string, emit_to_write_style};

use crate::app::{RenderError, SpawnError};
use crate::diagnostic::excerpt::{Excerpt, SourceLine};
use crate::scene::SceneError;

pub use excerpt::SourceLines;

/// How [`render_error`] writes an error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorStyle {
    /// Each problem as a diagnostic: `error: ...`, ` --> file:line:column`, the line, a
    /// caret under the offending token, and a `= help: did you mean ...?` where a
    /// misspelling is likely. `color` adds ANSI colours (for a terminal).
    Rich {
        /// Whether to colour the output with ANSI escape codes.
        color: bool,
    },
    /// The error's message (its `Display`): one line per problem, `file:line:column: ...`.
    Short,
}

/// One problem of a [`Report`].
#[derive(Clone, Debug)]
pub(crate) struct Spot<'e> {
    /// Line and column (from 1, in characters); `None` when the problem has no known place.
    pub(crate) at: Option<(usize, usize)>,
    /// The line it is on, if kept.
    pub(crate) line: Option<&'e SourceLine>,
    /// What is wrong, without the position.
    pub(crate) message: String,
    /// A line of help, like ``did you mean `cascade_count`?``.
    pub(crate) help: Option<String>,
}

/// The problems of one error, with the lines they are on.
#[derive(Clone, Debug)]
pub(crate) struct Report<'e> {
    /// The file name the `-->` lines show.
    pub(crate) origin: String,
    /// The problems, in the order shown.
    pub(crate) spots: Vec<Spot<'e>>,
    /// A last note, like `FILE: and 3 more problems`.
    pub(crate) more: Option<String>,
}

/// `FILE: and N more problems`, the line that ends a capped list of problems.
pub(crate) fn more_problems(origin: &str, more: usize) -> String {
    let s = if more == 1 { "" } else { "s" };
    format!("{origin}: and {more} more problem{s}")
}

/// Nested errors followed at most, in case a chain loops.
const MAX_CHAIN: usize = 32;

/// `err` as `style` asks, without a trailing newline.
///
/// [`ErrorStyle::Short`] is `err.to_string()`. [`ErrorStyle::Rich`] looks for a
/// [`SceneError`] (scene or settings file) or a glTF error in `err`, through this crate's
/// wrappers ([`RenderError`], [`SpawnError`], the bench's and the viewer's errors) and
/// [`Error::source`], and shows each of its problems with its line; words a wrapper puts in
/// front of the message (`scene.ron: object 0: `) become a note. Any other error is one
/// `error: ...` diagnostic. The output is the same on every run; colour only if asked.
pub fn render_error(err: &(dyn Error + 'static), style: ErrorStyle) -> String {
    let ErrorStyle::Rich { color } = style else {
        return err.to_string();
    };
    let message = err.to_string();
    let Some((inner, report)) = find_report(err) else {
        return emit(&[(Diagnostic::error().with_message(message), Excerpt::none())], color);
    };
    let mut diagnostics: Vec<(Diagnostic<()>, Excerpt)> = (report.spots.iter())
        .map(|spot| diagnostic(&report.origin, spot))
        .collect();
    // Words a wrapper adds in front: `scene.ron: object 0: ` before the model's message.
    let context = (message.strip_suffix(&inner.to_string()))
        .map(|front| front.trim_end_matches([':', ' ']))
        .filter(|front| !front.is_empty());
    if let (Some(front), Some((first, _))) = (context, diagnostics.first_mut()) {
        first.notes.push(format!("note: while loading {front}"));
    }
    if let Some(more) = &report.more {
        diagnostics.push((Diagnostic::note().with_message(more), Excerpt::none()));
    }
    emit(&diagnostics, color)
}

/// The error in `err`'s chain that keeps source lines, and its problems.
fn find_report<'e>(err: &'e (dyn Error + 'static)) -> Option<(&'e (dyn Error + 'static), Report<'e>)> {
    let mut current = err;
    for _ in 0..MAX_CHAIN {
        if let Some(scene) = current.downcast_ref::<SceneError>() {
            return Some((current, scene.report()?));
        }
        #[cfg(feature = "gltf")]
        if let Some(gltf) = current.downcast_ref::<crate::gltf::GltfError>() {
            return Some((current, gltf.report()?));
        }
        current = wrapped(current).or_else(|| current.source())?;
    }
    None
}

/// The error inside one of this crate's wrappers: those that show it transparently (so
/// [`Error::source`] skips it) or keep it beside their message.
fn wrapped<'e>(err: &'e (dyn Error + 'static)) -> Option<&'e (dyn Error + 'static)> {
    if let Some(e) = err.downcast_ref::<RenderError>() {
        return match e {
            RenderError::Scene(e) => Some(e),
            RenderError::Spawn(e) => Some(e),
            _ => None,
        };
    }
    if let Some(e) = err.downcast_ref::<SpawnError>() {
        return e.model_error();
    }
    #[cfg(feature = "bench")]
    if let Some(e) = err.downcast_ref::<crate::bench::BenchError>() {
        return match e {
            crate::bench::BenchError::Scene(e) => Some(e),
            crate::bench::BenchError::Spawn(e) => Some(e),
            _ => None,
        };
    }
    #[cfg(feature = "viewer")]
    if let Some(e) = err.downcast_ref::<crate::viewer::ViewerError>() {
        return match e {
            crate::viewer::ViewerError::Scene(e) => Some(e),
            crate::viewer::ViewerError::Spawn(e) => Some(e),
            _ => None,
        };
    }
    None
}

/// The diagnostic of one problem, and the line it shows. A problem whose line was not kept
/// (or that has no place) keeps its position in the message instead.
fn diagnostic(origin: &str, spot: &Spot) -> (Diagnostic<()>, Excerpt) {
    let message = match (spot.at, spot.line) {
        (_, Some(_)) => spot.message.clone(),
        (Some((line, column)), None) => format!("{origin}:{line}:{column}: {}", spot.message),
        (None, None) => format!("{origin}: {}", spot.message),
    };
    let mut d = Diagnostic::error().with_message(message);
    if let Some(help) = &spot.help {
        d = d.with_note(format!("help: {help}"));
    }
    match spot.line {
        Some(line) => {
            let excerpt = Excerpt::new(origin, line);
            (d.with_label(Label::primary((), excerpt.underline())), excerpt)
        }
        None => (d, Excerpt::none()),
    }
}

/// The diagnostics as text, ASCII-drawn like rustc's, with ANSI colours if `color`.
fn emit(diagnostics: &[(Diagnostic<()>, Excerpt)], color: bool) -> String {
    let config = Config {
        chars: Chars::ascii(),
        ..Config::default()
    };
    let mut out = String::new();
    for (d, excerpt) in diagnostics {
        // NOTE: writing to memory fails only on a label outside its line, which `Excerpt`
        // rules out; the message alone is better than nothing then.
        let written = if color {
            let mut buffer = Buffer::ansi();
            emit_to_write_style(&mut buffer, &config, excerpt, d)
                .map(|()| String::from_utf8_lossy(buffer.as_slice()).into_owned())
        } else {
            emit_into_string(&config, excerpt, d)
        };
        out.push_str(&written.unwrap_or_else(|_| format!("error: {}\n", d.message)));
    }
    out.trim_end().to_owned()
}

#[cfg(test)]
mod tests {
    use std::fmt;

    use super::*;
    use crate::scene::{Problem, SceneDesc};

    const RICH: ErrorStyle = ErrorStyle::Rich { color: false };

    fn parse_error() -> SceneError {
        SceneDesc::from_str("Scene(\n  camera: (fov: x),\n)", "s.ron").unwrap_err()
    }

    #[test]
    fn short_is_the_message_and_plain_errors_are_one_line() {
        let err = parse_error();
        assert_eq!(render_error(&err, ErrorStyle::Short), err.to_string());
        let io = std::io::Error::other("disk on fire\nand smoking");
        assert_eq!(render_error(&io, RICH), "error: disk on fire\nand smoking");
        assert_eq!(render_error(&io, ErrorStyle::Short), "disk on fire\nand smoking");
    }

    #[test]
    fn colour_only_when_asked() {
        let err = parse_error();
        let plain = render_error(&err, RICH);
        assert!(
            !plain.contains('\u{1b}') && plain.contains("  --> s.ron:2:17\n"),
            "{plain}"
        );
        let coloured = render_error(&err, ErrorStyle::Rich { color: true });
        assert!(coloured.contains("\u{1b}["), "{coloured:?}");
    }

    /// A wrapper that adds words in front of the message and keeps the error as its source.
    #[derive(Debug)]
    struct InObject(SceneError);

    impl fmt::Display for InObject {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "garden.ron: object 3: {}", self.0)
        }
    }

    impl Error for InObject {
        fn source(&self) -> Option<&(dyn Error + 'static)> {
            Some(&self.0)
        }
    }

    #[test]
    fn wrappers_are_looked_through_and_their_words_become_a_note() {
        let rich = render_error(&InObject(parse_error()), RICH);
        assert!(rich.starts_with("error: expected "), "{rich}");
        assert!(
            rich.ends_with("\n  = note: while loading garden.ron: object 3"),
            "{rich}"
        );
        // This crate's transparent wrappers, and a model's error kept beside its message.
        let render = RenderError::Scene(parse_error());
        assert_eq!(render_error(&render, RICH), render_error(&parse_error(), RICH));
        let spawn = SpawnError::Model {
            object: 2,
            message: parse_error().to_string(),
            error: Some(Box::new(parse_error())),
        };
        let rich = render_error(&RenderError::Spawn(spawn), RICH);
        assert!(rich.contains("  --> s.ron:2:17\n"), "{rich}");
        assert!(rich.ends_with("= note: while loading object 2"), "{rich}");
    }

    #[test]
    fn long_lists_end_with_a_count_and_lost_lines_keep_their_position() {
        let problem = |line| Problem {
            line,
            column: 2,
            field: "f".to_owned(),
            expected: "a number".to_owned(),
            found: "`y`".to_owned(),
            suggestion: None,
        };
        let err = SceneError::Invalid {
            origin: "s.ron".to_owned(),
            problems: (0..52).map(|_| problem(1)).collect(),
            source_lines: SourceLines::new("(f: y)", &[(1, 2, 1); 50]),
        };
        let rich = render_error(&err, RICH);
        assert_eq!(rich.matches("error: expected a number for `f`, found `y`").count(), 50);
        assert!(rich.ends_with("\n\nnote: s.ron: and 2 more problems"), "{rich}");
        // A line the text does not have: the message keeps the position, and no snippet.
        let err = SceneError::Invalid {
            origin: "s.ron".to_owned(),
            problems: vec![problem(9)],
            source_lines: SourceLines::new("(f: y)", &[(9, 2, 1)]),
        };
        assert_eq!(
            render_error(&err, RICH),
            "error: s.ron:9:2: expected a number for `f`, found `y`"
        );
    }
}
