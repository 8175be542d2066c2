//! Finding where a value is written in a RON text.
//!
//! serde forgets positions once a value is parsed, so validation errors would have no
//! line:column. This module re-reads the text with a small, forgiving RON reader that builds a
//! tree of positions only (no values) and answers two questions: where is the value at a
//! field path like `objects[3].shape.size`, and which field path contains a given position.
//! It never fails and never panics: on malformed text it returns what it could make out.

/// A 1-based line and column (counted in characters, like ron's own positions).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) struct Pos {
    /// Line, from 1.
    pub(crate) line: usize,
    /// Column in characters, from 1.
    pub(crate) column: usize,
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

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Open(char),
    Close(char),
    Comma,
    Colon,
    Ident(String),
    /// A number, string, char or any other single token that is a value by itself, with its
    /// source text.
    Atom(String),
    /// A character that means nothing to the tree (`#`, `!`, stray symbols).
    Other(char),
}

/// The positions of one value and of everything inside it.
#[derive(Debug, Default)]
pub(crate) struct Node {
    start: Pos,
    /// Position of the closing bracket for groups, of the token itself for atoms.
    end: Pos,
    /// Whether this is a list (`[...]`): only list elements get an index in `path_at`.
    list: bool,
    /// Source text of an atom or a bare name (used to name map keys); empty for groups.
    atom: String,
    /// `name: value` pairs of a struct, with the position of the name.
    fields: Vec<(String, Pos, Node)>,
    /// Elements of a list or tuple, or the payload of a named tuple like `Some(x)`.
    items: Vec<Node>,
    /// `key: value` pairs of a map.
    entries: Vec<(Node, Node)>,
}

impl Node {
    /// Reads `text` into a position tree; never fails.
    pub(crate) fn parse(text: &str) -> Node {
        let toks = tokenize(text);
        let mut p = Parser { toks: &toks, at: 0 };
        p.skip_attributes();
        p.value(0)
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
    fn child(&self, seg: Seg) -> Option<&Node> {
        let direct = match seg {
            Seg::Field(name) => self.fields.iter().find(|(n, _, _)| n == name).map(|f| &f.2),
            Seg::Item(i) => self.items.get(i),
            Seg::Entry(i) => self.entries.get(i).map(|(_, v)| v),
            Seg::Key(i) => self.entries.get(i).map(|(k, _)| k),
        };
        // `Some(x)` wraps a value without adding a step to the path.
        direct.or_else(|| match (&self.items[..], seg) {
            ([inner], Seg::Field(_) | Seg::Entry(_) | Seg::Key(_)) if self.fields.is_empty() => inner.child(seg),
            _ => None,
        })
    }

    /// The field path (as text, like `camera.fov` or `materials["leaf"].alpha`) of the
    /// innermost named or indexed value that contains `pos`; empty at the top level.
    pub(crate) fn path_at(&self, pos: Pos) -> String {
        let mut path = String::new();
        let mut node = self;
        'descend: loop {
            for (name, at, value) in &node.fields {
                if *at <= pos && pos <= value.end {
                    path.push_str(if path.is_empty() { "" } else { "." });
                    path.push_str(name);
                    node = value;
                    continue 'descend;
                }
            }
            // List elements get an index; the payload of a wrapper like `Some(x)` or
            // `Mask(x)` is no separate step; a tuple of numbers like `(0, 1, 0)` is one value.
            if node.list || node.items.len() == 1 {
                for (i, value) in node.items.iter().enumerate() {
                    if value.start <= pos && pos <= value.end {
                        if node.list {
                            path.push_str(&format!("[{i}]"));
                        }
                        node = value;
                        continue 'descend;
                    }
                }
            }
            for (key, value) in &node.entries {
                if key.start <= pos && pos <= value.end.max(key.end) {
                    path.push_str(&format!("[{}]", key.atom));
                    node = value;
                    continue 'descend;
                }
            }
            return path;
        }
    }

