//! The source lines an error keeps ([`SourceLines`]: each problem's line, cut to a window
//! around the problem when long, so an error never holds a whole file), and one such line
//! as codespan's [`Files`] ([`Excerpt`]): with `...` where it was cut, control characters
//! made harmless, and the line's real number and the problem's real column.

use std::ops::Range;

use codespan_reporting::files::{Error, Files};

/// Lines longer than this, in characters, are cut to a window around the underline.
const MAX_LINE_CHARS: usize = 120;

/// Characters kept on each side of the underline in a cut line.
const CONTEXT_CHARS: usize = 50;

/// The most characters underlined.
const MAX_UNDERLINE: usize = 80;

/// What stands for the text cut from a long line.
const CUT: &str = "...";

/// The lines of a source text that an error's problems are on, one per problem shown, each
/// cut to a window around its problem when long: what
/// [`render_error`](crate::diagnostic::render_error) shows under each problem. It holds a few
/// hundred bytes per problem, however large the text; the error's message does not use it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SourceLines(Vec<Option<SourceLine>>);

impl SourceLines {
    /// For each `(line, column, len)` of `places` (line from 1, column from 1 in characters,
    /// `len` characters to underline), the line of `text` it is on; none for a line the text
    /// does not have (line 0 included). Reads the text once, up to the last line wanted.
    pub(crate) fn new(text: &str, places: &[(usize, usize, usize)]) -> SourceLines {
        let mut wanted: Vec<(usize, usize)> = (places.iter().enumerate())
            .filter(|(_, place)| place.0 > 0)
            .map(|(i, place)| (place.0, i))
            .collect();
        wanted.sort_unstable();
        let mut out = vec![None; places.len()];
        let mut rows = text.split('\n').zip(1..);
        let mut current: Option<(&str, usize)> = None;
        for (line, i) in wanted {
            while current.is_none_or(|(_, n)| n < line) {
                match rows.next() {
                    Some(row) => current = Some(row),
                    None => break,
                }
            }
            if let Some((row, _)) = current.filter(|&(_, n)| n == line) {
                let (_, column, len) = places[i];
                out[i] = Some(SourceLine::cut(row, line, column, len));
            }
        }
        SourceLines(out)
    }

    /// The line of problem `i`, if kept.
    pub(crate) fn get(&self, i: usize) -> Option<&SourceLine> {
        self.0.get(i)?.as_ref()
    }
}

/// One problem's line, or the part of it around the problem.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct SourceLine {
    /// Line, from 1.
    pub(crate) line: usize,
    /// Column of the problem in characters, from 1 (may be past the end of the line).
    pub(crate) column: usize,
    /// The kept text of the line.
    text: String,
    /// Characters of the line before `text` (cut off).
    skipped: usize,
    /// Whether the line goes on after `text`.
    more: bool,
    /// Characters underlined, from the problem's column (0 at the end of the line).
    len: usize,
}

impl SourceLine {
    /// `row` (line `line`, without its newline) with `len` characters from `column`
    /// underlined, cut when long; the underline stops at the end of the line.
    fn cut(row: &str, line: usize, column: usize, len: usize) -> SourceLine {
        let row = row.strip_suffix('\r').unwrap_or(row);
        let chars = row.chars().count();
        let start = column.saturating_sub(1).min(chars);
        let len = len.clamp(1, MAX_UNDERLINE).min(chars - start);
        let (from, to) = match chars <= MAX_LINE_CHARS {
            true => (0, chars),
            false => (
                start.saturating_sub(CONTEXT_CHARS),
                (start + len + CONTEXT_CHARS).min(chars),
            ),
        };
        SourceLine {
            line,
            column,
            text: row[char_to_byte(row, from)..char_to_byte(row, to)].to_owned(),
            skipped: from,
            more: to < chars,
            len,
        }
    }
}

/// The byte offset of character `c` of `text` (its length past the end).
fn char_to_byte(text: &str, c: usize) -> usize {
    text.char_indices().nth(c).map_or(text.len(), |(b, _)| b)
}

/// The line shown under one problem, as codespan reads it.
#[derive(Debug)]
pub(super) struct Excerpt {
    name: String,
    line: usize,
    column: usize,
    text: String,
    underline: Range<usize>,
}

impl Excerpt {
    /// `source` as shown under a problem of file `name`: `...` where it was cut, control
    /// characters (which would act on a terminal) as one replacement character each, so the
    /// underline keeps its place.
    pub(super) fn new(name: &str, source: &SourceLine) -> Excerpt {
        let mut text = String::new();
        let mut start = source.column.saturating_sub(1).saturating_sub(source.skipped);
        if source.skipped > 0 {
            text.push_str(CUT);
            start += CUT.chars().count();
        }
        let shown = source.text.chars();
        text.extend(shown.map(|c| if c.is_control() && c != '\t' { '\u{FFFD}' } else { c }));
        let underline = char_to_byte(&text, start)..char_to_byte(&text, start + source.len);
        if source.more {
            text.push_str(CUT);
        }
        Excerpt {
            name: name.to_owned(),
            line: source.line,
            column: source.column,
            text,
            underline,
        }
    }

