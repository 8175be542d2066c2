//! The error type of scene loading, and the wording of parse errors.

use std::fmt;
use std::path::PathBuf;

use ron::error::{Error as RonError, SpannedError};

use crate::diagnostic::{SourceLines, more_problems};
use crate::scene::limits::MAX_LISTED_PROBLEMS;
use crate::scene::locate::{Node, Pos, token_at, underline_lengths};
use crate::scene::suggest::did_you_mean;
use crate::text::echoed;

/// Why a scene could not be loaded. Every message starts with the file name; parse and
/// validation messages continue with `line:column:` and what was expected there, and end
/// with `; did you mean ...?` where a misspelling is likely. [`render_error`] shows them
/// with the offending line and a caret.
///
/// [`render_error`]: crate::diagnostic::render_error
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// The scene file could not be read (missing, unreadable, or not UTF-8).
    #[error("{}: cannot read the scene file: {source}", path.display())]
    Io {
        /// The path given to [`SceneDesc::load`](crate::scene::SceneDesc::load).
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The text is not a scene: a RON syntax error, a value of the wrong type, an unknown,
    /// missing or repeated field. Parsing stops at the first such error.
    #[error("{origin}:{line}:{column}: {message}{}", did_you_mean_suffix(suggestion.as_deref()))]
    Parse {
        /// File name (or the name given to `from_str`).
        origin: String,
        /// Line of the error, from 1.
        line: usize,
        /// Column of the error in characters, from 1.
        column: usize,
        /// What was expected and what was found.
        message: String,
        /// The name that an unknown field or variant most likely meant, quoted as in the
        /// message (`` `cascade_count` ``); the message ends with `; did you mean ...?` then.
        suggestion: Option<String>,
        /// The offending line, for showing it; not part of the message.
        source_lines: SourceLines,
    },
    /// The scene parsed but has invalid values; the problems are listed in file order, one
    /// per line, at most [`MAX_LISTED_PROBLEMS`](crate::scene::MAX_LISTED_PROBLEMS) of them
    /// and then a line `FILE: and N more problems`.
    #[error("{}", list_problems(origin, problems))]
    Invalid {
        /// File name (or the name given to `from_str`).
        origin: String,
        /// Every problem, sorted by position.
        problems: Vec<Problem>,
        /// The lines of the listed problems, for showing them; not part of the message.
        source_lines: SourceLines,
    },
}

/// One invalid value in a scene that parsed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Problem {
    /// Line of the offending value, from 1.
    pub line: usize,
    /// Column of the offending value in characters, from 1.
    pub column: usize,
    /// Field path of the value, like `objects[3].material` or `shadows.cascade_count`.
    pub field: String,
    /// What a valid value looks like.
    pub expected: String,
    /// The value that was found.
    pub found: String,
    /// The value most likely meant, quoted as in the message (`"leaf"` for a misspelt
    /// material name); the message ends with `; did you mean ...?` then.
    pub suggestion: Option<String>,
}

impl Problem {
    /// What is wrong, without the position: ``expected ... for `FIELD`, found ...``.
    pub fn message(&self) -> String {
        format!("expected {} for `{}`, found {}", self.expected, self.field, self.found)
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}: {}{}",
            self.line,
            self.column,
            self.message(),
            did_you_mean_suffix(self.suggestion.as_deref())
        )
    }
}

/// `; did you mean NAME?` after a message, or nothing.
fn did_you_mean_suffix(suggestion: Option<&str>) -> String {
    suggestion.map(|s| format!("; did you mean {s}?")).unwrap_or_default()
}

fn list_problems(origin: &str, problems: &[Problem]) -> String {
    let mut lines: Vec<String> = (problems.iter().take(MAX_LISTED_PROBLEMS))
        .map(|p| format!("{origin}:{p}"))
        .collect();
    if let Some(more) = problems.len().checked_sub(MAX_LISTED_PROBLEMS).filter(|&n| n > 0) {
        lines.push(more_problems(origin, more));
    }
    lines.join("\n")
}

