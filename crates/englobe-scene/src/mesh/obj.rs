//! Wavefront OBJ files through `tobj`, behind englobe's own checks: the file is scanned line by
//! line first ([`super::obj_scan`]), material libraries too ([`super::mtl`]), so `tobj` only ever
//! sees what it handles; its output then goes through the common checks of [`super::build`].
//!
//! All groups and objects of the file become one mesh, each triangle keeping its material.
//! Polygons are triangulated by englobe ([`super::triangulate`]): `tobj`'s fan would cover the
//! notches of concave faces. Texture coordinates are flipped to englobe's convention (`v` down
//! from the top of the image: `v = 1 - vt`), and materials are mapped by [`super::mtl_material`].

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use englobe::{Vec2, Vec3};

use super::build::{MeshParts, finish};
use super::error::{MeshErrorKind, MeshFileError};
use super::loaded::{LoadedMesh, MAX_MTL_FILE_BYTES, MeshFormat, NO_MATERIAL};
use super::mtl_map::MapStatement;
use super::mtl_material::{MtlTextures, to_material};
use super::read::{guarded, read_limited, utf8_text};
use super::triangulate::triangulate;
use super::{mtl, obj_scan};

/// Material libraries read while `tobj` parses, and what went wrong with them.
#[derive(Default)]
struct Libraries {
    error: Option<MeshFileError>,
    warnings: Vec<String>,
    /// Each material's texture statements and the folder of its library.
    maps: HashMap<String, (PathBuf, Vec<(String, MapStatement)>)>,
}

/// Loads the OBJ file `path` whose content is `bytes`.
pub(super) fn load(path: &Path, bytes: Vec<u8>) -> Result<LoadedMesh, MeshFileError> {
    let mut text = utf8_text(path, bytes)?;
    let scan = obj_scan::scan(path, &text)?;
    let mut warnings = scan.warnings.clone();
    if !scan.polyline_lines.is_empty() {
        // `tobj` reads `l a b c` as a triangle: turn polylines into comments, line count kept.
        text = hide_lines(&text, &scan.polyline_lines);
    }
    if scan.lines_and_points + scan.short_faces > 0 {
        warnings.push(format!(
            "skipped {} point and line element(s): englobe renders surfaces",
            scan.lines_and_points + scan.short_faces
        ));
    }

    if scan.faces == 0 {
        let why = match scan.lines_and_points + scan.short_faces {
            0 => ": the file has no faces".to_owned(),
            n => format!(": the file has no faces, only {n} point and line element(s), which englobe skips"),
        };
        return Err(MeshFileError::file(path, MeshErrorKind::NoTriangles(why)));
    }
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let libraries = RefCell::new(Libraries::default());
    let options = tobj::LoadOptions { single_index: true, triangulate: false, ignore_points: true, ignore_lines: true };
    let parsed = guarded(path, "OBJ", || {
        tobj::load_obj_buf(&mut text.as_bytes(), &options, |p| load_library(&dir, p, &libraries))
    })?;
    let libraries = libraries.into_inner();
    if let Some(e) = libraries.error {
        return Err(e);
    }
    warnings.extend(libraries.warnings.iter().cloned());
    let (models, materials) =
        parsed.map_err(|e| MeshFileError::file(path, MeshErrorKind::Parser(format!("tobj: {e}"))))?;
    let mut textures = MtlTextures::default();
    let materials: Vec<_> = materials
        .unwrap_or_default()
        .iter()
        .map(|m| {
            let (dir, maps) =
                libraries.maps.get(&m.name).map_or((dir.as_path(), &[][..]), |(d, s)| (d.as_path(), s.as_slice()));
            (m.name.clone(), to_material(m, maps, dir, &mut textures))
        })
        .collect();
    warnings.append(&mut textures.warnings);
    let undefined: Vec<&str> =
        scan.used_materials.iter().filter(|u| !materials.iter().any(|(n, _)| n == *u)).map(String::as_str).collect();
    if !undefined.is_empty() {
        warnings.push(format!(
            "material(s) used but defined in no material library, replaced by the default: {}",
            undefined.join(", ")
        ));
    }

    let mut parts = MeshParts::default();
    let (mut normals, mut uvs) = (Vec::new(), Vec::new());
    let (mut all_normals, mut all_uvs) = (true, true);
    let mut ids = Vec::new();
    let mut concave = 0usize;
    for model in &models {
        let m = &model.mesh;
        let base = parts.positions.len() as u32;
        let count = m.positions.len() / 3;
        parts.positions.extend(m.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])));
        all_normals &= m.normals.len() == 3 * count;
        all_uvs &= m.texcoords.len() == 2 * count;
        if all_normals {
            normals.extend(m.normals.chunks_exact(3).map(|n| Vec3::new(n[0], n[1], n[2])));
        }
        if all_uvs {
            uvs.extend(m.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], 1.0 - t[1])));
        }
        let material = m.material_id.map_or(NO_MATERIAL, |id| id as u32);
        let before = parts.triangles.len();
        if m.indices.iter().any(|&i| i as usize >= count) {
            return Err(MeshFileError::file(
                path,
                MeshErrorKind::Parser(format!("tobj returned an index out of range in `{}`", model.name)),
            ));
        }
        let shifted: Vec<u32> = m.indices.iter().map(|&i| i + base).collect();
        if m.face_arities.is_empty() {
            parts.triangles.extend(shifted.chunks_exact(3).map(|t| [t[0], t[1], t[2]]));
        } else {
            let mut at = 0usize;
            for &arity in &m.face_arities {
                let Some(face) = shifted.get(at..at + arity as usize) else { break };
                concave += triangulate(&parts.positions, face, &mut parts.triangles) as usize;
                at += arity as usize;
            }
        }
        ids.resize(ids.len() + parts.triangles.len() - before, material);
    }
    if concave > 0 {
        warnings.push(format!("{concave} concave polygon(s) triangulated by ear clipping"));
    }
    let with_normals = models.iter().filter(|m| !m.mesh.normals.is_empty()).count();
    if !all_normals && with_normals > 0 {
        warnings.push("normals are given for some vertices only; shading uses face normals".into());
    }
    parts.normals = (all_normals && !normals.is_empty()).then_some(normals);
    parts.uvs = (all_uvs && !uvs.is_empty()).then_some(uvs);
    parts.triangle_materials = Some(ids);
    finish(path, MeshFormat::Obj, parts, (materials, textures.textures), warnings)
}