    /// The start of the group whose closing bracket is at `pos`, if there is one.
    pub(crate) fn opening_of(&self, pos: Pos) -> Option<Pos> {
        if self.end == pos && self.start != pos {
            return Some(self.start);
        }
        let children = self
            .fields
            .iter()
            .map(|(_, _, v)| v)
            .chain(&self.items)
            .chain(self.entries.iter().flat_map(|(k, v)| [k, v]));
        for child in children {
            if child.start <= pos && pos <= child.end {
                return child.opening_of(pos);
            }
        }
        None
    }
}

struct Parser<'t> {
    toks: &'t [(Tok, Pos, usize)],
    at: usize,
}

impl Parser<'_> {
    fn peek(&self, ahead: usize) -> Option<&Tok> {
        self.toks.get(self.at + ahead).map(|(t, _, _)| t)
    }

    fn pos(&self) -> Pos {
        self.toks
            .get(self.at)
            .or(self.toks.last())
            .map(|(_, p, _)| *p)
            .unwrap_or(Pos { line: 1, column: 1 })
    }

    fn bump(&mut self) -> Option<&Tok> {
        let tok = self.toks.get(self.at).map(|(t, _, _)| t);
        self.at += 1;
        tok
    }

    /// Skips `#![enable(...)]` attributes before the top-level value.
    fn skip_attributes(&mut self) {
        while self.peek(0) == Some(&Tok::Other('#')) {
            self.at += 1;
            if self.peek(0) == Some(&Tok::Other('!')) {
                self.at += 1;
            }
            if matches!(self.peek(0), Some(Tok::Open(_))) {
                self.skip_group();
            }
        }
    }

    /// Skips a balanced group without recursion (used past `MAX_DEPTH`).
    fn skip_group(&mut self) {
        let mut depth = 0usize;
        while let Some(tok) = self.bump() {
            match tok {
                Tok::Open(_) => depth += 1,
                Tok::Close(_) => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        return;
                    }
                }
                _ if depth == 0 => return,
                _ => {}
            }
        }
    }

    fn value(&mut self, depth: usize) -> Node {
        let start = self.pos();
        let leaf = |end| Node {
            start,
            end,
            ..Node::default()
        };
        match self.peek(0).cloned() {
            None => leaf(start),
            Some(Tok::Ident(name)) => {
                self.at += 1;
                if matches!(self.peek(0), Some(Tok::Open('('))) {
                    let mut node = self.group(depth);
                    node.start = start;
                    node
                } else {
                    Node {
                        atom: name,
                        ..leaf(start)
                    }
                }
            }
            Some(Tok::Open(_)) => self.group(depth),
            // A stray closing bracket, comma or colon is left for the enclosing group.
            Some(Tok::Close(_) | Tok::Comma | Tok::Colon) => leaf(start),
            Some(Tok::Atom(text)) => {
                self.at += 1;
                Node {
                    atom: text,
                    ..leaf(start)
                }
            }
            Some(Tok::Other(_)) => {
                self.at += 1;
                leaf(start)
            }
        }
    }

    /// Reads a bracketed group; the current token is its opening bracket.
    fn group(&mut self, depth: usize) -> Node {
        let start = self.pos();
        if depth >= MAX_DEPTH {
            self.skip_group();
            return Node {
                start,
                end: start,
                ..Node::default()
            };
        }
        let open = match self.bump() {
            Some(Tok::Open(c)) => *c,
            _ => {
                return Node {
                    start,
                    end: start,
                    ..Node::default()
                };
            }
        };
        let mut node = Node {
            start,
            ..Node::default()
        };
        loop {
            match self.peek(0).cloned() {
                None => {
                    node.end = self.pos();
                    break;
                }
                Some(Tok::Close(_)) => {
                    node.end = self.pos();
                    self.at += 1;
                    break;
                }
                Some(Tok::Comma | Tok::Colon) => self.at += 1,
                Some(Tok::Ident(name)) if open == '(' && self.peek(1) == Some(&Tok::Colon) => {
                    let at = self.pos();
                    self.at += 2;
                    let value = self.value(depth + 1);
                    node.fields.push((name, at, value));
                }
                Some(_) if open == '{' => {
                    let before = self.at;
                    let key = self.value(depth + 1);
                    let value = if self.peek(0) == Some(&Tok::Colon) {
                        self.at += 1;
                        self.value(depth + 1)
                    } else {
                        Node {
                            start: key.end,
                            end: key.end,
                            ..Node::default()
                        }
                    };
                    node.entries.push((key, value));
                    self.ensure_progress(before);
                }
                Some(_) => {
                    let before = self.at;
                    let item = self.value(depth + 1);
                    node.items.push(item);
                    self.ensure_progress(before);
                }
            }
        }
        node.list = open == '[';
        node
    }

    fn ensure_progress(&mut self, before: usize) {
        if self.at == before {
            self.at += 1;
        }
    }
}

