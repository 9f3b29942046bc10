//! The text of a pbrt scene and of every file it includes: each file read whole (within a size
//! limit), named as the user named it, and the places in them (a file and a byte offset) that
//! errors and warnings point at, shown as `file:line:column`.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::{Located, SceneError};
use crate::mesh::MAX_MESH_FILE_BYTES;

/// Largest pbrt file read: as large as a mesh file, since pbrt files often hold their meshes inline.
pub const MAX_PBRT_FILE_BYTES: u64 = MAX_MESH_FILE_BYTES;
/// Most bytes read over a scene and all its includes (a file included many times counts each time).
pub const MAX_PBRT_TOTAL_BYTES: u64 = 2 * MAX_MESH_FILE_BYTES;

/// A place in one of the files: the file's number and a byte offset in its text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) struct Place {
    pub file: u32,
    pub offset: usize,
}

impl Place {
    /// The start of the main file: where things the file does not say are blamed.
    pub const START: Place = Place { file: 0, offset: 0 };
}

/// Why reading stopped: a message at a place of the files, or an error already made (a mesh file
/// that would not load, a file that could not be read).
#[derive(Debug)]
pub(super) enum Fail {
    At(Place, String),
    Scene(SceneError),
}

/// A shorthand for the many functions that fail at a place.
pub(super) type Res<T> = Result<T, Fail>;

/// `Err(Fail::At(at, message))`.
pub(super) fn fail<T>(at: Place, message: impl Into<String>) -> Res<T> {
    Err(Fail::At(at, message.into()))
}

/// One file of the scene.
pub(super) struct Source {
    /// How messages name it: the path as given, or as resolved from the including file.
    pub name: String,
    /// Where it is, for resolving the files it names (empty for text given in memory).
    pub path: PathBuf,
    pub text: Arc<String>,
    /// The `Include` or `Import` that named it.
    pub from: Option<Place>,
}

/// Every file read so far, in the order they were first read.
#[derive(Default)]
pub(super) struct Sources {
    files: Vec<Source>,
    total_bytes: u64,
}

impl Sources {
    /// Adds a file's text; returns its number.
    pub fn add(&mut self, name: String, path: PathBuf, text: String, from: Option<Place>) -> u32 {
        self.total_bytes += text.len() as u64;
        self.files.push(Source { name, path, text: Arc::new(text), from });
        (self.files.len() - 1) as u32
    }

    pub fn get(&self, file: u32) -> &Source {
        &self.files[file as usize]
    }

    /// Bytes read over all files so far.
    pub fn total_bytes(&self) -> u64 {
        self.total_bytes
    }

    /// `message` at `at`, with the line of text it points into.
    pub fn located(&self, at: Place, message: impl Into<String>) -> Located {
        let s = self.get(at.file);
        Located::at(&s.name, &s.text, Some(at.offset..at.offset), message)
    }

    /// `file:line:column` of `at`.
    pub fn show(&self, at: Place) -> String {
        let l = self.located(at, "");
        format!("{}:{}:{}", l.file, l.line, l.column)
    }

    /// The scene error of a failure.
    pub fn error(&self, fail: Fail) -> SceneError {
        match fail {
            Fail::At(at, mut message) => {
                // Name the includes that led to the file, innermost first.
                let mut from = self.get(at.file).from;
                let mut depth = 0;
                while let Some(place) = from {
                    message.push_str(&format!("\n  included from {}", self.show(place)));
                    from = self.get(place.file).from;
                    depth += 1;
                    if depth > 64 {
                        break;
                    }
                }
                SceneError::Invalid(self.located(at, message))
            }
            Fail::Scene(e) => e,
        }
    }
}

/// The text of `path`, refusing directories, files over [`MAX_PBRT_FILE_BYTES`] (also while
/// reading, for devices and pipes), gzip-compressed files (which pbrt reads and englobe does not)
/// and text that is not UTF-8.
pub(super) fn read_text(path: &Path) -> std::io::Result<String> {
    let meta = std::fs::metadata(path)?;
    if meta.is_dir() {
        return Err(std::io::Error::other("is a directory, expected a pbrt file"));
    }
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gz")) {
        return Err(std::io::Error::other("gzip-compressed pbrt files are not supported: decompress it first"));
    }
    if meta.len() > MAX_PBRT_FILE_BYTES {
        return Err(std::io::Error::other(format!(
            "{} bytes is larger than the {MAX_PBRT_FILE_BYTES}-byte limit",
            meta.len()
        )));
    }
    let file = std::fs::File::open(path)?;
    let initial = if meta.is_file() { meta.len() as usize } else { 0 };
    let mut bytes = crate::mesh::read_at_most(file, initial, MAX_PBRT_FILE_BYTES + 1)?;
    if bytes.len() as u64 > MAX_PBRT_FILE_BYTES {
        return Err(std::io::Error::other(format!("the file is larger than the {MAX_PBRT_FILE_BYTES}-byte limit")));
    }
    if bytes.starts_with(b"\x1f\x8b") {
        return Err(std::io::Error::other("the file is gzip-compressed, which is not supported: decompress it first"));
    }
    if bytes.starts_with(b"\xEF\xBB\xBF") {
        bytes.drain(..3);
    }
    String::from_utf8(bytes).map_err(|e| {
        std::io::Error::other(format!("byte {}: the file is not valid UTF-8 text", e.utf8_error().valid_up_to()))
    })
}
