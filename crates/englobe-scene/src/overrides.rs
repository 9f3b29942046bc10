//! Scene values set from the command line: `-D camera.fov=40`, `-D point_light.0.intensity=60`.
//!
//! An override replaces (or adds) one value of the scene's TOML document, found by its dotted path
//! (a number indexes an array such as `[[point_light]]`), before the document is read into the
//! scene's structures, so an overridden value is checked exactly like one written in the file.
//! Why not edit the text: the document is parsed once with its spans, the new values are parsed
//! on their own, and their spans are moved past the end of the file's text, into a region that
//! stands for the overrides. An error whose span falls there is then reported against the
//! override (`-D camera.fov=400:1:14: ...`), and every other error keeps its place in the file.

use std::borrow::Cow;
use std::fmt;
use std::ops::Range;
use std::str::FromStr;

use toml::Spanned;
use toml::de::{DeArray, DeTable, DeValue};

use crate::error::Located;

/// One `key=value` of the command line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Override {
    /// The dotted path, as written: `camera.fov`, `point_light.0.intensity`.
    pub key: String,
    /// The value, as written: a TOML value (`40`, `[1, 2, 3]`, `"path"`), or a bare word such as
    /// `path` or `meshes/bunny.obj`, taken as a string.
    pub value: String,
}

impl FromStr for Override {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let Some((key, value)) = s.split_once('=') else {
            return Err(format!("`{s}`: expected KEY=VALUE, such as camera.fov=40"));
        };
        let key = key.trim();
        if key.is_empty() || key.split('.').any(|part| part.trim().is_empty()) {
            return Err(format!("`{s}`: the key must be a dotted path such as camera.fov or point_light.0.intensity"));
        }
        Ok(Override { key: key.to_owned(), value: value.trim().to_owned() })
    }
}

impl fmt::Display for Override {
    /// The form that `englobe render` accepts back: `-D key=value`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "-D {}={}", self.key, self.value)
    }
}

/// Where the overrides stand in the span space of a scene text: override `i` is shown as
/// `-D key=value` and occupies `starts[i]..starts[i] + shown[i].len()`, past the end of the text.
#[derive(Clone, Debug, Default)]
pub(crate) struct Placed {
    text_len: usize,
    starts: Vec<usize>,
    shown: Vec<String>,
}

impl Placed {
    pub(crate) fn new(text_len: usize, overrides: &[Override]) -> Self {
        let mut starts = Vec::new();
        let mut shown = Vec::new();
        let mut at = text_len + 1;
        for o in overrides {
            starts.push(at);
            let s = o.to_string();
            at += s.len() + 1;
            shown.push(s);
        }
        Placed { text_len, starts, shown }
    }

    /// The place of `span`: in the file's `text`, or in the override it falls in.
    pub(crate) fn locate(&self, file: &str, text: &str, span: Option<Range<usize>>, message: String) -> Located {
        let start = span.as_ref().map_or(0, |s| s.start);
        if start <= self.text_len {
            return Located::at(file, text, span, message);
        }
        let i = self.starts.iter().rposition(|&s| s <= start).unwrap_or(0);
        let shown = &self.shown[i];
        let offset = start - self.starts[i];
        Located::at(shown, shown, Some(offset..offset + 1), message)
    }

    /// Offset of override `i`'s key, and of its value, in span space.
    fn key_and_value(&self, i: usize, o: &Override) -> (usize, usize) {
        let key = self.starts[i] + "-D ".len();
        (key, key + o.key.len() + 1)
    }
}

/// The file's document, `root`, with `overrides` applied; spans of the new values point into the
/// region that `placed` describes.
pub(crate) fn apply<'a>(
    root: &mut DeTable<'a>,
    overrides: &'a [Override],
    placed: &Placed,
    file: &str,
    text: &str,
) -> Result<(), Located> {
    for (i, o) in overrides.iter().enumerate() {
        let (key_at, value_at) = placed.key_and_value(i, o);
        let fail = |at: usize, message: String| placed.locate(file, text, Some(at..at + 1), message);
        let value = parse_value(&o.value).map_err(|(span, message)| fail(value_at + span.start, message))?;
        let value = shifted(value, value_at);
        let mut parts = Vec::new();
        let mut at = key_at;
        for part in o.key.split('.') {
            parts.push((part.trim(), at..at + part.len()));
            at += part.len() + 1;
        }
        set(root, &parts, value).map_err(|(span, message)| fail(span.start, message))?;
    }
    Ok(())
}

/// A TOML value, or a bare word read as a string (`path`, `meshes/bunny.obj`), so that the shell's
/// quotes are not needed for the common case.
fn parse_value(text: &str) -> Result<Spanned<DeValue<'_>>, (Range<usize>, String)> {
    match DeValue::parse(text) {
        Ok(v) => Ok(v),
        Err(_) if is_bare_word(text) => Ok(Spanned::new(0..text.len(), DeValue::String(Cow::Borrowed(text)))),
        Err(e) => Err((e.span().unwrap_or(0..0), format!("not a TOML value: {}", e.message().trim()))),
    }
}

