//! Reading a mesh file safely: the file checked (it exists, is not a directory, is within its size
//! limit) before it is read whole, text without its byte-order mark, and third-party parsers run
//! so that a panic of theirs is an error naming the file.

use std::path::Path;

use super::error::{MeshErrorKind, MeshFileError};

/// Refuses a `path` that does not exist, is a directory or is over `limit` bytes.
pub(super) fn check_file(path: &Path, limit: u64) -> Result<(), MeshFileError> {
    let io = |e| MeshFileError::file(path, MeshErrorKind::Io(e));
    let meta = std::fs::metadata(path).map_err(io)?;
    if meta.is_dir() {
        return Err(io(std::io::Error::other("it is a directory, not a file")));
    }
    if meta.len() > limit {
        return Err(MeshFileError::file(path, MeshErrorKind::FileTooLarge { bytes: meta.len(), limit }));
    }
    Ok(())
}

/// The bytes of `path`, refusing directories and files over `limit` bytes before reading.
pub(crate) fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, MeshFileError> {
    check_file(path, limit)?;
    std::fs::read(path).map_err(|e| MeshFileError::file(path, MeshErrorKind::Io(e)))
}

/// `bytes` as UTF-8 text without its byte-order mark, if any (which would otherwise hide the
/// first statement), or an error at the first invalid byte.
pub(crate) fn utf8_text(path: &Path, mut bytes: Vec<u8>) -> Result<String, MeshFileError> {
    const BOM: &[u8] = b"\xEF\xBB\xBF";
    let skipped = if bytes.starts_with(BOM) { bytes.drain(..BOM.len()).count() as u64 } else { 0 };
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to() as u64 + skipped;
        MeshFileError::byte(path, at, MeshErrorKind::Malformed("the file is not valid UTF-8 text".into()))
    })
}

/// Runs a third-party parser, turning a panic into an error: englobe checks inputs before handing
/// them over, so this only guards against the parser's own bugs.
pub(crate) fn guarded<T>(path: &Path, parser: &str, f: impl FnOnce() -> T) -> Result<T, MeshFileError> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).map_err(|_| {
        MeshFileError::file(path, MeshErrorKind::Parser(format!("the {parser} parser failed on this file")))
    })
}
