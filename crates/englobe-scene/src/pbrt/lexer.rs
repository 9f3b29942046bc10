//! The tokens of a pbrt file (pbrt-v4's file format, "Tokenization" in its documentation, and
//! `Tokenizer` in pbrt-v4's `parser.cpp`): quoted strings (with the escapes `\b \f \n \r \t \\
//! \' \"`, on one line), `[` and `]`, comments from `#` to the end of the line, and words: runs of
//! anything else up to white space, a quote or a bracket (directive names, numbers, `true`).

use std::borrow::Cow;
use std::sync::Arc;

use super::source::{Place, Res, fail};

/// What a token is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    Word,
    /// A quoted string; `escaped` when it holds a backslash.
    Str {
        escaped: bool,
    },
    Open,
    Close,
}

/// A token: its kind and its bytes `start..end` in the file (a string's include its quotes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Token {
    pub kind: Kind,
    pub start: usize,
    pub end: usize,
}

/// The tokens of one file, one at a time.
pub(super) struct Lexer {
    text: Arc<String>,
    file: u32,
    pos: usize,
    peeked: Option<Token>,
}

impl Lexer {
    pub fn new(text: Arc<String>, file: u32) -> Self {
        Lexer { text, file, pos: 0, peeked: None }
    }

    pub fn file(&self) -> u32 {
        self.file
    }

    /// The place of byte `offset` of this file.
    pub fn place(&self, offset: usize) -> Place {
        Place { file: self.file, offset }
    }

    /// The place where the text ends, for "the file ended before..." errors.
    pub fn end_place(&self) -> Place {
        self.place(self.text.len())
    }

    /// The text of a token as written (a string with its quotes).
    pub fn slice(&self, t: &Token) -> &str {
        &self.text[t.start..t.end]
    }

    /// The value of a string token, escapes resolved; a word as written.
    pub fn string(&self, t: &Token) -> Cow<'_, str> {
        match t.kind {
            Kind::Str { escaped: false } => Cow::Borrowed(&self.text[t.start + 1..t.end - 1]),
            Kind::Str { escaped: true } => Cow::Owned(unescape(&self.text[t.start + 1..t.end - 1])),
            _ => Cow::Borrowed(self.slice(t)),
        }
    }

    /// The next token without taking it.
    pub fn peek(&mut self) -> Res<Option<Token>> {
        if self.peeked.is_none() {
            self.peeked = self.scan()?;
        }
        Ok(self.peeked)
    }

    /// The next token, or `None` at the end of the file.
    pub fn next(&mut self) -> Res<Option<Token>> {
        match self.peeked.take() {
            Some(t) => Ok(Some(t)),
            None => self.scan(),
        }
    }

    fn scan(&mut self) -> Res<Option<Token>> {
        let bytes = self.text.as_bytes();
        loop {
            while self.pos < bytes.len() && bytes[self.pos].is_ascii_whitespace() {
                self.pos += 1;
            }
            if self.pos >= bytes.len() {
                return Ok(None);
            }
            if bytes[self.pos] == b'#' {
                while self.pos < bytes.len() && bytes[self.pos] != b'\n' {
                    self.pos += 1;
                }
                continue;
            }
            break;
        }
        let start = self.pos;
        let one = |kind| Token { kind, start, end: start + 1 };
        match bytes[start] {
            b'[' => {
                self.pos += 1;
                Ok(Some(one(Kind::Open)))
            }
            b']' => {
                self.pos += 1;
                Ok(Some(one(Kind::Close)))
            }
            b'"' => {
                let mut i = start + 1;
                let mut escaped = false;
                loop {
                    match bytes.get(i) {
                        None | Some(b'\n') | Some(b'\r') => {
                            return fail(
                                self.place(start),
                                "unterminated string: a quoted string must end with `\"` on the line it starts",
                            );
                        }
                        Some(b'"') => break,
                        Some(b'\\') => {
                            escaped = true;
                            i += 2;
                        }
                        Some(_) => i += 1,
                    }
                }
                self.pos = i + 1;
                Ok(Some(Token { kind: Kind::Str { escaped }, start, end: i + 1 }))
            }
            _ => {
                let mut i = start;
                while i < bytes.len() && !bytes[i].is_ascii_whitespace() && !matches!(bytes[i], b'"' | b'[' | b']') {
                    i += 1;
                }
                self.pos = i;
                // Words end at ASCII bytes only, so `start..i` lies on character boundaries.
                Ok(Some(Token { kind: Kind::Word, start, end: i }))
            }
        }
    }
}

/// A string's content with its escapes resolved (pbrt-v4's list; an unknown escape keeps the
/// character after the backslash).
fn unescape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        match chars.next() {
            Some('b') => out.push('\u{8}'),
            Some('f') => out.push('\u{c}'),
            Some('n') => out.push('\n'),
            Some('r') => out.push('\r'),
            Some('t') => out.push('\t'),
            Some(other) => out.push(other),
            None => {}
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tokens(text: &str) -> Vec<(Kind, String)> {
        let mut lex = Lexer::new(Arc::new(text.to_owned()), 0);
        let mut out = Vec::new();
        while let Some(t) = lex.next().unwrap() {
            out.push((t.kind, lex.string(&t).into_owned()));
        }
        out
    }

    #[test]
    fn words_strings_brackets_and_comments() {
        let t = tokens("Shape \"sphere\" # a comment \"not a string\"\n\"float radius\"[2.5]-1e3 é\"a\\\"b\\n\"");
        let kinds: Vec<Kind> = t.iter().map(|(k, _)| *k).collect();
        assert_eq!(
            kinds,
            vec![
                Kind::Word,
                Kind::Str { escaped: false },
                Kind::Str { escaped: false },
                Kind::Open,
                Kind::Word,
                Kind::Close,
                Kind::Word,
                Kind::Word,
                Kind::Str { escaped: true }
            ]
        );
        let values: Vec<&str> = t.iter().map(|(_, v)| v.as_str()).collect();
        assert_eq!(values, vec!["Shape", "sphere", "float radius", "[", "2.5", "]", "-1e3", "é", "a\"b\n"]);
    }

    #[test]
    fn a_string_must_end_on_its_line() {
        for text in ["Shape \"sphere", "Shape \"sph\nere\"", "\"a\\"] {
            let mut lex = Lexer::new(Arc::new(text.to_owned()), 0);
            let mut result = Ok(None);
            for _ in 0..3 {
                result = lex.next();
                if result.is_err() {
                    break;
                }
            }
            match result {
                Err(super::super::source::Fail::At(at, message)) => {
                    assert!(message.contains("unterminated string"), "{message}");
                    assert_eq!(&text[at.offset..at.offset + 1], "\"");
                }
                other => panic!("{text:?}: {other:?}"),
            }
        }
    }
}