/// Splits RON text into the tokens the tree needs, skipping whitespace and comments.
/// Each token comes with its start and its length in characters.
fn tokenize(text: &str) -> Vec<(Tok, Pos, usize)> {
    let chars: Vec<char> = text.chars().collect();
    let mut toks = Vec::new();
    let mut i = 0;
    let (mut line, mut col) = (1usize, 1usize);
    // Advances over `n` chars, keeping line and column up to date.
    let advance = |i: &mut usize, line: &mut usize, col: &mut usize, n: usize| {
        for _ in 0..n {
            if chars.get(*i) == Some(&'\n') {
                *line += 1;
                *col = 1;
            } else {
                *col += 1;
            }
            *i += 1;
        }
    };
    let at = |k: usize| chars.get(k).copied().unwrap_or('\0');
    while i < chars.len() {
        let c = chars[i];
        let pos = Pos { line, column: col };
        let len = if c.is_whitespace() {
            1
        } else if c == '/' && at(i + 1) == '/' {
            (i..chars.len()).find(|&k| chars[k] == '\n').unwrap_or(chars.len()) - i
        } else if c == '/' && at(i + 1) == '*' {
            block_comment_len(&chars[i..])
        } else {
            let (tok, len) = token(&chars[i..]);
            toks.push((tok, pos, len));
            len
        };
        advance(&mut i, &mut line, &mut col, len.max(1));
    }
    toks
}

/// Length of a (nestable) block comment starting at `s[0..2] == "/*"`.
fn block_comment_len(s: &[char]) -> usize {
    let mut depth = 0usize;
    let mut k = 0;
    while k < s.len() {
        match (s[k], s.get(k + 1)) {
            ('/', Some('*')) => {
                depth += 1;
                k += 2;
            }
            ('*', Some('/')) => {
                depth = depth.saturating_sub(1);
                k += 2;
                if depth == 0 {
                    return k;
                }
            }
            _ => k += 1,
        }
    }
    s.len()
}

/// The token at the start of `s` (not whitespace or a comment) and its length in chars.
fn token(s: &[char]) -> (Tok, usize) {
    let c = s[0];
    let at = |k: usize| s.get(k).copied().unwrap_or('\0');
    let ident_len = |from: usize| {
        from + s[from..]
            .iter()
            .take_while(|c| c.is_alphanumeric() || **c == '_')
            .count()
    };
    match c {
        '(' | '[' | '{' => (Tok::Open(c), 1),
        ')' | ']' | '}' => (Tok::Close(c), 1),
        ',' => (Tok::Comma, 1),
        ':' => (Tok::Colon, 1),
        '"' => atom(s, quoted_len(s, '"')),
        '\'' => atom(s, quoted_len(s, '\'')),
        'b' if at(1) == '"' || at(1) == '\'' => atom(s, 1 + quoted_len(&s[1..], at(1))),
        'b' if at(1) == 'r' && matches!(at(2), '"' | '#') => atom(s, 1 + raw_string_len(&s[1..])),
        'r' if at(1) == '"' || (at(1) == '#' && matches!(at(2), '"' | '#')) => atom(s, raw_string_len(s)),
        'r' if at(1) == '#' && (at(2).is_alphabetic() || at(2) == '_') => {
            let end = ident_len(2);
            (Tok::Ident(s[2..end].iter().collect()), end)
        }
        _ if c.is_alphabetic() || c == '_' => {
            let end = ident_len(0);
            (Tok::Ident(s[..end].iter().collect()), end)
        }
        _ if c.is_ascii_digit() || matches!(c, '+' | '-' | '.') => {
            let mut k = 1;
            while k < s.len() {
                let d = s[k];
                let exponent_sign = matches!(d, '+' | '-') && matches!(s[k - 1], 'e' | 'E') && !is_hex(s);
                if d.is_alphanumeric() || d == '_' || (d == '.' && at(k + 1) != '.') || exponent_sign {
                    k += 1;
                } else {
                    break;
                }
            }
            atom(s, k)
        }
        _ => (Tok::Other(c), 1),
    }
}

