//! Where a glTF JSON path like `meshes[0].primitives[0].indices` is written in the file's
//! text, to show the line of a validation error, and serde_json's byte columns as character
//! columns.
//!
//! The scanner reads text that serde_json has already accepted. It follows the path's steps
//! and skips every value off the path without reading it, so one look-up costs at most one
//! pass over the text, no memory and no recursion; on text it cannot follow it gives up
//! (`None`) rather than fail.

use std::ops::Range;

use crate::diagnostic::SourceLines;
use crate::scene::MAX_LISTED_PROBLEMS;

/// Path look-ups for one error (each at most one pass over the JSON text), counted in bytes
/// of text: a few hundred milliseconds at most.
const SCAN_BUDGET: usize = 256 << 20;

/// One step of a path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Step<'p> {
    /// An object member: `.indices` or `["POSITION"]`.
    Member(&'p str),
    /// An array element: `[3]`.
    Index(usize),
}

/// Where a path's value is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct JsonSpot {
    /// Line, from 1.
    pub line: usize,
    /// Column in characters, from 1.
    pub column: usize,
    /// Characters of the value on its line (1 for a value that spans lines, or for a
    /// container found in place of a missing member).
    pub len: usize,
}

/// The value at `path` in `text`, or the deepest value on the path that is written (the
/// object that lacks a missing property); `None` when the path is not in the `gltf` crate's
/// form or the text cannot be followed.
pub(super) fn locate(text: &str, path: &str) -> Option<JsonSpot> {
    let steps = steps(path)?;
    let (range, complete) = find(text.as_bytes(), &steps)?;
    let before = text.get(..range.start)?;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let line = before.bytes().filter(|&b| b == b'\n').count() + 1;
    let column = before[line_start..].chars().count() + 1;
    let value = text.get(range)?;
    let len = match complete && !value.contains('\n') {
        true => value.chars().count().max(1),
        false => 1,
    };
    Some(JsonSpot { line, column, len })
}

/// The lines of the paths of the problems a message lists, while the scan budget lasts.
pub(super) fn path_lines(text: &str, problems: &[(String, String)]) -> SourceLines {
    let scans = SCAN_BUDGET / text.len().max(1);
    let places: Vec<(usize, usize, usize)> = (problems.iter().take(MAX_LISTED_PROBLEMS.min(scans)))
        .map(|(path, _)| locate(text, path).map_or((0, 0, 0), |s| (s.line, s.column, s.len)))
        .collect();
    SourceLines::new(text, &places)
}

/// The character column of serde_json's `column` (bytes from 1, 0 at a line's start) on line
/// `line` (from 1) of `text`; `column` itself when the text has no such line.
pub(super) fn char_column(text: &str, line: usize, column: usize) -> usize {
    let Some(row) = line.checked_sub(1).and_then(|i| text.split('\n').nth(i)) else {
        return column.max(1);
    };
    let mut end = column.saturating_sub(1).min(row.len());
    while !row.is_char_boundary(end) {
        end -= 1;
    }
    row[..end].chars().count() + 1
}

/// The steps of a path as the `gltf` crate writes them: names joined by `.`, `[3]`,
/// `["KEY"]`, and perhaps a trailing ` = "value"`.
fn steps(path: &str) -> Option<Vec<Step<'_>>> {
    let mut rest = path.split_once(" = ").map_or(path, |(p, _)| p);
    let mut out = Vec::new();
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix("[\"") {
            let end = r.find("\"]")?;
            out.push(Step::Member(&r[..end]));
            rest = &r[end + 2..];
        } else if let Some(r) = rest.strip_prefix('[') {
            let end = r.find(']')?;
            out.push(Step::Index(r[..end].parse().ok()?));
            rest = &r[end + 1..];
        } else {
            let r = rest.strip_prefix('.').unwrap_or(rest);
            let end = r.find(['.', '[']).unwrap_or(r.len());
            if end == 0 {
                return None;
            }
            out.push(Step::Member(&r[..end]));
            rest = &r[end..];
        }
    }
    Some(out)
}

/// The byte range of the value at `steps`, and whether every step was found (else the range
/// is the deepest value on the path).
fn find(b: &[u8], steps: &[Step]) -> Option<(Range<usize>, bool)> {
    let mut at = blank_end(b, 0);
    for step in steps {
        let child = match *step {
            Step::Member(name) => member(b, at, name),
            Step::Index(n) => element(b, at, n),
        };
        match child {
            Some(child) => at = child,
            None => return Some((at..value_end(b, at)?, false)),
        }
    }
    Some((at..value_end(b, at)?, true))
}

/// The start of the value of member `name` of the object at `at`.
fn member(b: &[u8], at: usize, name: &str) -> Option<usize> {
    if *b.get(at)? != b'{' {
        return None;
    }
    let mut k = blank_end(b, at + 1);
    loop {
        if *b.get(k)? != b'"' {
            return None;
        }
        let key_end = string_end(b, k)?;
        let key = b.get(k + 1..key_end - 1)?;
        k = blank_end(b, key_end);
        if *b.get(k)? != b':' {
            return None;
        }
        let value = blank_end(b, k + 1);
        if key == name.as_bytes() {
            return Some(value);
        }
        k = blank_end(b, value_end(b, value)?);
        if *b.get(k)? != b',' {
            return None;
        }
        k = blank_end(b, k + 1);
    }
}

