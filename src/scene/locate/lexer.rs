//! A lazy RON tokenizer for the locator: it walks the text once, byte by byte, and hands out
//! tokens that borrow their text, so reading a file costs a few words of memory however
//! long it is, and time linear in its length (every scan below looks at each byte a bounded
//! number of times).

use crate::scene::locate::Pos;

/// One token of RON text.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Tok<'t> {
    /// `(`, `[` or `{`.
    Open(u8),
    /// `)`, `]` or `}`.
    Close(u8),
    /// `,`.
    Comma,
    /// `:`.
    Colon,
    /// A bare name (`r#` prefix removed).
    Ident(&'t str),
    /// A number, string, char or other literal that is a value by itself, with its source text.
    Atom(&'t str),
    /// A character that means nothing to the tree (`#`, `!`, stray symbols).
    Other(&'t str),
}

impl<'t> Tok<'t> {
    /// The token's source text.
    pub(super) fn text(&self) -> &'t str {
        match *self {
            Tok::Open(b'(') => "(",
            Tok::Open(b'[') => "[",
            Tok::Open(_) => "{",
            Tok::Close(b')') => ")",
            Tok::Close(b']') => "]",
            Tok::Close(_) => "}",
            Tok::Comma => ",",
            Tok::Colon => ":",
            Tok::Ident(s) | Tok::Atom(s) | Tok::Other(s) => s,
        }
    }
}

/// A token with where it starts and where the text after it starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Token<'t> {
    pub(super) tok: Tok<'t>,
    pub(super) start: Pos,
    pub(super) end: Pos,
}

/// The tokens of a text, skipping whitespace and comments; optionally only those that start
/// at or before a limit.
#[derive(Clone)]
pub(super) struct Lexer<'t> {
    text: &'t str,
    /// Byte offset of the next unread byte.
    at: usize,
    pos: Pos,
    limit: Option<Pos>,
    /// Whether tokens were left unread because of the limit.
    cut: bool,
}

impl<'t> Lexer<'t> {
    /// Every token of `text`.
    pub(super) fn new(text: &'t str) -> Self {
        Lexer {
            text,
            at: 0,
            pos: Pos { line: 1, column: 1 },
            limit: None,
            cut: false,
        }
    }

    /// The tokens of `text` that start at or before `limit`.
    pub(super) fn until(text: &'t str, limit: Pos) -> Self {
        Lexer {
            limit: Some(limit),
            ..Lexer::new(text)
        }
    }

    /// Whether the limit stopped the lexer before the end of the text.
    pub(super) fn was_cut(&self) -> bool {
        self.cut
    }

    /// Moves over the next `len` bytes (a char boundary), keeping the position up to date:
    /// columns count characters, so UTF-8 continuation bytes do not count.
    fn advance(&mut self, len: usize) {
        let end = (self.at + len).min(self.text.len());
        for &b in &self.text.as_bytes()[self.at..end] {
            if b == b'\n' {
                self.pos.line += 1;
                self.pos.column = 1;
            } else if b & 0xC0 != 0x80 {
                self.pos.column += 1;
            }
        }
        self.at = end;
    }
}

impl<'t> Iterator for Lexer<'t> {
    type Item = Token<'t>;

    fn next(&mut self) -> Option<Token<'t>> {
        if self.cut {
            return None;
        }
        loop {
            let rest = &self.text[self.at..];
            let c = rest.chars().next()?;
            let bytes = rest.as_bytes();
            let skip = if c.is_whitespace() {
                rest.find(|c: char| !c.is_whitespace()).unwrap_or(rest.len())
            } else if bytes.starts_with(b"//") {
                bytes.iter().position(|&b| b == b'\n').unwrap_or(bytes.len())
            } else if bytes.starts_with(b"/*") {
                block_comment_len(bytes)
            } else {
                0
            };
            if skip > 0 {
                self.advance(skip);
                continue;
            }
            let start = self.pos;
            if self.limit.is_some_and(|limit| start > limit) {
                self.cut = true;
                return None;
            }
            let (tok, len) = token(rest);
            self.advance(len);
            return Some(Token {
                tok,
                start,
                end: self.pos,
            });
        }
    }
}