fn atom(s: &[char], len: usize) -> (Tok, usize) {
    let len = len.min(s.len());
    (Tok::Atom(s[..len].iter().collect()), len)
}

fn is_hex(s: &[char]) -> bool {
    let digits = if matches!(s.first(), Some('+' | '-')) {
        &s[1..]
    } else {
        s
    };
    matches!(digits, ['0', 'x' | 'X', ..])
}

/// Length of a string or char literal opened by `quote` at `s[0]`, escapes included.
fn quoted_len(s: &[char], quote: char) -> usize {
    let mut k = 1;
    while k < s.len() {
        match s[k] {
            '\\' => k += 2,
            c if c == quote => return k + 1,
            _ => k += 1,
        }
    }
    s.len()
}

/// Length of a raw string `r#"..."#` starting at `s[0] == 'r'`.
fn raw_string_len(s: &[char]) -> usize {
    let hashes = s[1..].iter().take_while(|c| **c == '#').count();
    let mut k = 1 + hashes + 1;
    while k < s.len() {
        if s[k] == '"' && s[k + 1..].iter().take(hashes).filter(|c| **c == '#').count() == hashes {
            return k + 1 + hashes;
        }
        k += 1;
    }
    s.len()
}

/// The token that contains `pos`, or else the first one after it: its start and its source
/// text, shortened to 40 characters. `None` at the end of the text.
pub(crate) fn token_at(text: &str, pos: Pos) -> Option<(Pos, String)> {
    let toks = tokenize(text);
    let containing = toks
        .iter()
        .rposition(|(_, at, len)| *at <= pos && at.line == pos.line && pos.column < at.column + len);
    let index = containing.or_else(|| toks.iter().position(|(_, at, _)| *at >= pos))?;
    let (tok, start, _) = toks.into_iter().nth(index)?;
    let full = match tok {
        Tok::Open(c) | Tok::Close(c) | Tok::Other(c) => c.to_string(),
        Tok::Comma => ",".to_owned(),
        Tok::Colon => ":".to_owned(),
        Tok::Ident(s) | Tok::Atom(s) => s,
    };
    let shown = match full.char_indices().nth(40) {
        Some((cut, _)) => format!("{}...", &full[..cut]),
        None => full,
    };
    Some((start, shown))
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
    fn token_at_finds_the_containing_or_next_token() {
        let text = "(a: -12,\n   b: \"x\")";
        assert_eq!(token_at(text, at(1, 6)), Some((at(1, 5), "-12".to_owned())));
        assert_eq!(token_at(text, at(1, 9)), Some((at(2, 4), "b".to_owned())));
        assert_eq!(token_at(text, at(2, 20)), None);
    }

    #[test]
    fn malformed_text_gives_a_tree_anyway() {
        for text in ["", "(", ")", "(a: ", "{ : , ]", "r#\"", "/* (", "\"", "(a: (b: [)", "'"] {
            let tree = Node::parse(text);
            let _ = tree.find(&[Seg::Field("a"), Seg::Item(3), Seg::Entry(1)]);
            let _ = tree.path_at(at(1, 3));
            let _ = token_at(text, at(1, 2));
        }
        let deep = "[".repeat(10_000);
        assert_eq!(Node::parse(&deep).find(&[Seg::Item(0)]), at(1, 2));
    }
}
