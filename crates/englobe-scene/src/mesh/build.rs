//! The checks every loader's output goes through, whatever parsed it: indices in range, finite
//! coordinates, attributes with one entry per vertex; degenerate triangles dropped and counted.
//! Loaders check as they read, with line or byte positions; this is the backstop that makes
//! sure nothing a third-party parser returns can reach the renderer unchecked.

use std::path::Path;

use std::sync::Arc;

use englobe::{TriangleMesh, Vec2, Vec3};
use glam::Vec4;

use super::error::{MeshErrorKind, MeshFileError};
use super::loaded::{LoadedMesh, MeshFormat, NO_MATERIAL, NamedMaterial};
use crate::texture::Texture;

/// A mesh as a loader produced it, before the common checks.
#[derive(Debug, Default)]
pub(super) struct MeshParts {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    /// The second texture coordinate set (glTF's `TEXCOORD_1`), when a material samples it.
    pub uvs1: Option<Vec<Vec2>>,
    pub tangents: Option<Vec<Vec4>>,
    /// One per triangle, indexing the materials or [`NO_MATERIAL`].
    pub triangle_materials: Option<Vec<u32>>,
}

/// Checks `parts` and makes the mesh of `path`.
pub(super) fn finish(
    path: &Path,
    format: MeshFormat,
    mut parts: MeshParts,
    (materials, textures): (Vec<NamedMaterial>, Vec<Arc<Texture>>),
    mut warnings: Vec<String>,
) -> Result<LoadedMesh, MeshFileError> {
    let file_err = |kind| MeshFileError::file(path, kind);
    let vertices = parts.positions.len();
    if let Some((i, p)) = parts.positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
        return Err(file_err(MeshErrorKind::NonFinite { what: format!("vertex {i}"), value: p.to_string() }));
    }
    if let Some((t, &index)) = parts
        .triangles
        .iter()
        .enumerate()
        .find_map(|(t, tri)| tri.iter().find(|&&i| i as usize >= vertices).map(|i| (t, i)))
    {
        return Err(file_err(MeshErrorKind::IndexOutOfRange {
            what: "vertex",
            index: format!("{index} (triangle {t})"),
            available: vertices as u64,
            context: "",
        }));
    }
    if let Some(ids) = &parts.triangle_materials {
        let bad = ids.len() != parts.triangles.len()
            || ids.iter().any(|&m| m != NO_MATERIAL && m as usize >= materials.len());
        if bad {
            warnings.push("per-triangle materials are inconsistent; the default material is used".into());
            parts.triangle_materials = None;
        }
    }
    if let Some(n) = &parts.normals {
        if n.len() != vertices {
            warnings.push(format!("{} normals for {vertices} vertices; shading uses face normals", n.len()));
            parts.normals = None;
        } else if n.iter().any(|v| !v.is_finite()) {
            warnings.push("some normals are not finite; shading uses face normals".into());
            parts.normals = None;
        }
    }
    for (set, uvs) in [&mut parts.uvs, &mut parts.uvs1].into_iter().enumerate() {
        if let Some(uv) = uvs {
            if uv.len() != vertices || uv.iter().any(|v| !v.is_finite()) {
                let which = if set == 0 { String::new() } else { format!(" (set {set})") };
                warnings
                    .push(format!("{} texture coordinates{which} for {vertices} vertices; they are dropped", uv.len()));
                *uvs = None;
            }
        }
    }

    if let Some(t) = &parts.tangents {
        if t.len() != vertices || t.iter().any(|v| !v.is_finite()) {
            warnings.push(format!("{} tangents for {vertices} vertices; they are dropped", t.len()));
            parts.tangents = None;
        }
    }

    let dropped = drop_degenerate(&parts.positions, &mut parts.triangles, parts.triangle_materials.as_mut());
    if dropped > 0 {
        warnings
            .push(format!("dropped {dropped} degenerate triangle{} (zero area)", if dropped == 1 { "" } else { "s" }));
    }
    if parts.triangles.is_empty() {
        let why = if dropped > 0 { " left once the degenerate ones are dropped" } else { "" };
        return Err(file_err(MeshErrorKind::NoTriangles(why.into())));
    }
    if parts.triangle_materials.as_ref().is_some_and(|ids| ids.iter().all(|&m| m == NO_MATERIAL)) {
        parts.triangle_materials = None;
    }

    let to_err = |e: englobe::shapes::MeshError| file_err(MeshErrorKind::Malformed(e.to_string()));
    let mut mesh = TriangleMesh::new(parts.positions, parts.triangles).map_err(to_err)?;
    if let Some(n) = parts.normals {
        mesh = mesh.with_normals(n).map_err(to_err)?;
    }
    if let Some(uv) = parts.uvs {
        mesh = mesh.with_uvs(uv).map_err(to_err)?;
    }
    if let Some(uv) = parts.uvs1 {
        mesh = mesh.with_uvs1(uv).map_err(to_err)?;
    }
    Ok(LoadedMesh {
        mesh,
        materials,
        textures,
        tangents: parts.tangents,
        triangle_materials: parts.triangle_materials,
        warnings,
        format,
    })
}

