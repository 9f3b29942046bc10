//! What every loaded mesh goes through before shading: smooth normals for meshes without any
//! (within the scene's crease angle, see [`super::smooth_normals`]), then tangents for meshes
//! whose materials have normal maps and whose file gives none (see [`super::tangents`]), each
//! triangle's from the texture coordinate set its normal map reads.

use englobe::TriangleMesh;

use super::loaded::{LoadedMesh, NO_MATERIAL};
use super::smooth_normals::smooth_normals;
use super::tangents::{TangentUvs, generate_tangents};

/// How a mesh file is prepared for shading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshOptions {
    /// For meshes without normals: faces meeting at most at this angle (degrees, `0..=180`) are
    /// shaded smoothly across their shared vertices; 0 keeps flat faces.
    pub smooth_angle: f32,
    /// Generate tangents even if no material of the file has a normal map (the scene replaces
    /// the file's materials with one that has; a scene's materials read texture coordinate set
    /// 0, so these tangents follow set 0).
    pub want_tangents: bool,
}

/// Smoothing angle of meshes without normals unless the scene says otherwise: smooth enough for
/// curved surfaces tessellated into a few thousand triangles (the teapot's faces meet at 20
/// degrees and less), sharp enough that the edges of boxes, at 90 degrees, stay edges.
pub const DEFAULT_SMOOTH_ANGLE: f32 = 60.0;

impl Default for MeshOptions {
    fn default() -> Self {
        MeshOptions { smooth_angle: DEFAULT_SMOOTH_ANGLE, want_tangents: false }
    }
}

/// Applies `options` to `loaded`.
pub(super) fn prepare(loaded: &mut LoadedMesh, options: &MeshOptions) {
    if loaded.mesh.normals().is_none() && options.smooth_angle > 0.0 {
        smooth(loaded, options.smooth_angle.min(180.0));
    }
    let normal_mapped = |id: u32| {
        id != NO_MATERIAL && loaded.materials.get(id as usize).is_some_and(|(_, m)| m.textures.normal.is_some())
    };
    let needed = options.want_tangents
        || loaded.triangle_materials.as_ref().is_some_and(|ids| ids.iter().any(|&id| normal_mapped(id)));
    if needed && loaded.tangents.is_none() {
        let m = &loaded.mesh;
        // The set each triangle's normal map reads, as the renderer resolves it: set 1 where the
        // mesh has it, set 0 for everything else.
        let reads_set1 = |face: usize| {
            !options.want_tangents
                && m.uvs1().is_some()
                && loaded.triangle_materials.as_ref().and_then(|ids| ids.get(face)).is_some_and(|&id| {
                    id != NO_MATERIAL
                        && loaded
                            .materials
                            .get(id as usize)
                            .and_then(|(_, mat)| mat.textures.normal)
                            .is_some_and(|n| n.texture.uv_set == 1)
                })
        };
        let set_of_face = |face: usize| usize::from(reads_set1(face));
        let has_coordinates = m.uvs().is_some() || (0..m.len()).any(reads_set1);
        if has_coordinates {
            let uvs = TangentUvs { sets: [m.uvs(), m.uvs1()], set_of_face: &set_of_face };
            loaded.tangents = generate_tangents(m.positions(), m.normals(), uvs, m.triangles());
            if loaded.tangents.is_none() {
                loaded
                    .warnings
                    .push("MikkTSpace could not make tangents for this mesh: normal maps are not applied".into());
            }
        } else {
            loaded
                .warnings
                .push("normal maps need texture coordinates, which the mesh has not: they are not applied".into());
        }
    }
}

fn smooth(loaded: &mut LoadedMesh, angle: f32) {
    let m = &loaded.mesh;
    let s = smooth_normals(m.positions(), m.triangles(), angle);
    let pick = |i: &u32| *i as usize;
    let positions = s.source.iter().map(|i| m.positions()[pick(i)]).collect();
    let uvs = m.uvs().map(|uvs| s.source.iter().map(|i| uvs[pick(i)]).collect());
    let uvs1 = m.uvs1().map(|uvs| s.source.iter().map(|i| uvs[pick(i)]).collect());
    let tangents = loaded.tangents.as_ref().map(|t| s.source.iter().map(|i| t[pick(i)]).collect());
    // The new arrays are copies of checked ones, index for index, so the checks pass again.
    let rebuilt = TriangleMesh::new(positions, s.triangles).and_then(|mesh| mesh.with_normals(s.normals));
    let rebuilt = match (rebuilt, uvs) {
        (Ok(mesh), Some(uvs)) => mesh.with_uvs(uvs),
        (r, _) => r,
    };
    let rebuilt = match (rebuilt, uvs1) {
        (Ok(mesh), Some(uvs)) => mesh.with_uvs1(uvs),
        (r, _) => r,
    };
    match rebuilt {
        Ok(mesh) => {
            loaded.mesh = mesh;
            loaded.tangents = tangents;
        }
        Err(e) => loaded.warnings.push(format!("smooth normals could not be made ({e}); shading uses face normals")),
    }
}
