//! Finding where a value is written in a RON text.
//!
//! serde forgets positions once a value is parsed, so validation errors would have no
//! line:column. This module re-reads the text with a small, forgiving RON reader that builds a
//! tree of positions only (no values) and answers two questions: where is the value at a
//! field path like `objects[3].shape.size`, and which field path contains a given position.
//! It never fails and never panics: on malformed text it returns what it could make out.
//!
//! Budgets: the tokenizer is lazy and borrows its text, stray characters make no tree nodes,
//! and locating a parse error reads only the text up to the error and keeps only the groups
//! that contain it, so a damaged file of any size costs memory in proportion to its nesting
//! depth, and time linear in the text before the error. A whole-file tree (for validation,
//! where the file parsed) costs a bounded number of bytes per value written.

mod lexer;
mod parser;

use crate::scene::locate::lexer::{Lexer, Tok};
use crate::scene::locate::parser::Parser;

/// A 1-based line and column (counted in characters, like ron's own positions).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) struct Pos {
    /// Line, from 1.
    pub(crate) line: usize,
    /// Column in characters, from 1.
    pub(crate) column: usize,
}

impl Pos {
    /// After every position in any text: the end of a group left open where reading stopped.
    const MAX: Pos = Pos {
        line: usize::MAX,
        column: usize::MAX,
    };
}

/// One step of a field path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Seg {
    /// A named struct field: `camera` in `camera.fov`.
    Field(&'static str),
    /// The n-th element of a list or tuple (also the payload of `Mask(0.5)`).
    Item(usize),
    /// The value of the n-th entry of a map.
    Entry(usize),
    /// The key of the n-th entry of a map.
    Key(usize),
}

/// Nesting deeper than this is skipped rather than followed (ron itself stops at 128).
const MAX_DEPTH: usize = 256;

/// The positions of one value and of everything inside it.
#[derive(Debug, Default)]
pub(crate) struct Node<'t> {
    start: Pos,
    /// Position of the closing bracket for groups, of the token itself for atoms.
    end: Pos,
    /// Source text of an atom or a bare name (used to name map keys); empty for groups.
    atom: &'t str,
    /// What a bracketed group holds; `None` for atoms and names.
    group: Option<Box<Group<'t>>>,
}

/// The contents of a bracketed group.
#[derive(Debug, Default)]
struct Group<'t> {
    /// Whether this is a list (`[...]`): only list elements get an index in `path_at`.
    list: bool,
    /// `name: value` pairs of a struct, with the position of the name.
    fields: Vec<(&'t str, Pos, Node<'t>)>,
    /// Elements of a list or tuple, or the payload of a named tuple like `Some(x)`, with their
    /// index (increasing; elements before a position of interest may be left out).
    items: Vec<(usize, Node<'t>)>,
    /// How many elements (or map entries) there are, including any left out.
    item_count: usize,
    /// `key: value` pairs of a map, with their index (as for `items`).
    entries: Vec<(usize, Node<'t>, Node<'t>)>,
}

impl<'t> Group<'t> {
    fn item(&self, i: usize) -> Option<&Node<'t>> {
        let k = self.items.binary_search_by_key(&i, |(n, _)| *n).ok()?;
        Some(&self.items[k].1)
    }

    fn entry(&self, i: usize) -> Option<(&Node<'t>, &Node<'t>)> {
        let k = self.entries.binary_search_by_key(&i, |(n, _, _)| *n).ok()?;
        Some((&self.entries[k].1, &self.entries[k].2))
    }

    /// The payload of a wrapper like `Some(x)`: a group of exactly one element.
    fn wrapped(&self) -> Option<&Node<'t>> {
        match (&self.items[..], self.item_count) {
            ([(_, inner)], 1) if self.fields.is_empty() => Some(inner),
            _ => None,
        }
    }
}

