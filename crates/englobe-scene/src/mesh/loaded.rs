//! What the loaders return and the limits they read within: the formats, the checked mesh with
//! its materials and warnings, the "no material of its own" id, and the largest files read.

use std::path::Path;

use std::sync::Arc;

use englobe::TriangleMesh;
use glam::Vec4;

use crate::model::Material;
use crate::texture::Texture;

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
    /// Materials the file defines (OBJ's MTL libraries, glTF's materials), in file order; their
    /// texture references index `textures`.
    pub materials: Vec<NamedMaterial>,
    /// Textures the materials use (those that could not be read included, without an image).
    pub textures: Vec<Arc<Texture>>,
    /// One tangent per vertex (see [`crate::SceneObject::tangents`] for the convention), from
    /// the file or generated for normal maps.
    pub tangents: Option<Vec<Vec4>>,
    /// For each triangle, an index into `materials` or [`NO_MATERIAL`]; `None` when no triangle
    /// has a material of its own.
    pub triangle_materials: Option<Vec<u32>>,
    /// What was skipped or repaired (dropped degenerate triangles, missing material libraries...).
    pub warnings: Vec<String>,
    /// The format it was read as.
    pub format: MeshFormat,
}