/// Turns ron's error into a [`SceneError::Parse`] that says what was expected where.
pub(crate) fn parse_error(origin: &str, text: &str, err: &SpannedError) -> SceneError {
    let mut pos = Pos {
        line: err.span.start.line.max(1),
        column: err.span.start.col.max(1),
    };
    if let RonError::ExpectedDifferentLength { .. } = err.code {
        // ron points at the closing bracket; the tuple's start is easier to find.
        pos = Node::parse_until(text, pos).opening_of(pos).unwrap_or(pos);
    }
    let mut code = &err.code;
    let found = match token_at(text, pos) {
        Some((start, tok)) => {
            // ron reads `2` of `2.5` as an integer and then wants a separator: the number
            // itself is what is wrong.
            let separator = matches!(
                code,
                RonError::ExpectedComma
                    | RonError::ExpectedStructLikeEnd
                    | RonError::ExpectedArrayEnd
                    | RonError::ExpectedMapEnd
            );
            if separator && start < pos && tok.starts_with(|c: char| c.is_ascii_digit()) {
                code = &RonError::ExpectedInteger;
            }
            // ron may point inside the token (after the sign of `-1`) or at the blank before
            // it: point at the token itself.
            pos = start;
            format!("`{}`", echoed(&tok))
        }
        None => "the end of the file".to_owned(),
    };
    // Only the text up to the error is read again, and only the groups around it are kept.
    let path = Node::parse_until(text, pos).path_at(pos);
    let token_len = underline_lengths(text, &[pos], false).first().copied().unwrap_or(1);
    SceneError::Parse {
        origin: origin.to_owned(),
        line: pos.line,
        column: pos.column,
        message: describe(code, &path, &found),
        suggestion: suggest(code),
        source_lines: SourceLines::new(text, &[(pos.line, pos.column, token_len)]),
    }
}

/// The field or variant name that an unknown one most likely meant, in backticks.
fn suggest(code: &RonError) -> Option<String> {
    let (RonError::NoSuchStructField { expected, found, .. } | RonError::NoSuchEnumVariant { expected, found, .. }) =
        code
    else {
        return None;
    };
    did_you_mean(found, expected).map(|name| format!("`{name}`"))
}