/// Removes the triangles of zero area (two equal indices, or three points on one line as
/// [`englobe::shapes::is_degenerate`] decides it), and their materials. Returns how many were removed.
pub(super) fn drop_degenerate(
    positions: &[Vec3],
    triangles: &mut Vec<[u32; 3]>,
    materials: Option<&mut Vec<u32>>,
) -> usize {
    let degenerate = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || englobe::shapes::is_degenerate(a, b, c)
    };
    let before = triangles.len();
    match materials {
        Some(ids) => {
            let mut keep = 0;
            for i in 0..triangles.len() {
                if !degenerate(&triangles[i]) {
                    triangles[keep] = triangles[i];
                    ids[keep] = ids[i];
                    keep += 1;
                }
            }
            triangles.truncate(keep);
            ids.truncate(keep);
        }
        None => triangles.retain(|t| !degenerate(t)),
    }
    before - triangles.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parts(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> MeshParts {
        MeshParts { positions, triangles, ..Default::default() }
    }

    #[test]
    fn degenerate_triangles_are_dropped_and_counted() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::X * 2.0];
        let mut m = parts(p, vec![[0, 1, 2], [0, 1, 3], [1, 1, 2], [2, 1, 0]]);
        m.triangle_materials = Some(vec![0, 1, 2, 3]);
        let mats = (0..4).map(|i| (i.to_string(), Default::default())).collect();
        let loaded = finish(Path::new("m"), MeshFormat::Obj, m, (mats, vec![]), vec![]).unwrap();
        assert_eq!(loaded.mesh.triangles(), &[[0, 1, 2], [2, 1, 0]]);
        assert_eq!(loaded.triangle_materials, Some(vec![0, 3]));
        assert_eq!(loaded.warnings, vec!["dropped 2 degenerate triangles (zero area)".to_owned()]);
    }

    #[test]
    fn nothing_unchecked_gets_through() {
        let nan = parts(vec![Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
        assert!(matches!(
            finish(Path::new("m"), MeshFormat::Obj, nan, (vec![], vec![]), vec![]).unwrap_err().kind,
            MeshErrorKind::NonFinite { .. }
        ));
        let far = parts(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 3]]);
        assert!(matches!(
            finish(Path::new("m"), MeshFormat::Obj, far, (vec![], vec![]), vec![]).unwrap_err().kind,
            MeshErrorKind::IndexOutOfRange { .. }
        ));
        let flat = parts(vec![Vec3::ZERO, Vec3::X, Vec3::X * 3.0], vec![[0, 1, 2]]);
        assert!(matches!(
            finish(Path::new("m"), MeshFormat::Obj, flat, (vec![], vec![]), vec![]).unwrap_err().kind,
            MeshErrorKind::NoTriangles(_)
        ));
        let mut short = parts(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
        short.normals = Some(vec![Vec3::Z]);
        let loaded = finish(Path::new("m"), MeshFormat::Obj, short, (vec![], vec![]), vec![]).unwrap();
        assert!(loaded.mesh.normals().is_none() && loaded.warnings.len() == 1);
    }
}