fn is_bare_word(text: &str) -> bool {
    let mut chars = text.chars();
    chars.next().is_some_and(|c| c.is_alphabetic() || c == '_' || c == '.' || c == '/')
        && text.chars().all(|c| c.is_alphanumeric() || "_-./".contains(c))
}

/// `v` with every span moved by `by`.
fn shifted(v: Spanned<DeValue<'_>>, by: usize) -> Spanned<DeValue<'_>> {
    let span = v.span();
    let inner = match v.into_inner() {
        DeValue::Array(items) => {
            let mut out = DeArray::new();
            for item in items.iter().cloned() {
                out.push(shifted(item, by));
            }
            DeValue::Array(out)
        }
        DeValue::Table(table) => DeValue::Table(
            table
                .into_iter()
                .map(|(k, v)| {
                    let ks = k.span();
                    (Spanned::new(ks.start + by..ks.end + by, k.into_inner()), shifted(v, by))
                })
                .collect(),
        ),
        other => other,
    };
    Spanned::new(span.start + by..span.end + by, inner)
}

type Part<'a> = (&'a str, Range<usize>);

/// Sets the value at path `parts` under `table`, creating tables on the way (serde then refuses
/// any that the format does not know, at the override's key).
fn set<'a>(
    table: &mut DeTable<'a>,
    parts: &[Part<'a>],
    value: Spanned<DeValue<'a>>,
) -> Result<(), (Range<usize>, String)> {
    let ((name, span), rest) = parts.split_first().expect("a key has at least one part");
    let key = Spanned::new(span.clone(), Cow::Borrowed(*name));
    if rest.is_empty() {
        table.remove(*name);
        table.insert(key, value);
        return Ok(());
    }
    let slot = table.entry(key).or_insert_with(|| Spanned::new(span.clone(), DeValue::Table(DeTable::new())));
    descend(slot.get_mut(), name, rest, value)
}

fn descend<'a>(
    current: &mut DeValue<'a>,
    path: &str,
    parts: &[Part<'a>],
    value: Spanned<DeValue<'a>>,
) -> Result<(), (Range<usize>, String)> {
    match current {
        DeValue::Table(table) => set(table, parts, value),
        DeValue::Array(items) => {
            let ((index, span), rest) = parts.split_first().expect("a key has at least one part");
            let len = items.len();
            let i = index.parse::<usize>().ok().filter(|&i| i <= len).ok_or_else(|| {
                let range = if len == 0 { String::new() } else { format!("0 to {}, or ", len - 1) };
                (
                    span.clone(),
                    format!("`{path}` has {len} entries: `{index}` is not an index (expected {range}{len} to add one)"),
                )
            })?;
            if rest.is_empty() {
                if i == len {
                    items.push(value);
                } else {
                    items.as_mut()[i] = value;
                }
                return Ok(());
            }
            if i == len {
                items.push(Spanned::new(span.clone(), DeValue::Table(DeTable::new())));
            }
            descend(items.as_mut()[i].get_mut(), &format!("{path}.{index}"), rest, value)
        }
        other => Err((
            parts[0].1.clone(),
            format!("`{path}` is {} {}, so it has no `{}`", article(other.type_str()), other.type_str(), parts[0].0),
        )),
    }
}

fn article(word: &str) -> &'static str {
    if word.starts_with(['a', 'e', 'i', 'o', 'u']) { "an" } else { "a" }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_override_needs_a_key_and_a_value() {
        assert_eq!("camera.fov=40".parse(), Ok(Override { key: "camera.fov".into(), value: "40".into() }));
        assert!("camera.fov".parse::<Override>().unwrap_err().contains("KEY=VALUE"));
        assert!("camera..fov=1".parse::<Override>().unwrap_err().contains("dotted path"));
    }

    #[test]
    fn bare_words_are_strings_and_values_are_toml() {
        assert!(matches!(parse_value("path").unwrap().into_inner(), DeValue::String(_)));
        assert!(matches!(parse_value("meshes/bunny.obj").unwrap().into_inner(), DeValue::String(_)));
        assert!(matches!(parse_value("40").unwrap().into_inner(), DeValue::Integer(_)));
        assert!(matches!(parse_value("[1, 2, 3]").unwrap().into_inner(), DeValue::Array(_)));
        assert!(parse_value("[1, 2").is_err());
    }

    #[test]
    fn an_error_in_an_override_is_reported_against_it() {
        let overrides =
            vec![Override { key: "a".into(), value: "1".into() }, Override { key: "b.c".into(), value: "2".into() }];
        let placed = Placed::new(10, &overrides);
        let (key, value) = placed.key_and_value(1, &overrides[1]);
        let l = placed.locate("s.toml", "0123456789", Some(value..value + 1), "bad".into());
        assert_eq!((l.file.as_str(), l.line, l.column), ("-D b.c=2", 1, 8));
        let l = placed.locate("s.toml", "0123456789", Some(key..key + 1), "bad".into());
        assert_eq!(l.column, 4);
        let l = placed.locate("s.toml", "0123456789", Some(3..4), "bad".into());
        assert_eq!((l.file.as_str(), l.column), ("s.toml", 4));
    }
}