/// The message for one ron error code, in the form `expected ..., found ...`.
fn describe(code: &RonError, path: &str, found: &str) -> String {
    let found_instead = |what: &str, found: &str| {
        if path.is_empty() {
            format!("expected {what}, found {found}")
        } else {
            format!("expected {what} for `{path}`, found {found}")
        }
    };
    let of = |what: &str| found_instead(what, found);
    match code {
        RonError::Eof => "expected more text (is a bracket left open?), found the end of the file".to_owned(),
        RonError::ExpectedArray => of("a list `[...]`"),
        RonError::ExpectedArrayEnd => format!("expected `,` or `]`, found {found}"),
        RonError::ExpectedBoolean => of("`true` or `false`"),
        RonError::ExpectedComma => format!("expected `,`, found {found}"),
        RonError::ExpectedFloat => of("a number"),
        RonError::ExpectedInteger => of("an integer"),
        RonError::ExpectedOption => of("`Some(...)` or `None`"),
        RonError::ExpectedOptionEnd | RonError::ExpectedStructLikeEnd => {
            format!("expected `,` or `)`, found {found}")
        }
        RonError::ExpectedMap => of("a map `{ \"name\": value, ... }`"),
        RonError::ExpectedMapColon => format!("expected `:` after the map key, found {found}"),
        RonError::ExpectedMapEnd => format!("expected `,` or `}}`, found {found}"),
        RonError::ExpectedDifferentStructName { expected, found } => found_instead(
            &format!("`{expected}(...)` or `(...)`"),
            &format!("`{}(...)`", echoed(found)),
        ),
        RonError::ExpectedStructLike => of("`(`"),
        RonError::ExpectedNamedStructLike("") => of("`(`"),
        RonError::ExpectedNamedStructLike(name) => of(&format!("`(` or `{name}(`")),
        RonError::ExpectedUnit => of("`()`"),
        RonError::ExpectedString => of("a string in double quotes"),
        RonError::ExpectedStringEnd => "expected a closing `\"`, found the end of the file".to_owned(),
        RonError::ExpectedIdentifier => of("a field name"),
        RonError::InvalidEscape(what) => {
            format!("expected a valid escape sequence in the string, found an invalid one: {what}")
        }
        RonError::ExceededRecursionLimit => "expected at most 128 levels of nested brackets, found more".to_owned(),
        RonError::IntegerOutOfBounds => of("a non-negative integer small enough for its type"),
        RonError::InvalidIntegerDigit { digit, base } => {
            format!("expected a base-{base} digit, found {digit:?}")
        }
        RonError::UnexpectedChar(c) => format!("expected a value, found {c:?}"),
        RonError::TrailingCharacters => {
            format!("expected the end of the file after the scene, found {found}")
        }
        RonError::UnclosedBlockComment => "expected `*/` closing a block comment, found the end of the file".to_owned(),
        RonError::NoSuchStructField { expected, found, outer } => format!(
            "expected one of the fields {}{}, found unknown field `{}`",
            names(expected),
            outer.as_deref().map(|o| format!(" of `{o}`")).unwrap_or_default(),
            echoed(found),
        ),
        RonError::NoSuchEnumVariant { expected, found, outer } => {
            let what = match (path.is_empty(), outer) {
                (false, _) => format!(" for `{path}`"),
                (true, Some(o)) => format!(" of `{o}`"),
                (true, None) => String::new(),
            };
            format!(
                "expected one of {}{what}, found unknown variant `{}`",
                names(expected),
                echoed(found)
            )
        }
        RonError::MissingStructField { field, outer } => format!(
            "expected the required field `{field}`{}, found none",
            match (path.is_empty(), outer) {
                (false, _) => format!(" in `{path}`"),
                (true, Some(o)) => format!(" in `{o}`"),
                (true, None) => String::new(),
            }
        ),
        RonError::DuplicateStructField { field, .. } => {
            format!("expected each field once, found `{}` a second time", echoed(field))
        }
        RonError::InvalidValueForType { expected, found: what } => found_instead(expected, &echoed(what)),
        RonError::ExpectedDifferentLength { expected, found: n } => {
            let what = if *n == 1 {
                "1 element".to_owned()
            } else {
                format!("{n} elements")
            };
            found_instead(&tuple_of(expected), &what)
        }
        other => {
            let text = other.to_string();
            let mut chars = text.chars();
            let first = chars.next().map(|c| c.to_lowercase().to_string()).unwrap_or_default();
            format!("{first}{}", chars.as_str())
        }
    }
}

/// Rewords glam's "a sequence of 3 f32 values" as "3 numbers in parentheses, like `(...)`".
fn tuple_of(expected: &str) -> String {
    let words: Vec<&str> = expected.split(' ').collect();
    match words[..] {
        ["a", "sequence", "of", n, kind, "values"] => {
            let what = if kind.starts_with('f') { "numbers" } else { "integers" };
            let example: Vec<String> = (1..=n.parse().unwrap_or(0)).map(|i: u32| i.to_string()).collect();
            format!("{n} {what} in parentheses, like `({})`", example.join(", "))
        }
        _ => expected.to_owned(),
    }
}

/// Formats `["a", "b"]` as "`a`, `b`".
fn names(list: &[&str]) -> String {
    let quoted: Vec<String> = list.iter().map(|n| format!("`{n}`")).collect();
    if quoted.is_empty() {
        "(none)".to_owned()
    } else {
        quoted.join(", ")
    }
}
