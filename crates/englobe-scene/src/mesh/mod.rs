//! Mesh files: OBJ (+ MTL) through `tobj`, PLY with englobe's own parser, glTF 2.0 with the
//! `gltf` crate's JSON model. Every loader is wrapped in englobe's own checks (see each module and
//! `build.rs`): a bad file is refused with an error naming the file and the line, byte or JSON path,
//! sizes are checked against the file before anything is allocated, and nothing here panics on a
//! file.

mod build;
pub mod error;
mod gltf;
mod gltf_data;
mod gltf_material;
mod loaded;
mod mtl;
mod mtl_color;
mod mtl_map;
mod mtl_material;
mod obj;
mod obj_scan;
mod ply;
mod ply_body;
mod ply_header;
mod prepare;
mod read;
mod smooth_normals;
mod tangents;
mod transform;
mod triangulate;

use std::path::Path;

pub use error::{MeshErrorKind, MeshFileError, Position};
pub use loaded::{LoadedMesh, MAX_MESH_FILE_BYTES, MAX_MTL_FILE_BYTES, MeshFormat, NO_MATERIAL, NamedMaterial};
pub use prepare::{DEFAULT_SMOOTH_ANGLE, MeshOptions};
pub use transform::{bake_transform, transform_tangents};

use read::check_file;
pub(crate) use read::{guarded, read_at_most, read_limited};

/// Reads and checks the mesh file `path`, choosing the format by its extension, and prepares it
/// for shading with the default [`MeshOptions`].
pub fn load_mesh_file(path: &Path) -> Result<LoadedMesh, MeshFileError> {
    load_mesh_file_with(path, &MeshOptions::default())
}

/// [`load_mesh_file`] with `options`: smooth normals for meshes without any, tangents for normal
/// maps.
pub fn load_mesh_file_with(path: &Path, options: &MeshOptions) -> Result<LoadedMesh, MeshFileError> {
    let mut loaded = read_mesh_file(path)?;
    prepare::prepare(&mut loaded, options);
    Ok(loaded)
}

fn read_mesh_file(path: &Path) -> Result<LoadedMesh, MeshFileError> {
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

/// Checks the text of an MTL material library as OBJ loading does (every statement, texture
/// statements and their options included, then `tobj`'s parse of the text as englobe rewrites
/// it, then each material's mapping onto englobe's materials), without reading the textures;
/// `path` names it in errors.
pub fn check_mtl_text(path: &Path, text: &str) -> Result<(), MeshFileError> {
    let scan = mtl::scan(path, text)?;
    let (materials, _) = read::guarded(path, "MTL", || tobj::load_mtl_buf(&mut scan.text.as_bytes()))?
        .map_err(|e| MeshFileError::file(path, MeshErrorKind::Parser(format!("tobj: {e}"))))?;
    // The numbers of every material through the same mapping as a loaded OBJ's (no texture
    // statement is passed, so no file is read).
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut textures = mtl_material::MtlTextures::default();
    for m in &materials {
        mtl_material::to_material(m, &[], dir, &mut textures);
    }
    Ok(())
}

/// Reads and checks a mesh already in memory, as it is in the file (no normals or tangents
/// generated). `path` names it in errors, and files it refers to (an OBJ's material libraries,
/// a glTF's buffers and images) are looked for beside it.
pub fn load_mesh_bytes(path: &Path, format: MeshFormat, bytes: Vec<u8>) -> Result<LoadedMesh, MeshFileError> {
    match format {
        MeshFormat::Obj => obj::load(path, bytes),
        MeshFormat::Ply => ply::load(path, &bytes),
        MeshFormat::Gltf | MeshFormat::Glb => gltf::load(path, &bytes, format),
    }
}