impl<'t> Node<'t> {
    /// Reads all of `text` into a position tree; never fails.
    pub(crate) fn parse(text: &'t str) -> Node<'t> {
        Parser::new(Lexer::new(text), None).top()
    }

    /// Reads `text` up to `pos` into a tree that holds only the groups that reach `pos`
    /// (enough for [`path_at`](Self::path_at) and [`opening_of`](Self::opening_of) at `pos`).
    pub(crate) fn parse_until(text: &'t str, pos: Pos) -> Node<'t> {
        Parser::new(Lexer::until(text, pos), Some(pos)).top()
    }

    /// Position of the value at `path`, or of the deepest part of it that is written in the
    /// text (a field left at its default points at the struct that would hold it).
    pub(crate) fn find(&self, path: &[Seg]) -> Pos {
        let mut node = self;
        for seg in path {
            match node.child(*seg) {
                Some(child) => node = child,
                None => break,
            }
        }
        node.start
    }

    /// The child at one step of a path.
    fn child(&self, seg: Seg) -> Option<&Node<'t>> {
        let group = self.group.as_deref()?;
        let direct = match seg {
            Seg::Field(name) => group.fields.iter().find(|(n, _, _)| *n == name).map(|f| &f.2),
            Seg::Item(i) => group.item(i),
            Seg::Entry(i) => group.entry(i).map(|(_, v)| v),
            Seg::Key(i) => group.entry(i).map(|(k, _)| k),
        };
        // `Some(x)` wraps a value without adding a step to the path.
        direct.or_else(|| match seg {
            Seg::Field(_) | Seg::Entry(_) | Seg::Key(_) => group.wrapped()?.child(seg),
            Seg::Item(_) => None,
        })
    }

    /// The field path (as text, like `camera.fov` or `materials["leaf"].alpha`) of the
    /// innermost named or indexed value that contains `pos`; empty at the top level.
    pub(crate) fn path_at(&self, pos: Pos) -> String {
        let mut path = String::new();
        let mut node = self;
        'descend: while let Some(group) = node.group.as_deref() {
            for (name, at, value) in &group.fields {
                if *at <= pos && pos <= value.end {
                    path.push_str(if path.is_empty() { "" } else { "." });
                    path.push_str(name);
                    node = value;
                    continue 'descend;
                }
            }
            // List elements get an index; the payload of a wrapper like `Some(x)` or
            // `Mask(x)` is no separate step; a tuple of numbers like `(0, 1, 0)` is one value.
            if group.list || group.item_count == 1 {
                for (i, value) in &group.items {
                    if value.start <= pos && pos <= value.end {
                        if group.list {
                            path.push_str(&format!("[{i}]"));
                        }
                        node = value;
                        continue 'descend;
                    }
                }
            }
            for (_, key, value) in &group.entries {
                if key.start <= pos && pos <= value.end.max(key.end) {
                    path.push_str(&format!("[{}]", key.atom));
                    node = value;
                    continue 'descend;
                }
            }
            break;
        }
        path
    }

    /// The start of the group whose closing bracket is at `pos`, if there is one.
    pub(crate) fn opening_of(&self, pos: Pos) -> Option<Pos> {
        if self.end == pos && self.start != pos {
            return Some(self.start);
        }
        let group = self.group.as_deref()?;
        let children = (group.fields.iter().map(|(_, _, v)| v))
            .chain(group.items.iter().map(|(_, v)| v))
            .chain(group.entries.iter().flat_map(|(_, k, v)| [k, v]));
        for child in children {
            if child.start <= pos && pos <= child.end {
                return child.opening_of(pos);
            }
        }
        None
    }
}

/// The longest token text shown in a message, in characters.
const SHOWN_CHARS: usize = 40;

/// The token that contains `pos`, or else the first one after it: its start and its source
/// text, shortened to 40 characters. `None` at the end of the text. Reads the text only up
/// to that token.
pub(crate) fn token_at(text: &str, pos: Pos) -> Option<(Pos, String)> {
    let token = Lexer::new(text).find(|t| t.end > pos)?;
    let full = token.tok.text();
    let shown = match full.char_indices().nth(SHOWN_CHARS) {
        Some((cut, _)) => format!("{}...", &full[..cut]),
        None => full.to_owned(),
    };
    Some((token.start, shown))
}