/// The text with the given (0-based) lines replaced by comments.
fn hide_lines(text: &str, lines: &[usize]) -> String {
    let mut out = String::with_capacity(text.len());
    let mut next = lines.iter().peekable();
    for (i, line) in text.split_inclusive('\n').enumerate() {
        if next.peek() == Some(&&i) {
            next.next();
            out.push_str("# (line element)\n");
        } else {
            out.push_str(line);
        }
    }
    out
}

/// The material loader handed to `tobj` for an `mtllib` statement naming `name`. A missing
/// library is a warning (the mesh still renders, with the default material); a library that
/// exists but is broken is an error, kept in `state` and reported once `tobj` returns.
fn load_library(dir: &Path, name: &Path, state: &RefCell<Libraries>) -> tobj::MTLLoadResult {
    let whole = dir.join(name);
    // `mtllib a.mtl b.mtl` names two libraries; `tobj` passes the whole rest of the line, since a
    // single name may hold spaces.
    let files: Vec<PathBuf> = if whole.is_file() {
        vec![whole]
    } else {
        split_names(&name.to_string_lossy()).iter().map(|n| dir.join(n)).collect()
    };
    let mut materials = Vec::new();
    let mut map = HashMap::new();
    for file in files {
        if !file.is_file() {
            state.borrow_mut().warnings.push(format!(
                "material library {} not found; its materials are replaced by the default",
                file.display()
            ));
            continue;
        }
        match read_library(&file) {
            Ok((mats, names, maps, warnings)) => {
                state.borrow_mut().warnings.extend(warnings);
                let offset = materials.len();
                materials.extend(mats);
                map.extend(names.into_iter().map(|(n, i)| (n, i + offset)));
                let folder = file.parent().map(Path::to_path_buf).unwrap_or_default();
                state.borrow_mut().maps.extend(maps.into_iter().map(|(n, s)| (n, (folder.clone(), s))));
            }
            Err(e) => {
                let mut s = state.borrow_mut();
                s.error.get_or_insert(e);
                return Err(tobj::LoadError::MaterialParseError);
            }
        }
    }
    Ok((materials, map))
}

/// Library names separated by spaces, where `\ ` is a space inside a name.
fn split_names(list: &str) -> Vec<String> {
    let mut names = vec![String::new()];
    let mut chars = list.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if chars.peek().is_some_and(|n| n.is_whitespace()) => {
                names.last_mut().unwrap().push(chars.next().unwrap())
            }
            c if c.is_whitespace() => {
                if !names.last().unwrap().is_empty() {
                    names.push(String::new());
                }
            }
            c => names.last_mut().unwrap().push(c),
        }
    }
    names.retain(|n| !n.is_empty());
    names
}

type Library = (Vec<tobj::Material>, HashMap<String, usize>, mtl::MtlMaps, Vec<String>);

fn read_library(file: &Path) -> Result<Library, MeshFileError> {
    let text = utf8_text(file, read_limited(file, MAX_MTL_FILE_BYTES)?)?;
    let scan = mtl::scan(file, &text)?;
    let (materials, names) = guarded(file, "MTL", || tobj::load_mtl_buf(&mut scan.text.as_bytes()))?
        .map_err(|e| MeshFileError::file(file, MeshErrorKind::Parser(format!("tobj: {e}"))))?;
    Ok((materials, names, scan.maps, scan.warnings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn library_lists_allow_escaped_spaces() {
        assert_eq!(split_names("a.mtl  b\\ c.mtl d"), vec!["a.mtl", "b c.mtl", "d"]);
    }
}