/// Length in bytes of a (nestable) block comment starting at `s[0..2] == "/*"`.
fn block_comment_len(s: &[u8]) -> usize {
    let mut depth = 0usize;
    let mut k = 0;
    while k < s.len() {
        match (s[k], s.get(k + 1)) {
            (b'/', Some(b'*')) => {
                depth += 1;
                k += 2;
            }
            (b'*', Some(b'/')) => {
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

/// The token at the start of `s` (not whitespace or a comment) and its length in bytes (at a
/// char boundary, at least one char).
fn token(s: &str) -> (Tok<'_>, usize) {
    let b = s.as_bytes();
    let at = |k: usize| b.get(k).copied().unwrap_or(0);
    let atom = |len: usize| {
        let len = char_boundary(s, len);
        (Tok::Atom(&s[..len]), len)
    };
    match b[0] {
        c @ (b'(' | b'[' | b'{') => return (Tok::Open(c), 1),
        c @ (b')' | b']' | b'}') => return (Tok::Close(c), 1),
        b',' => return (Tok::Comma, 1),
        b':' => return (Tok::Colon, 1),
        b'"' => return atom(quoted_len(b, b'"')),
        b'\'' => return atom(quoted_len(b, b'\'')),
        b'b' if at(1) == b'"' || at(1) == b'\'' => return atom(1 + quoted_len(&b[1..], at(1))),
        b'b' if at(1) == b'r' && matches!(at(2), b'"' | b'#') => return atom(1 + raw_string_len(&b[1..])),
        b'r' if at(1) == b'"' || (at(1) == b'#' && matches!(at(2), b'"' | b'#')) => return atom(raw_string_len(b)),
        b'r' if at(1) == b'#' && s[2..].starts_with(is_ident_start) => {
            let end = 2 + ident_len(&s[2..]);
            return (Tok::Ident(&s[2..end]), end);
        }
        _ => {}
    }
    let c = s.chars().next().unwrap_or('\0');
    if is_ident_start(c) {
        let end = ident_len(s);
        (Tok::Ident(&s[..end]), end)
    } else if c.is_ascii_digit() || matches!(c, '+' | '-' | '.') {
        atom(number_len(s))
    } else {
        let len = c.len_utf8();
        (Tok::Other(&s[..len]), len)
    }
}

fn is_ident_start(c: char) -> bool {
    c.is_alphabetic() || c == '_'
}

/// Bytes of the name at the start of `s`.
fn ident_len(s: &str) -> usize {
    s.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(s.len())
}

/// Bytes of the number at the start of `s` (digits, letters for hex and suffixes, `_`, one
/// `.` not followed by another, and the sign of a decimal exponent).
fn number_len(s: &str) -> usize {
    let hex = s.trim_start_matches(['+', '-']).starts_with("0x") || s.trim_start_matches(['+', '-']).starts_with("0X");
    let mut prev = '\0';
    let mut chars = s.char_indices().skip(1).peekable();
    while let Some((i, d)) = chars.next() {
        let dot = d == '.' && chars.peek().is_none_or(|&(_, n)| n != '.');
        let exponent_sign = matches!(d, '+' | '-') && matches!(prev, 'e' | 'E') && !hex;
        if !(d.is_alphanumeric() || d == '_' || dot || exponent_sign) {
            return i;
        }
        prev = d;
    }
    s.len()
}

/// Bytes of a string or char literal opened by `quote` at `s[0]`, escapes included; the
/// whole rest when it is not closed.
fn quoted_len(s: &[u8], quote: u8) -> usize {
    let mut k = 1;
    while k < s.len() {
        match s[k] {
            b'\\' => k += 2,
            c if c == quote => return k + 1,
            _ => k += 1,
        }
    }
    s.len()
}

/// Bytes of a raw string `r#"..."#` starting at `s[0] == b'r'`; the whole rest when it is not
/// closed. Linear: after a `"` that does not close the string, the `#`s that follow it are
/// skipped at once (none of them can start the closing `"`).
fn raw_string_len(s: &[u8]) -> usize {
    let hashes = s[1..].iter().take_while(|&&c| c == b'#').count();
    let mut k = 1 + hashes + 1;
    while k < s.len() {
        if s[k] == b'"' {
            let run = s[k + 1..].iter().take(hashes).take_while(|&&c| c == b'#').count();
            if run == hashes {
                return k + 1 + hashes;
            }
            k += 1 + run;
        } else {
            k += 1;
        }
    }
    s.len()
}

/// `len` moved forward to a char boundary of `s` (at most `s.len()`).
fn char_boundary(s: &str, len: usize) -> usize {
    let mut len = len.min(s.len());
    while !s.is_char_boundary(len) {
        len += 1;
    }
    len
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(text: &str) -> Vec<Tok<'_>> {
        Lexer::new(text).map(|t| t.tok).collect()
    }

    #[test]
    fn splits_tokens_and_skips_comments() {
        let text = "#![x] /* a /* b */ c */ r#n: -1.5e-3, 'c' // end\n \"s\\\"\" b\"x\" br#\"y\"# é.0";
        assert_eq!(
            toks(text),
            [
                Tok::Other("#"),
                Tok::Other("!"),
                Tok::Open(b'['),
                Tok::Ident("x"),
                Tok::Close(b']'),
                Tok::Ident("n"),
                Tok::Colon,
                Tok::Atom("-1.5e-3"),
                Tok::Comma,
                Tok::Atom("'c'"),
                Tok::Atom("\"s\\\"\""),
                Tok::Atom("b\"x\""),
                Tok::Atom("br#\"y\"#"),
                Tok::Ident("é"),
                Tok::Atom(".0"),
            ]
        );
        assert_eq!(toks("0x1e-2"), [Tok::Atom("0x1e"), Tok::Atom("-2")]);
        assert_eq!(toks("1..2"), [Tok::Atom("1"), Tok::Atom("..2")]);
    }

    #[test]
    fn positions_count_characters() {
        let all: Vec<Token<'_>> = Lexer::new("é (\n  ab)").collect();
        let at = |line, column| Pos { line, column };
        assert_eq!((all[0].start, all[0].end), (at(1, 1), at(1, 2)));
        assert_eq!(all[1].start, at(1, 3));
        assert_eq!((all[2].start, all[2].end), (at(2, 3), at(2, 5)));
        let mut cut = Lexer::until("a b c", at(1, 3));
        assert_eq!(cut.by_ref().count(), 2);
        assert!(cut.was_cut());
    }

    #[test]
    fn raw_strings_close_on_enough_hashes() {
        assert_eq!(raw_string_len(b"r##\"a\"#\"##b"), 10);
        assert_eq!(raw_string_len(b"r\"a\"b"), 4);
        assert_eq!(raw_string_len(b"r#\"open"), 7);
        // Many quotes, each followed by one `#` too few: read once, not once per quote.
        let mut text = b"r###\"".to_vec();
        text.extend(b"\"##".repeat(1000));
        assert_eq!(raw_string_len(&text), text.len());
    }
}
