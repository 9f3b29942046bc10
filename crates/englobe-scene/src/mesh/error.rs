//! Why a mesh file was refused: the file, the place in it (a line, a byte, or a path into a glTF
//! document) and what was wrong, as a typed value that tests and programs can match on.

use std::fmt;
use std::path::{Path, PathBuf};

/// A place in a mesh file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Position {
    /// A 1-based line of a text file (OBJ, MTL, ASCII PLY, PLY header).
    Line(usize),
    /// A 1-based line and column (the JSON of a glTF file).
    LineColumn(usize, usize),
    /// A 0-based byte offset (binary PLY, GLB, glTF buffers).
    Byte(u64),
    /// A path into a glTF document, such as `accessors[3].count`.
    Json(String),
}

impl fmt::Display for Position {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Position::Line(l) => write!(f, "line {l}"),
            Position::LineColumn(l, c) => write!(f, "line {l}, column {c}"),
            Position::Byte(b) => write!(f, "byte {b}"),
            Position::Json(p) => f.write_str(p),
        }
    }
}

/// What was wrong.
#[derive(Debug, thiserror::Error)]
pub enum MeshErrorKind {
    /// The file could not be read (missing, a directory, no permission).
    #[error("cannot read: {0}")]
    Io(#[source] std::io::Error),
    /// The file is larger than englobe reads.
    #[error("{bytes} bytes is more than the limit of {limit} bytes")]
    FileTooLarge {
        /// Size of the file.
        bytes: u64,
        /// The limit.
        limit: u64,
    },
    /// A file with no size known beforehand (a device, a pipe) gave more bytes than englobe reads;
    /// reading stopped there.
    #[error("more than the limit of {limit} bytes (not a regular file, so read up to the limit, then refused)")]
    StreamTooLarge {
        /// The limit.
        limit: u64,
    },
    /// The extension names no format englobe reads.
    #[error("unknown mesh format `{0}`: expected .obj, .ply, .gltf or .glb")]
    UnknownFormat(String),
    /// The file is part of a mesh but not a mesh itself (a material library, a buffer).
    #[error("{0}")]
    NotAMesh(String),
    /// A file this one refers to (a glTF buffer) could not be used; the inner error names it.
    #[error("{0}")]
    Referenced(Box<MeshFileError>),
    /// Text that should be a number is not one.
    #[error("`{token}` is not {expected}")]
    BadNumber {
        /// The offending text.
        token: String,
        /// What was expected there.
        expected: &'static str,
    },
    /// A coordinate, normal, colour or matrix entry is NaN or infinite.
    #[error("{what} is not finite: {value}")]
    NonFinite {
        /// Which value.
        what: String,
        /// The value as read.
        value: String,
    },
    /// A statement has the wrong number of values.
    #[error("`{keyword}` expects {expected}, found {found} value(s)")]
    Arity {
        /// The statement.
        keyword: String,
        /// What it expects.
        expected: &'static str,
        /// How many values were given.
        found: usize,
    },
    /// An index refers to something that does not exist.
    #[error("{what} index {index} is out of range: {available} defined{context}")]
    IndexOutOfRange {
        /// What the index refers to (vertex, texture coordinate, normal, accessor...).
        what: &'static str,
        /// The index as written.
        index: String,
        /// How many exist.
        available: u64,
        /// Extra words, such as " before this line".
        context: &'static str,
    },
    /// A count or size would need more bytes than the file holds (or absurd memory).
    #[error("{what}: {count} would need at least {needed} bytes, but only {available} remain")]
    CountTooLarge {
        /// What is counted.
        what: String,
        /// The count as declared.
        count: u64,
        /// Bytes the count needs at the least (saturating).
        needed: u64,
        /// Bytes left in the file or buffer.
        available: u64,
    },
    /// The file ends before the data it declares.
    #[error("the file ends early: {0}")]
    Truncated(String),
    /// The file needs a glTF extension englobe does not implement.
    #[error("the file requires the glTF extension `{0}`, which englobe does not support")]
    UnsupportedExtension(String),
    /// A valid feature of the format that englobe does not read.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// The structure of the file is wrong.
    #[error("{0}")]
    Malformed(String),
    /// The file holds no triangle to render.
    #[error("no triangles{0}")]
    NoTriangles(String),
    /// A third-party parser failed after englobe's own checks passed.
    #[error("{0}")]
    Parser(String),
}

/// A mesh file that was refused.
#[derive(Debug, thiserror::Error)]
pub struct MeshFileError {
    /// The file.
    pub path: PathBuf,
    /// Where in it, when known.
    pub at: Option<Position>,
    /// What was wrong (its message is part of this error's, so it is not a separate source).
    pub kind: MeshErrorKind,
}

impl fmt::Display for MeshFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.at {
            Some(at) => write!(f, "{}: {at}: {}", self.path.display(), self.kind),
            None => write!(f, "{}: {}", self.path.display(), self.kind),
        }
    }
}

impl MeshFileError {
    /// An error at `at` of `path`.
    pub fn new(path: &Path, at: Option<Position>, kind: MeshErrorKind) -> Self {
        MeshFileError { path: path.to_owned(), at, kind }
    }

    /// An error at line `line` of `path`.
    pub fn line(path: &Path, line: usize, kind: MeshErrorKind) -> Self {
        Self::new(path, Some(Position::Line(line)), kind)
    }

    /// An error at byte `byte` of `path`.
    pub fn byte(path: &Path, byte: u64, kind: MeshErrorKind) -> Self {
        Self::new(path, Some(Position::Byte(byte)), kind)
    }

    /// An error about the whole of `path`.
    pub fn file(path: &Path, kind: MeshErrorKind) -> Self {
        Self::new(path, None, kind)
    }

    /// The line the error is on, for text formats.
    pub fn line_number(&self) -> Option<usize> {
        match self.at {
            Some(Position::Line(l)) | Some(Position::LineColumn(l, _)) => Some(l),
            _ => None,
        }
    }

    /// The byte offset the error is at, for binary formats.
    pub fn byte_offset(&self) -> Option<u64> {
        match self.at {
            Some(Position::Byte(b)) => Some(b),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_the_file_and_the_place() {
        let e = MeshFileError::line(
            Path::new("m.obj"),
            3,
            MeshErrorKind::Arity { keyword: "v".into(), expected: "3 coordinates", found: 2 },
        );
        assert_eq!(e.to_string(), "m.obj: line 3: `v` expects 3 coordinates, found 2 value(s)");
        assert_eq!(e.line_number(), Some(3));
        let e = MeshFileError::byte(Path::new("m.ply"), 120, MeshErrorKind::Truncated("face 2".into()));
        assert_eq!(e.to_string(), "m.ply: byte 120: the file ends early: face 2");
        assert_eq!(e.byte_offset(), Some(120));
    }
}
