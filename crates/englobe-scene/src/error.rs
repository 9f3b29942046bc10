//! Errors that name the file, the line and the column, and say what was expected.

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Why a scene was refused.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{}: cannot read: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said (already part of the message, so not a separate source).
        error: std::io::Error,
    },
    /// The file was read but its content is wrong at a known place.
    #[error("{0}")]
    Invalid(Located),
    /// A mesh file the scene names could not be loaded: the place is the scene's `[[mesh]]` entry,
    /// `mesh` says what is wrong with the mesh file, and where.
    #[error("{located}")]
    Mesh {
        /// The scene entry, with a message that includes the mesh error.
        located: Located,
        /// The mesh file's own error (already part of `located`'s message).
        mesh: Box<crate::mesh::MeshFileError>,
    },
}

/// A message about one place of one file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Located {
    /// The file, as it should be shown to the user.
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// What is wrong and what was expected.
    pub message: String,
    /// The offending line of the file, for context.
    pub source_line: String,
}

impl fmt::Display for Located {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}: {}", self.file, self.line, self.column, self.message)?;
        if !self.source_line.is_empty() {
            let gutter = self.line.to_string().len();
            write!(
                f,
                "\n{:gutter$} |\n{} | {}\n{:gutter$} | {:>col$}",
                "",
                self.line,
                self.source_line,
                "",
                "^",
                col = self.column
            )?;
        }
        Ok(())
    }
}

impl Located {
    /// The place of byte range `span` of `text` (its start), with `message`.
    pub fn at(file: &str, text: &str, span: Option<Range<usize>>, message: impl Into<String>) -> Self {
        let offset = span.map_or(0, |s| s.start).min(text.len());
        let (line, column, source_line) = line_and_column(text, offset);
        Located { file: file.to_owned(), line, column, message: message.into(), source_line }
    }
}

impl SceneError {
    /// An error at byte range `span` of `text` (the start of the range is reported).
    pub fn at(file: &str, text: &str, span: Option<Range<usize>>, message: impl Into<String>) -> Self {
        SceneError::Invalid(Located::at(file, text, span, message))
    }

    /// The place of the error, when it has one.
    pub fn location(&self) -> Option<&Located> {
        match self {
            SceneError::Invalid(l) | SceneError::Mesh { located: l, .. } => Some(l),
            SceneError::Io { .. } => None,
        }
    }

    /// An error reading `path`.
    pub fn io(path: &Path, error: std::io::Error) -> Self {
        SceneError::Io { path: path.to_owned(), error }
    }
}

/// 1-based line and column (in characters) of byte `offset`, and the text of that line.
fn line_and_column(text: &str, offset: usize) -> (usize, usize, String) {
    // Back off to a character boundary so slicing cannot panic on a span inside a character.
    let mut offset = offset;
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = text[line_start..offset].chars().count() + 1;
    let line_end = text[line_start..].find('\n').map_or(text.len(), |i| line_start + i);
    (line, column, text[line_start..line_end].trim_end_matches('\r').to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column_are_one_based() {
        let text = "a = 1\nbé = 2\n";
        assert_eq!(line_and_column(text, 0), (1, 1, "a = 1".into()));
        assert_eq!(line_and_column(text, 6), (2, 1, "bé = 2".into()));
        let e = text.find("= 2").unwrap();
        assert_eq!(line_and_column(text, e), (2, 4, "bé = 2".into()));
        // Inside a multi-byte character: no panic.
        assert_eq!(line_and_column(text, 8).0, 2);
    }

    #[test]
    fn display_starts_with_file_line_column() {
        let e = SceneError::at("s.toml", "x = 1\ny = 2", Some(10..11), "expected a string");
        let shown = e.to_string();
        assert!(shown.starts_with("s.toml:2:5: expected a string"), "{shown}");
        assert!(shown.contains("y = 2"));
    }
}
