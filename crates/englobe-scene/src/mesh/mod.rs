//! Mesh files: OBJ (+ MTL) through `tobj`, PLY with englobe's own parser, glTF 2.0 with the
//! `gltf` crate's JSON model. Every loader is wrapped in englobe's own checks (see each module and
//! `build.rs`): a bad file is refused with an error naming the file and the line, byte or JSON path,
//! sizes are checked against the file before anything is allocated, and nothing here panics on a
//! file.

mod build;
pub mod error;
mod gltf;
mod gltf_data;
mod mtl;
mod obj;
mod obj_scan;
mod ply;
mod ply_body;
mod transform;
mod triangulate;

use std::path::Path;

use englobe::TriangleMesh;

pub use error::{MeshErrorKind, MeshFileError, Position};
pub use transform::bake_transform;

use crate::model::Material;

/// Largest mesh file read (whole, into memory).
pub const MAX_MESH_FILE_BYTES: u64 = 2 << 30;
/// Largest material library read.
pub const MAX_MTL_FILE_BYTES: u64 = 64 << 20;

/// Per-triangle material id meaning "the material of the object" (no material in the file).
pub const NO_MATERIAL: u32 = u32::MAX;

/// A material a mesh file defines, with its name in the file.
pub type NamedMaterial = (String, Material);

/// The formats englobe reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ, with MTL material libraries.
    Obj,
    /// Stanford PLY: ASCII, binary little-endian or binary big-endian.
    Ply,
    /// glTF 2.0 as JSON (`.gltf`) with buffers in files or data URIs.
    Gltf,
    /// glTF 2.0 binary container (`.glb`).
    Glb,
}

impl MeshFormat {
    /// The format a file name's extension (any case) names, if any.
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "obj" => MeshFormat::Obj,
            "ply" => MeshFormat::Ply,
            "gltf" => MeshFormat::Gltf,
            "glb" => MeshFormat::Glb,
            _ => return None,
        })
    }

    /// Its usual name.
    pub fn name(self) -> &'static str {
        match self {
            MeshFormat::Obj => "OBJ",
            MeshFormat::Ply => "PLY",
            MeshFormat::Gltf => "glTF",
            MeshFormat::Glb => "glTF (binary)",
        }
    }
}

/// A mesh read from a file and checked.
#[derive(Clone, Debug)]
pub struct LoadedMesh {
    /// The triangles, degenerate ones dropped.
    pub mesh: TriangleMesh,
    /// Materials the file defines (OBJ's MTL libraries, glTF's materials), in file order.
    pub materials: Vec<NamedMaterial>,
    /// For each triangle, an index into `materials` or [`NO_MATERIAL`]; `None` when no triangle
    /// has a material of its own.
    pub triangle_materials: Option<Vec<u32>>,
    /// What was skipped or repaired (dropped degenerate triangles, missing material libraries...).
    pub warnings: Vec<String>,
    /// The format it was read as.
    pub format: MeshFormat,
}

/// Reads and checks the mesh file `path`, choosing the format by its extension.
pub fn load_mesh_file(path: &Path) -> Result<LoadedMesh, MeshFileError> {
    check_file(path, MAX_MESH_FILE_BYTES)?;
    let Some(format) = MeshFormat::from_path(path) else {
        let ext = path.extension().map_or(String::new(), |e| e.to_string_lossy().into_owned());
        let kind = if ext.eq_ignore_ascii_case("mtl") {
            MeshErrorKind::NotAMesh(
                "a material library (MTL), not a mesh: it is read through the OBJ file that names it".into(),
            )
        } else if ext.eq_ignore_ascii_case("bin") {
            MeshErrorKind::NotAMesh("a glTF buffer, not a mesh: it is read through the .gltf file that names it".into())
        } else {
            MeshErrorKind::UnknownFormat(if ext.is_empty() { "(no extension)".into() } else { format!(".{ext}") })
        };
        return Err(MeshFileError::file(path, kind));
    };
    let bytes = read_limited(path, MAX_MESH_FILE_BYTES)?;
    load_mesh_bytes(path, format, bytes)
}

/// Reads and checks a mesh already in memory. `path` names it in errors, and files it refers to
/// (an OBJ's material libraries, a glTF's buffers) are looked for beside it.
pub fn load_mesh_bytes(path: &Path, format: MeshFormat, bytes: Vec<u8>) -> Result<LoadedMesh, MeshFileError> {
    match format {
        MeshFormat::Obj => obj::load(path, bytes),
        MeshFormat::Ply => ply::load(path, &bytes),
        MeshFormat::Gltf | MeshFormat::Glb => gltf::load(path, &bytes, format),
    }
}

/// Refuses a `path` that does not exist, is a directory or is over `limit` bytes.
fn check_file(path: &Path, limit: u64) -> Result<(), MeshFileError> {
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