/// The start of element `n` of the array at `at`.
fn element(b: &[u8], at: usize, n: usize) -> Option<usize> {
    if *b.get(at)? != b'[' {
        return None;
    }
    let mut k = blank_end(b, at + 1);
    if *b.get(k)? == b']' {
        return None;
    }
    for _ in 0..n {
        k = blank_end(b, value_end(b, k)?);
        if *b.get(k)? != b',' {
            return None;
        }
        k = blank_end(b, k + 1);
    }
    Some(k)
}

/// The end of the JSON whitespace from `at`.
fn blank_end(b: &[u8], mut at: usize) -> usize {
    while b.get(at).is_some_and(|c| matches!(c, b' ' | b'\t' | b'\n' | b'\r')) {
        at += 1;
    }
    at
}

/// The end (after the closing quote) of the string starting at `at`.
fn string_end(b: &[u8], at: usize) -> Option<usize> {
    let mut k = at + 1;
    loop {
        match *b.get(k)? {
            b'"' => return Some(k + 1),
            b'\\' => k += 2,
            _ => k += 1,
        }
    }
}

/// The end of the value starting at `at`.
fn value_end(b: &[u8], at: usize) -> Option<usize> {
    match *b.get(at)? {
        b'"' => string_end(b, at),
        b'{' | b'[' => {
            let mut depth = 0usize;
            let mut k = at;
            loop {
                match *b.get(k)? {
                    b'"' => {
                        k = string_end(b, k)?;
                        continue;
                    }
                    b'{' | b'[' => depth += 1,
                    b'}' | b']' => {
                        depth = depth.checked_sub(1)?;
                        if depth == 0 {
                            return Some(k + 1);
                        }
                    }
                    _ => {}
                }
                k += 1;
            }
        }
        _ => {
            let mut k = at;
            while b
                .get(k)
                .is_some_and(|c| !matches!(c, b',' | b'}' | b']' | b' ' | b'\t' | b'\n' | b'\r'))
            {
                k += 1;
            }
            (k > at).then_some(k)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = r#"{
  "asset": {"version": "2.0"},
  "meshes": [
    {"name": "a \"quoted\" [name]", "primitives": []},
    {"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 7}]}
  ],
  "nodes": [{"mesh": 1, "name": "é"}, {"children": [0]}]
}"#;

    fn spot(line: usize, column: usize, len: usize) -> Option<JsonSpot> {
        Some(JsonSpot { line, column, len })
    }

    #[test]
    fn paths_split_into_steps() {
        use Step::{Index, Member};
        let s = steps("meshes[1].primitives[0].attributes[\"POSITION\"]").unwrap();
        assert_eq!(
            s,
            [
                Member("meshes"),
                Index(1),
                Member("primitives"),
                Index(0),
                Member("attributes"),
                Member("POSITION")
            ]
        );
        assert_eq!(
            steps("extensionsRequired[0] = \"KHR_x\"").unwrap(),
            [Member("extensionsRequired"), Index(0)]
        );
        assert_eq!(steps("a..b"), None);
        assert_eq!(steps("a[x]"), None);
        assert_eq!(steps("a[\"k"), None);
    }

    #[test]
    fn values_on_the_path_are_found_past_strings_and_siblings() {
        assert_eq!(locate(TEXT, "meshes[1].primitives[0].indices"), spot(5, 77, 1));
        assert_eq!(
            locate(TEXT, "meshes[1].primitives[0].attributes[\"NORMAL\"]"),
            spot(5, 62, 1)
        );
        assert_eq!(locate(TEXT, "asset.version"), spot(2, 24, 5));
        assert_eq!(locate(TEXT, "nodes[1].children"), spot(7, 52, 3));
        // The whole object when it fits on its line.
        assert_eq!(locate(TEXT, "asset"), spot(2, 12, 18));
        // A missing member points at the object that should hold it.
        assert_eq!(locate(TEXT, "meshes[0].mesh"), spot(4, 5, 1));
        assert_eq!(locate(TEXT, "nodes[5]"), spot(7, 12, 1));
        assert_eq!(locate(TEXT, "scenes"), spot(1, 1, 1));
    }

    #[test]
    fn damaged_text_gives_up_without_failing() {
        for text in ["", "{", "{\"a\"", "{\"a\": [1,", "[\"\\", "{\"a\": }", "{\"é\": 1"] {
            for path in ["a", "a[3]", "a.b", "a[\"k\"]"] {
                let _ = locate(text, path);
            }
        }
        assert_eq!(locate("{\"a\": [1", "a[1]"), None);
        // What can be followed is found, even in damaged text.
        assert_eq!(locate("{\"a\": [1, 2", "a[1]"), spot(1, 11, 1));
    }

    #[test]
    fn byte_columns_become_character_columns() {
        let text = "{\n  \"é\": x\n}";
        // serde_json reports the `x` at byte column 9 of line 2; it is the 8th character.
        assert_eq!(char_column(text, 2, 9), 8);
        assert_eq!(char_column(text, 2, 0), 1);
        assert_eq!(char_column(text, 2, 100), 9);
        assert_eq!(char_column(text, 9, 4), 4);
        // Inside a multi-byte character: the character's own column.
        assert_eq!(char_column(text, 2, 5), 4);
    }
}
