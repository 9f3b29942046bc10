//! Per-vertex tangents for normal mapping, generated with MikkTSpace (Mikkelsen 2008, "Simulation
//! of wrinkled surfaces revisited"), the algorithm glTF 2.0 prescribes when a file has no
//! `TANGENT` attribute (section 3.7.2.1) and the one Blender bakes normal maps with.
//!
//! MikkTSpace expects OpenGL's texture coordinates (`v` up); englobe's point `v` down, so it is
//! given `(u, 1 - v)`. The tangent then points along increasing `u` and `w * cross(n, t)` towards
//! the top of the image, which is what a normal map's green channel means. The algorithm writes
//! one tangent per triangle corner; corners sharing a vertex share its position, normal and
//! coordinates and so get the same tangent, which is kept per vertex.
//!
//! glTF ties tangents to the normal texture's coordinates (section 3.7.2.1), and a normal texture
//! may read the second set (`texCoord: 1`): each triangle is given the coordinates of the set its
//! own normal map reads. Triangles of different materials share no vertex in a glTF file (each
//! primitive has its own), so no vertex mixes the two sets.

use englobe::{Vec2, Vec3};
use glam::Vec4;

/// The texture coordinates tangents follow: sets 0 and 1 as the mesh has them, and the set each
/// triangle's normal map reads (a set the mesh lacks gives `(0, 0)`, a degenerate mapping whose
/// tangents are never used: without coordinates no normal map is read there).
pub(super) struct TangentUvs<'a> {
    pub sets: [Option<&'a [Vec2]>; 2],
    pub set_of_face: &'a dyn Fn(usize) -> usize,
}

struct Geometry<'a> {
    positions: &'a [Vec3],
    normals: Option<&'a [Vec3]>,
    uvs: TangentUvs<'a>,
    triangles: &'a [[u32; 3]],
    sum: Vec<Vec3>,
    sign: Vec<f32>,
}

impl Geometry<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.triangles[face][vert] as usize
    }
}

impl mikktspace::Geometry for Geometry<'_> {
    fn num_faces(&self) -> usize {
        self.triangles.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[self.vertex(face, vert)].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        match self.normals {
            Some(n) => n[self.vertex(face, vert)].to_array(),
            None => {
                let [a, b, c] = self.triangles[face].map(|i| self.positions[i as usize]);
                (b - a).cross(c - a).normalize_or_zero().to_array()
            }
        }
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let set = (self.uvs.set_of_face)(face).min(1);
        let uv = self.uvs.sets[set].map_or(Vec2::ZERO, |uvs| uvs[self.vertex(face, vert)]);
        [uv.x, 1.0 - uv.y]
    }

    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
        let v = self.vertex(face, vert);
        self.sum[v] += Vec3::new(tangent[0], tangent[1], tangent[2]);
        if self.sign[v] == 0.0 {
            self.sign[v] = if tangent[3] < 0.0 { -1.0 } else { 1.0 };
        }
    }
}

/// One tangent per vertex, or `None` if MikkTSpace gives up on the mesh. Without `normals`,
/// the face normals stand in (the renderer then orthogonalises against what it shades with).
pub(super) fn generate_tangents(
    positions: &[Vec3],
    normals: Option<&[Vec3]>,
    uvs: TangentUvs,
    triangles: &[[u32; 3]],
) -> Option<Vec<Vec4>> {
    let n = positions.len();
    let mut g = Geometry { positions, normals, uvs, triangles, sum: vec![Vec3::ZERO; n], sign: vec![0.0; n] };
    // The algorithm is a translation of C; a panic of its own is a failure, not a crash.
    let ok = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| mikktspace::generate_tangents(&mut g))).ok()?;
    if !ok {
        return None;
    }
    Some(
        (0..n)
            .map(|v| {
                // MikkTSpace leaves a default (1, 0, 0) where the texture mapping is degenerate:
                // made perpendicular to the normal like the others.
                let t = match normals.and_then(|ns| ns[v].try_normalize()) {
                    Some(n) => {
                        (g.sum[v] - n * n.dot(g.sum[v])).try_normalize().unwrap_or_else(|| n.any_orthonormal_vector())
                    }
                    None => g.sum[v].try_normalize().unwrap_or(Vec3::X),
                };
                t.extend(if g.sign[v] < 0.0 { -1.0 } else { 1.0 })
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Set 0 only.
    fn set0(uvs: &[Vec2]) -> TangentUvs<'_> {
        TangentUvs { sets: [Some(uvs), None], set_of_face: &|_| 0 }
    }

    #[test]
    fn a_quad_mapped_upright_has_tangent_x_and_bitangent_up() {
        // The xy square facing +z, the image upright on it: u along +x, v (down the image) along -y.
        let positions = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let uvs = [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];
        let normals = [Vec3::Z; 4];
        let t = generate_tangents(&positions, Some(&normals), set0(&uvs), &[[0, 1, 2], [0, 2, 3]]).unwrap();
        for tangent in &t {
            assert!((tangent.truncate() - Vec3::X).length() < 1e-5, "{tangent}");
            // The bitangent w * cross(n, t) = +y: towards the top of the image.
            assert_eq!(tangent.w, 1.0);
        }
        // Mirrored along u (u along -x): the tangent turns and the handedness flips, so the
        // bitangent still points up the image.
        let mirrored: Vec<Vec2> = uvs.iter().map(|uv| Vec2::new(1.0 - uv.x, uv.y)).collect();
        let t = generate_tangents(&positions, Some(&normals), set0(&mirrored), &[[0, 1, 2], [0, 2, 3]]).unwrap();
        for tangent in &t {
            assert!((tangent.truncate() + Vec3::X).length() < 1e-5, "{tangent}");
            let bitangent = tangent.w * Vec3::Z.cross(tangent.truncate());
            assert!((bitangent - Vec3::Y).length() < 1e-5, "{bitangent}");
        }
    }

    #[test]
    fn each_triangle_follows_the_set_its_normal_map_reads() {
        // Two separate triangles facing +z; set 0 runs u along +x on both, set 1 along +y. The
        // second triangle's normal map reads set 1: its tangent turns to +y.
        let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ZERO, Vec3::X, Vec3::Y];
        let normals = [Vec3::Z; 6];
        let uv0: Vec<Vec2> = positions.iter().map(|p| Vec2::new(p.x, 1.0 - p.y)).collect();
        let uv1: Vec<Vec2> = positions.iter().map(|p| Vec2::new(p.y, p.x)).collect();
        let uvs = TangentUvs { sets: [Some(&uv0), Some(&uv1)], set_of_face: &|face| face };
        let t = generate_tangents(&positions, Some(&normals), uvs, &[[0, 1, 2], [3, 4, 5]]).unwrap();
        for tangent in &t[..3] {
            assert!((tangent.truncate() - Vec3::X).length() < 1e-5, "{tangent}");
        }
        for tangent in &t[3..] {
            assert!((tangent.truncate() - Vec3::Y).length() < 1e-5, "{tangent}");
        }
    }
}
