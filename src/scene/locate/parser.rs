//! The forgiving reader behind [`Node`]: recursive descent over the lazy token stream, with
//! two tokens of look-ahead, that never fails and keeps only what a query needs.

use std::collections::VecDeque;

use crate::scene::locate::lexer::{Lexer, Tok, Token};
use crate::scene::locate::{Group, MAX_DEPTH, Node, Pos};

/// A recursive-descent reader over the lazy token stream, two tokens of look-ahead.
pub(super) struct Parser<'t> {
    lex: Lexer<'t>,
    ahead: VecDeque<Token<'t>>,
    /// Start of the last token read (where a value at the end of the text is placed).
    last: Pos,
    /// Reading for one position: children that end before it are not kept.
    keep_from: Option<Pos>,
}

impl<'t> Parser<'t> {
    pub(super) fn new(lex: Lexer<'t>, keep_from: Option<Pos>) -> Self {
        Parser {
            lex,
            ahead: VecDeque::with_capacity(2),
            last: Pos { line: 1, column: 1 },
            keep_from,
        }
    }

    /// The top-level value, after any `#![enable(...)]` attributes.
    pub(super) fn top(mut self) -> Node<'t> {
        self.skip_attributes();
        self.value(0)
    }

    fn peek(&mut self, ahead: usize) -> Option<Tok<'t>> {
        while self.ahead.len() <= ahead {
            let token = self.lex.next()?;
            self.last = token.start;
            self.ahead.push_back(token);
        }
        self.ahead.get(ahead).map(|t| t.tok)
    }

    fn pos(&mut self) -> Pos {
        self.peek(0);
        self.ahead.front().map_or(self.last, |t| t.start)
    }

    /// Where a group left open at the end of what is read ends: its last token, or after
    /// everything when reading stopped early.
    fn end_of_input(&mut self) -> Pos {
        if self.lex.was_cut() { Pos::MAX } else { self.pos() }
    }

    fn bump(&mut self) -> Option<Tok<'t>> {
        self.peek(0);
        self.ahead.pop_front().map(|t| t.tok)
    }

    /// Whether a finished child must be kept.
    fn keeps(&self, end: Pos) -> bool {
        self.keep_from.is_none_or(|from| end >= from)
    }

    /// Skips `#![enable(...)]` attributes before the top-level value.
    fn skip_attributes(&mut self) {
        while self.peek(0) == Some(Tok::Other("#")) {
            self.bump();
            if self.peek(0) == Some(Tok::Other("!")) {
                self.bump();
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

    fn value(&mut self, depth: usize) -> Node<'t> {
        let start = self.pos();
        let leaf = |atom| Node {
            start,
            end: start,
            atom,
            group: None,
        };
        match self.peek(0) {
            None => leaf(""),
            Some(Tok::Ident(name)) => {
                self.bump();
                if self.peek(0) == Some(Tok::Open(b'(')) {
                    let mut node = self.group(depth);
                    node.start = start;
                    node
                } else {
                    leaf(name)
                }
            }
            Some(Tok::Open(_)) => self.group(depth),
            // A stray closing bracket, comma or colon is left for the enclosing group.
            Some(Tok::Close(_) | Tok::Comma | Tok::Colon) => leaf(""),
            Some(Tok::Atom(text)) => {
                self.bump();
                leaf(text)
            }
            Some(Tok::Other(_)) => {
                self.bump();
                leaf("")
            }
        }
    }

    /// Reads a bracketed group; the current token is its opening bracket.
    fn group(&mut self, depth: usize) -> Node<'t> {
        let start = self.pos();
        let empty = Node {
            start,
            end: start,
            ..Node::default()
        };
        if depth >= MAX_DEPTH {
            self.skip_group();
            return empty;
        }
        let Some(Tok::Open(open)) = self.bump() else {
            return empty;
        };
        let mut group = Group {
            list: open == b'[',
            ..Group::default()
        };
        let end = loop {
            match self.peek(0) {
                None => break self.end_of_input(),
                Some(Tok::Close(_)) => {
                    let end = self.pos();
                    self.bump();
                    break end;
                }
                // Stray characters mean nothing here and make no node.
                Some(Tok::Comma | Tok::Colon | Tok::Other(_)) => {
                    self.bump();
                }
                Some(Tok::Ident(name)) if open == b'(' && self.peek(1) == Some(Tok::Colon) => {
                    let at = self.pos();
                    self.bump();
                    self.bump();
                    let value = self.value(depth + 1);
                    if self.keeps(value.end) {
                        group.fields.push((name, at, value));
                    }
                }
                Some(_) if open == b'{' => {
                    let key = self.value(depth + 1);
                    let value = if self.peek(0) == Some(Tok::Colon) {
                        self.bump();
                        self.value(depth + 1)
                    } else {
                        Node {
                            start: key.end,
                            end: key.end,
                            ..Node::default()
                        }
                    };
                    let index = group.item_count;
                    group.item_count += 1;
                    if self.keeps(value.end.max(key.end)) {
                        group.entries.push((index, key, value));
                    }
                }
                Some(_) => {
                    let item = self.value(depth + 1);
                    let index = group.item_count;
                    group.item_count += 1;
                    if self.keeps(item.end) {
                        group.items.push((index, item));
                    }
                }
            }
        };
        if group.fields.is_empty() && group.items.is_empty() && group.entries.is_empty() && group.item_count == 0 {
            return Node { end, ..empty };
        }
        Node {
            start,
            end,
            atom: "",
            group: Some(Box::new(group)),
        }
    }
}