    /// An excerpt of nothing, for diagnostics without a label.
    pub(super) fn none() -> Excerpt {
        Excerpt {
            name: String::new(),
            line: 1,
            column: 1,
            text: String::new(),
            underline: 0..0,
        }
    }

    /// The byte range of the underline in the shown line.
    pub(super) fn underline(&self) -> Range<usize> {
        self.underline.clone()
    }
}

impl<'a> Files<'a> for Excerpt {
    type FileId = ();
    type Name = &'a str;
    type Source = &'a str;

    fn name(&'a self, (): ()) -> Result<&'a str, Error> {
        Ok(&self.name)
    }

    fn source(&'a self, (): ()) -> Result<&'a str, Error> {
        Ok(&self.text)
    }

    fn line_index(&'a self, (): (), _byte_index: usize) -> Result<usize, Error> {
        Ok(0)
    }

    fn line_number(&'a self, (): (), _line_index: usize) -> Result<usize, Error> {
        Ok(self.line)
    }

    /// The problem's own column (the shown line may be cut, and there is one label).
    fn column_number(&'a self, (): (), _line_index: usize, _byte_index: usize) -> Result<usize, Error> {
        Ok(self.column)
    }

    fn line_range(&'a self, (): (), _line_index: usize) -> Result<Range<usize>, Error> {
        Ok(0..self.text.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shown line and the underlined text of the problem at `line`:`column`.
    fn shown(source: &str, line: usize, column: usize, len: usize) -> (String, String) {
        let lines = SourceLines::new(source, &[(line, column, len)]);
        let e = Excerpt::new("f", lines.get(0).expect("the line is kept"));
        (e.text.clone(), e.text[e.underline()].to_owned())
    }

    #[test]
    fn a_short_line_is_shown_whole() {
        assert_eq!(shown("a\n  bcd e\n", 2, 3, 3), ("  bcd e".into(), "bcd".into()));
        assert_eq!(shown("a\r\nbc\r\n", 2, 1, 9), ("bc".into(), "bc".into()));
        // Columns count characters, not bytes.
        assert_eq!(shown("(\"éé\", x)", 1, 8, 1), ("(\"éé\", x)".into(), "x".into()));
        // Past the end of the line: an empty underline at its end, the column as given.
        let lines = SourceLines::new("ab\n", &[(1, 9, 1)]);
        let e = Excerpt::new("f", lines.get(0).unwrap());
        assert_eq!((e.underline(), e.column), (2..2, 9));
    }

    #[test]
    fn only_the_lines_of_the_places_are_kept() {
        let text = "one\ntwo\nthree\n";
        let lines = SourceLines::new(
            text,
            &[(3, 1, 1), (1, 2, 1), (0, 1, 1), (4, 1, 1), (5, 1, 1), (3, 2, 9)],
        );
        let kept: Vec<Option<&str>> = (0..7).map(|i| lines.get(i).map(|l| l.text.as_str())).collect();
        // The empty line after the final newline exists; the one after it does not.
        assert_eq!(
            kept,
            [Some("three"), Some("one"), None, Some(""), None, Some("three"), None]
        );
        assert_eq!(SourceLines::default().get(0), None);
    }

    #[test]
    fn a_long_line_is_cut_around_the_underline() {
        let line = format!("{}TARGET{}", "é".repeat(500), "x".repeat(500));
        let (text, under) = shown(&line, 1, 501, 6);
        assert_eq!(under, "TARGET");
        assert_eq!(text, format!("...{}TARGET{}...", "é".repeat(50), "x".repeat(50)));
        let (text, under) = shown(&line, 1, 1, 1000);
        assert_eq!(under, "é".repeat(MAX_UNDERLINE));
        assert!(text.starts_with('é') && text.ends_with("é..."), "{text}");
        // What is kept is the window, not the line.
        let kept = SourceLines::new(&line, &[(1, 501, 6)]);
        assert_eq!(kept.get(0).unwrap().text.chars().count(), 106);
    }

    #[test]
    fn control_characters_are_replaced_in_place() {
        let (text, under) = shown("\u{1b}[31m \"x\"", 1, 7, 3);
        assert_eq!(text, "\u{FFFD}[31m \"x\"");
        assert_eq!(under, "\"x\"");
        assert_eq!(shown("\tx", 1, 2, 1), ("\tx".into(), "x".into()));
    }
}