/// The most characters underlined under one error.
const MAX_UNDERLINE: usize = 80;

/// How many characters to underline at each of `positions` (in file order): the token that
/// starts there, or with `whole_values`, a bracketed value up to its closing bracket when that
/// is on the same line and near; 1 where no token starts (the end of the text), at most 80.
/// Reads the text once, up to the last position.
pub(crate) fn underline_lengths(text: &str, positions: &[Pos], whole_values: bool) -> Vec<usize> {
    let mut lexer = Lexer::new(text);
    let mut current = lexer.next();
    let mut lengths = Vec::with_capacity(positions.len());
    for &pos in positions {
        while current.is_some_and(|t| t.end <= pos) {
            current = lexer.next();
        }
        let Some(token) = current.filter(|t| t.start == pos) else {
            lengths.push(1);
            continue;
        };
        let mut end = token.end;
        if whole_values && matches!(token.tok, Tok::Open(_)) {
            let mut depth = 1usize;
            for t in lexer.clone() {
                if t.start.line != pos.line || t.start.column > pos.column + MAX_UNDERLINE {
                    break;
                }
                match t.tok {
                    Tok::Open(_) => depth += 1,
                    Tok::Close(_) => depth -= 1,
                    _ => {}
                }
                if depth == 0 {
                    end = t.end;
                    break;
                }
            }
        }
        // A token that runs onto the next line (a string) is underlined to the end of its line.
        let len = match end.line == pos.line {
            true => end.column.saturating_sub(pos.column),
            false => MAX_UNDERLINE,
        };
        lengths.push(len.clamp(1, MAX_UNDERLINE));
    }
    lengths
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(line: usize, column: usize) -> Pos {
        Pos { line, column }
    }

    #[test]
    fn finds_values_past_comments_strings_and_names() {
        let text = r##"#![enable(implicit_some)]
/* a (block /* nested */ comment) */ Scene(
    // a comment with ( and [
    name: "a string with ) and ] and \" quote",
    raw: r#"raw ) string"#, big: Some((count: (1, 2, 3))),
    list: [1, (x: 2), Mask(0.5)], map: { "k": (v: 'c'), "j": [] },
)"##;
        let tree = Node::parse(text);
        let find = |path: &[Seg]| tree.find(path);
        assert_eq!(find(&[Seg::Field("name")]), at(4, 11));
        assert_eq!(find(&[Seg::Field("raw")]), at(5, 10));
        // `Some(...)` is looked through.
        assert_eq!(find(&[Seg::Field("big"), Seg::Field("count")]), at(5, 47));
        assert_eq!(find(&[Seg::Field("list"), Seg::Item(1), Seg::Field("x")]), at(6, 19));
        assert_eq!(find(&[Seg::Field("list"), Seg::Item(2), Seg::Item(0)]), at(6, 28));
        assert_eq!(find(&[Seg::Field("map"), Seg::Key(1)]), at(6, 57));
        assert_eq!(find(&[Seg::Field("map"), Seg::Entry(0), Seg::Field("v")]), at(6, 51));
        // A missing field points at the deepest part that exists.
        assert_eq!(find(&[Seg::Field("map"), Seg::Entry(5)]), at(6, 40));
        assert_eq!(find(&[Seg::Field("nothing")]), at(2, 38));
    }

    #[test]
    fn names_the_path_at_a_position() {
        let text = "(a: (b: [1, (c: 2)]), m: {\"k\": Mask(3)}, v: (1, 2, 3))";
        let tree = Node::parse(text);
        assert_eq!(tree.path_at(at(1, 17)), "a.b[1].c");
        assert_eq!(tree.path_at(at(1, 10)), "a.b[0]");
        assert_eq!(tree.path_at(at(1, 37)), "m[\"k\"]");
        assert_eq!(tree.path_at(at(1, 50)), "v");
        assert_eq!(tree.path_at(at(1, 1)), "");
        assert_eq!(tree.opening_of(at(1, 19)), Some(at(1, 9)));
    }

    #[test]
    fn a_tree_read_up_to_a_position_keeps_only_what_reaches_it() {
        let text = "(a: [1, 2, (c: 3), 4], m: {\"k\": 1, \"j\": (x: 2)}, z: 9)";
        for (pos, path) in [(at(1, 16), "a[2].c"), (at(1, 45), "m[\"j\"].x"), (at(1, 20), "a[3]")] {
            let partial = Node::parse_until(text, pos);
            assert_eq!(partial.path_at(pos), path);
            assert_eq!(Node::parse(text).path_at(pos), path);
        }
        // Nothing before the position is kept.
        let partial = Node::parse_until(text, at(1, 45));
        let root = partial.group.as_deref().unwrap();
        assert_eq!(root.fields.len(), 1);
        assert_eq!(partial.opening_of(at(1, 21)), None);
        assert_eq!(Node::parse_until(text, at(1, 21)).opening_of(at(1, 21)), Some(at(1, 5)));
        // Stray characters make no nodes.
        let junk = format!("[{}]", "# ".repeat(1000));
        assert_eq!(Node::parse(&junk).group.as_deref().map_or(0, |g| g.items.len()), 0);
    }

    #[test]
    fn token_at_finds_the_containing_or_next_token() {
        let text = "(a: -12,\n   b: \"x\")";
        assert_eq!(token_at(text, at(1, 6)), Some((at(1, 5), "-12".to_owned())));
        assert_eq!(token_at(text, at(1, 9)), Some((at(2, 4), "b".to_owned())));
        assert_eq!(token_at(text, at(2, 20)), None);
        let long = format!("\"{}\"", "x".repeat(100));
        assert_eq!(token_at(&long, at(1, 1)).unwrap().1, format!("\"{}...", "x".repeat(39)));
    }

    #[test]
    fn underlines_tokens_or_whole_values() {
        let text = "(a: -12, b: (1, (2)),\n c: \"é\", d: [\n 1])";
        let at_all = [at(1, 5), at(1, 13), at(2, 5), at(2, 13), at(3, 9), at(1, 1)];
        assert_eq!(underline_lengths(text, &at_all[..5], false), [3, 1, 3, 1, 1]);
        // `(1, (2))` is one value; the list `[` closes on the next line.
        assert_eq!(underline_lengths(text, &at_all[..5], true), [3, 8, 3, 1, 1]);
        // Out of order: what cannot be found again is one character.
        assert_eq!(underline_lengths(text, &at_all[4..], true), [1, 1]);
        let raw = "(a: \"two\nlines\")";
        assert_eq!(underline_lengths(raw, &[at(1, 5)], false), [MAX_UNDERLINE]);
        assert_eq!(underline_lengths("", &[at(1, 1)], true), [1]);
    }

    #[test]
    fn malformed_text_gives_a_tree_anyway() {
        for text in [
            "",
            "(",
            ")",
            "(a: ",
            "{ : , ]",
            "r#\"",
            "/* (",
            "\"",
            "(a: (b: [)",
            "'",
            "é\u{0}",
        ] {
            let tree = Node::parse(text);
            let _ = tree.find(&[Seg::Field("a"), Seg::Item(3), Seg::Entry(1)]);
            let _ = tree.path_at(at(1, 3));
            let _ = Node::parse_until(text, at(1, 2)).path_at(at(1, 2));
            let _ = token_at(text, at(1, 2));
        }
        let deep = "[".repeat(10_000);
        assert_eq!(Node::parse(&deep).find(&[Seg::Item(0)]), at(1, 2));
    }
}
