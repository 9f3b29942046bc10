//! Stanford PLY files (Turk 1994, "The PLY Polygon File Format"), read by englobe's own parser:
//! ASCII, binary little-endian and binary big-endian bodies; `\n` or `\r\n` header lines; any
//! elements and properties, of which englobe keeps the vertex positions (`x y z`), normals
//! (`nx ny nz`), texture coordinates (`u v`, `s t` or `texture_u texture_v`) and the face lists
//! (`vertex_indices` or `vertex_index`), fan- or ear-triangulated, or the triangle strips of a
//! `tristrips` element (older scanned-model archives store faces so). Everything else is skipped.
//! Texture coordinates follow OpenGL's convention in PLY (`v` up from the bottom of the image) and
//! are flipped to englobe's (`v = 1 - t`), as OBJ's are.
//!
//! Before anything is allocated, the counts the header declares are checked against the bytes
//! the file holds, so `element vertex 4294967295` in a 100-byte file is an error, not an attempt
//! at a 50 GB allocation.

use std::path::Path;

use super::build::{MeshParts, finish};
use super::error::MeshFileError;
use super::loaded::{LoadedMesh, MeshFormat};
use super::ply_body::read_body;
use super::ply_header::{check_sizes, parse_header};

/// Loads the PLY file `path` whose content is `bytes`.
pub(super) fn load(path: &Path, bytes: &[u8]) -> Result<LoadedMesh, MeshFileError> {
    let header = parse_header(path, bytes)?;
    check_sizes(path, &header, bytes.len() as u64)?;
    let body = read_body(path, &header, bytes)?;
    let uvs = body.uvs.map(|uvs| uvs.into_iter().map(|t| englobe::Vec2::new(t.x, 1.0 - t.y)).collect());
    let mut parts = MeshParts { positions: body.positions, normals: body.normals, uvs, ..Default::default() };
    let mut warnings = Vec::new();
    let mut concave = 0usize;
    let mut at = 0usize;
    parts.triangles.reserve(body.face_sizes.iter().map(|&n| n.saturating_sub(2) as usize).sum());
    for &n in &body.face_sizes {
        let face = &body.face_indices[at..at + n as usize];
        at += n as usize;
        concave += super::triangulate::triangulate(&parts.positions, face, &mut parts.triangles) as usize;
    }
    if body.short_faces > 0 {
        warnings.push(format!("skipped {} face(s) with fewer than 3 vertices", body.short_faces));
    }
    if concave > 0 {
        warnings.push(format!("{concave} concave polygon(s) triangulated by ear clipping"));
    }
    finish(path, MeshFormat::Ply, parts, (Vec::new(), Vec::new()), warnings)
}
