//! What a pbrt scene asks for that englobe does not do exactly, said once per kind of thing with
//! the place of its first occurrence and a count: skipped (not rendered at all), approximated
//! (rendered by the nearest thing englobe has), or ignored (read and dropped because it does not
//! change the picture, such as the output file name). Under `strict`, the first thing skipped or
//! approximated is an error at its place instead.

use std::collections::HashMap;

use super::source::{Fail, Place, Res, Sources};

/// How far the rendered picture departs from what the file asks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Severity {
    /// Not rendered.
    Skipped,
    /// Rendered by the nearest thing englobe has.
    Approximated,
    /// Does not change the picture.
    Ignored,
}

struct Entry {
    at: Place,
    message: String,
    severity: Severity,
    count: usize,
}

/// The report of one scene.
pub(super) struct Report {
    strict: bool,
    entries: Vec<Entry>,
    index: HashMap<String, usize>,
}

impl Report {
    pub fn new(strict: bool) -> Self {
        Report { strict, entries: Vec::new(), index: HashMap::new() }
    }

    /// Records one occurrence of the thing called `key` at `at`; `message` says what it is and
    /// what englobe does instead (made only for the first occurrence). Strict mode turns anything
    /// but [`Severity::Ignored`] into an error.
    pub fn note(&mut self, severity: Severity, at: Place, key: &str, message: impl FnOnce() -> String) -> Res<()> {
        if let Some(&i) = self.index.get(key) {
            self.entries[i].count += 1;
            return Ok(());
        }
        let message = message();
        if self.strict && severity != Severity::Ignored {
            return Err(Fail::At(at, format!("{message} (refused under --strict)")));
        }
        self.index.insert(key.to_owned(), self.entries.len());
        self.entries.push(Entry { at, message, severity, count: 1 });
        Ok(())
    }

    pub fn skipped(&mut self, at: Place, key: &str, message: impl FnOnce() -> String) -> Res<()> {
        self.note(Severity::Skipped, at, key, message)
    }

    pub fn approximated(&mut self, at: Place, key: &str, message: impl FnOnce() -> String) -> Res<()> {
        self.note(Severity::Approximated, at, key, message)
    }

    pub fn ignored(&mut self, at: Place, key: &str, message: impl FnOnce() -> String) -> Res<()> {
        self.note(Severity::Ignored, at, key, message)
    }

    /// The warnings, in the order first met: `file:line:column: message`, with the number of
    /// occurrences when there were several.
    pub fn warnings(&self, sources: &Sources) -> Vec<String> {
        self.entries
            .iter()
            .map(|e| {
                let what = match e.severity {
                    Severity::Skipped => "skipped",
                    Severity::Approximated => "approximated",
                    Severity::Ignored => "ignored",
                };
                let times =
                    if e.count > 1 { format!(" ({} times; the first is shown)", e.count) } else { String::new() };
                format!("{}: {what}: {}{times}", sources.show(e.at), e.message)
            })
            .collect()
    }
}
