//! Reading a mesh file safely: the file checked (it exists, is not a directory, is within its size
//! limit) before it is read whole, text without its byte-order mark, and third-party parsers run
//! so that a panic of theirs is an error naming the file. The size limit also holds while reading,
//! because a device or a pipe (`/dev/zero`, `<(...)`) has no size to check beforehand.

use std::io::Read;
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

/// The bytes of `path`, refusing directories and files over `limit` bytes before reading, and
/// stopping at `limit + 1` bytes whatever the file is.
pub(crate) fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, MeshFileError> {
    check_file(path, limit)?;
    let io = |e| MeshFileError::file(path, MeshErrorKind::Io(e));
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    let initial = if meta.is_file() { meta.len().min(limit) as usize + 1 } else { 0 };
    let bytes = read_at_most(file, initial, limit + 1).map_err(io)?;
    if bytes.len() as u64 > limit {
        let kind = if meta.is_file() {
            MeshErrorKind::FileTooLarge { bytes: meta.len().max(bytes.len() as u64), limit }
        } else {
            MeshErrorKind::StreamTooLarge { limit }
        };
        return Err(MeshFileError::file(path, kind));
    }
    Ok(bytes)
}

/// At most `most` bytes of `reader`, in a buffer that never grows past `most` (`read_to_end`
/// doubles its buffer, which would double the memory a file at the limit takes).
pub(crate) fn read_at_most(reader: impl Read, initial: usize, most: u64) -> std::io::Result<Vec<u8>> {
    let most = usize::try_from(most).unwrap_or(usize::MAX);
    let mut reader = reader.take(most as u64);
    let mut bytes = Vec::with_capacity(initial.min(most));
    let mut chunk = vec![0; 1 << 16];
    loop {
        let n = match reader.read(&mut chunk) {
            Ok(0) => return Ok(bytes),
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if bytes.len() + n > bytes.capacity() {
            let target = (bytes.capacity() * 2).max(bytes.len() + n).min(most);
            bytes.reserve_exact(target - bytes.len());
        }
        bytes.extend_from_slice(&chunk[..n]);
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(unix)]
    #[test]
    fn an_endless_device_stops_at_the_limit() {
        let e = read_limited(Path::new("/dev/zero"), 1 << 16).unwrap_err();
        assert!(matches!(e.kind, MeshErrorKind::StreamTooLarge { limit: 65536 }), "{e}");
    }
}
