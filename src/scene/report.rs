//! Scene and settings errors as [`Report`]s for [`render_error`]: each problem with the line
//! it is on, the token (or, for an invalid value, the whole value) underlined.
//!
//! [`render_error`]: crate::diagnostic::render_error

use crate::diagnostic::{Report, SourceLines, Spot, more_problems};
use crate::scene::error::{Problem, SceneError};
use crate::scene::limits::MAX_LISTED_PROBLEMS;
use crate::scene::locate::{Pos, underline_lengths};

/// The lines of the problems a message lists (`problems` in file order), each value
/// underlined whole when it fits on its line.
pub(crate) fn problem_lines(text: &str, problems: &[Problem]) -> SourceLines {
    let listed = &problems[..problems.len().min(MAX_LISTED_PROBLEMS)];
    let positions: Vec<Pos> = (listed.iter())
        .map(|p| Pos {
            line: p.line,
            column: p.column,
        })
        .collect();
    let lengths = underline_lengths(text, &positions, true);
    let places: Vec<(usize, usize, usize)> = (positions.iter().zip(lengths))
        .map(|(pos, len)| (pos.line, pos.column, len))
        .collect();
    SourceLines::new(text, &places)
}

impl SceneError {
    /// The problems with their lines; `None` for an unreadable file.
    pub(crate) fn report(&self) -> Option<Report<'_>> {
        let help = |suggestion: &Option<String>| suggestion.as_ref().map(|s| format!("did you mean {s}?"));
        match self {
            SceneError::Io { .. } => None,
            SceneError::Parse {
                origin,
                line,
                column,
                message,
                suggestion,
                source_lines,
            } => Some(Report {
                origin: origin.clone(),
                spots: vec![Spot {
                    at: Some((*line, *column)),
                    line: source_lines.get(0),
                    message: message.clone(),
                    help: help(suggestion),
                }],
                more: None,
            }),
            SceneError::Invalid {
                origin,
                problems,
                source_lines,
            } => {
                let spots = (problems.iter().take(MAX_LISTED_PROBLEMS).enumerate())
                    .map(|(i, p)| Spot {
                        at: Some((p.line, p.column)),
                        line: source_lines.get(i),
                        message: p.message(),
                        help: help(&p.suggestion),
                    })
                    .collect();
                let more = problems.len().saturating_sub(MAX_LISTED_PROBLEMS);
                Some(Report {
                    origin: origin.clone(),
                    spots,
                    more: (more > 0).then(|| more_problems(origin, more)),
                })
            }
        }
    }
}
