//! Indexed triangle meshes: one vertex array shared by many triangles, each triangle a primitive
//! of its own for the acceleration structures.

use glam::{Vec2, Vec3};

use super::Triangle;
use super::triangle::{WatertightRay, intersect_triangle};
use crate::PrimHit;
use crate::geom::prefetch::prefetch;
use crate::{Aabb, Ray};

/// Why a mesh was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {index}, but the mesh has {vertices} vertices")]
    IndexOutOfRange {
        /// Triangle number.
        triangle: usize,
        /// The bad index.
        index: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// A vertex position is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate: {position:?}")]
    NonFiniteVertex {
        /// Vertex number.
        vertex: usize,
        /// Its position.
        position: Vec3,
    },
    /// A per-vertex attribute array does not have one entry per vertex.
    #[error("{attribute} has {got} entries for {vertices} vertices")]
    AttributeCount {
        /// Which attribute.
        attribute: &'static str,
        /// Entries given.
        got: usize,
        /// Number of vertices.
        vertices: usize,
    },
    /// More than `u32::MAX` vertices or triangles.
    #[error("the mesh is too large: {0} elements do not fit 32-bit indices")]
    TooLarge(usize),
    /// A flat array whose length is not a multiple of three.
    #[error("{array} has {len} numbers, not a multiple of 3")]
    FlatLength {
        /// Which array: `vertices` or `indices`.
        array: &'static str,
        /// Its length.
        len: usize,
    },
}

/// A flat array of numbers seen as an array of triples, without a copy.
pub(crate) fn triples<'a, T: Copy>(flat: &'a [T], array: &'static str) -> Result<&'a [[T; 3]], MeshError> {
    if !flat.len().is_multiple_of(3) {
        return Err(MeshError::FlatLength { array, len: flat.len() });
    }
    // SAFETY: `[T; 3]` is three `T` in a row, with `T`'s alignment (the array layout Rust
    // guarantees), and `flat` holds `len / 3` such triples in its memory.
    Ok(unsafe { std::slice::from_raw_parts(flat.as_ptr() as *const [T; 3], flat.len() / 3) })
}

/// Checks vertex positions and triangles: sizes that fit 32-bit indices, finite coordinates,
/// indices inside the vertex array.
fn check_mesh<P: Copy>(positions: &[P], triangles: &[[u32; 3]]) -> Result<(), MeshError>
where
    Vec3: From<P>,
{
    for n in [positions.len(), triangles.len()] {
        if n > u32::MAX as usize {
            return Err(MeshError::TooLarge(n));
        }
    }
    if let Some((vertex, position)) = positions.iter().map(|&p| Vec3::from(p)).enumerate().find(|(_, p)| !p.is_finite())
    {
        return Err(MeshError::NonFiniteVertex { vertex, position });
    }
    for (triangle, t) in triangles.iter().enumerate() {
        if let Some(&index) = t.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(MeshError::IndexOutOfRange { triangle, index, vertices: positions.len() });
        }
    }
    Ok(())
}

/// Checks plain arrays as [`TriangleMesh::new`] checks a mesh: what [`TriangleMesh::from_arrays`]
/// and [`crate::TriangleBvh::from_arrays`] accept.
pub fn check_arrays(vertices: &[[f32; 3]], triangles: &[[u32; 3]]) -> Result<(), MeshError> {
    check_mesh(vertices, triangles)
}

/// An indexed triangle mesh with optional per-vertex normals (for smooth shading) and texture
/// coordinates: a first set, and a second one for files that map some textures differently
/// (glTF's `TEXCOORD_1`, often a light map's or a decal's). Construction checks every index and
/// coordinate, so queries never can fail.
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleMesh {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
    /// The second set: `None` unless a loader keeps one, so that meshes with one set pay nothing.
    uvs1: Option<Vec<Vec2>>,
    /// The box of the positions, kept: every instance of the mesh asks for it, and a scene may
    /// place a mesh of a million vertices thousands of times.
    bounds: Aabb,
}

impl TriangleMesh {
    /// A mesh from vertex positions and triangles (vertex indices, counter-clockwise).
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        check_mesh(&positions, &triangles)?;
        Ok(Self::checked(positions, triangles))
    }

    /// A mesh of positions and triangles already checked, its box computed once.
    fn checked(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Self {
        let bounds = Aabb::from_points(positions.iter().copied());
        TriangleMesh { positions, triangles, normals: None, uvs: None, uvs1: None, bounds }
    }

    /// A mesh from plain arrays: vertex positions as `[x, y, z]` and triangles as three vertex
    /// indices each, checked as [`TriangleMesh::new`] checks them (an index past the vertices or
    /// a non-finite coordinate is an error, never a panic).
    ///
    /// ```
    /// use englobe::TriangleMesh;
    /// use englobe::shapes::MeshError;
    ///
    /// let mesh = TriangleMesh::from_arrays(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]])?;
    /// assert_eq!(mesh.len(), 1);
    /// let bad = TriangleMesh::from_arrays(&[[0.0, 0.0, 0.0]], &[[0, 1, 2]]);
    /// assert_eq!(bad, Err(MeshError::IndexOutOfRange { triangle: 0, index: 1, vertices: 1 }));
    /// # Ok::<(), MeshError>(())
    /// ```
    pub fn from_arrays(vertices: &[[f32; 3]], triangles: &[[u32; 3]]) -> Result<Self, MeshError> {
        check_arrays(vertices, triangles)?;
        Ok(Self::checked(vertices.iter().map(|&p| Vec3::from_array(p)).collect(), triangles.to_vec()))
    }

    /// [`TriangleMesh::from_arrays`] from flat arrays, as graphics APIs and file formats hand
    /// them out: `x, y, z` of each vertex in turn, and three indices per triangle. A length that
    /// is not a multiple of three is an error.
    ///
    /// ```
    /// use englobe::TriangleMesh;
    ///
    /// let mesh = TriangleMesh::from_flat(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], &[0, 1, 2])?;
    /// assert_eq!(mesh.len(), 1);
    /// assert!(TriangleMesh::from_flat(&[0.0, 0.0], &[]).is_err());
    /// # Ok::<(), englobe::shapes::MeshError>(())
    /// ```
    pub fn from_flat(vertices: &[f32], indices: &[u32]) -> Result<Self, MeshError> {
        Self::from_arrays(triples(vertices, "vertices")?, triples(indices, "indices")?)
    }

    /// Adds per-vertex normals (one per vertex; normalised when used).
    pub fn with_normals(mut self, normals: Vec<Vec3>) -> Result<Self, MeshError> {
        self.check_per_vertex("normals", normals.len())?;
        self.normals = Some(normals);
        Ok(self)
    }

    /// Adds per-vertex texture coordinates.
    pub fn with_uvs(mut self, uvs: Vec<Vec2>) -> Result<Self, MeshError> {
        self.check_per_vertex("uvs", uvs.len())?;
        self.uvs = Some(uvs);
        Ok(self)
    }

    /// Adds a second set of per-vertex texture coordinates (set 1; [`TriangleMesh::with_uvs`]
    /// gives set 0).
    pub fn with_uvs1(mut self, uvs: Vec<Vec2>) -> Result<Self, MeshError> {
        self.check_per_vertex("uvs (set 1)", uvs.len())?;
        self.uvs1 = Some(uvs);
        Ok(self)
    }

    /// Refuses a per-vertex `attribute` of `got` values that is not one per vertex.
    fn check_per_vertex(&self, attribute: &'static str, got: usize) -> Result<(), MeshError> {
        if got == self.positions.len() {
            return Ok(());
        }
        Err(MeshError::AttributeCount { attribute, got, vertices: self.positions.len() })
    }

    /// Vertex positions.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Triangles as vertex indices.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Per-vertex normals, if any.
    pub fn normals(&self) -> Option<&[Vec3]> {
        self.normals.as_deref()
    }

    /// Per-vertex texture coordinates (set 0), if any.
    pub fn uvs(&self) -> Option<&[Vec2]> {
        self.uvs.as_deref()
    }

    /// The second set of per-vertex texture coordinates, if any.
    pub fn uvs1(&self) -> Option<&[Vec2]> {
        self.uvs1.as_deref()
    }

    /// Texture coordinate set `set` (0 or 1), if the mesh has it; `None` for any other set.
    pub fn uv_set(&self, set: u32) -> Option<&[Vec2]> {
        match set {
            0 => self.uvs(),
            1 => self.uvs1(),
            _ => None,
        }
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// True if the mesh has no triangle.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Triangle `i` as three points.
    #[inline(always)]
    pub fn triangle(&self, i: u32) -> Triangle {
        let [a, b, c] = self.triangles[i as usize];
        Triangle::new(self.positions[a as usize], self.positions[b as usize], self.positions[c as usize])
    }

    /// Bounding box of triangle `i`.
    pub fn triangle_bounds(&self, i: u32) -> Aabb {
        Aabb::from_points(self.triangle(i).vertices)
    }

    /// Bounding box of the whole mesh (of all its positions).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The watertight test of the ray against triangle `i`.
    #[inline(always)]
    pub fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit> {
        self.intersect_with(i, ray, &WatertightRay::new(ray))
    }

    /// The watertight test of the ray against triangle `i`, with the ray's constants `w` computed
    /// once for all the triangles a query tests (they depend on the direction only, which stays
    /// the same while a query shrinks `t_max`).
    #[inline(always)]
    pub fn intersect_with(&self, i: u32, ray: &Ray, w: &WatertightRay) -> Option<PrimHit> {
        let t = self.triangle(i);
        intersect_triangle(ray, w, t.vertices[0], t.vertices[1], t.vertices[2])
    }

    /// The unit geometric normal of triangle `i` (zero for a degenerate one).
    pub fn geometric_normal(&self, i: u32) -> Vec3 {
        let [a, b, c] = self.triangle(i).vertices;
        (b - a).cross(c - a).normalize_or_zero()
    }

    /// Starts loading what shading triangle `i` reads (its vertices, and their normals if the
    /// mesh has them; see [`crate::World::prefetch_shading`]).
    #[inline]
    pub fn prefetch_triangle(&self, i: u32) {
        let Some(&[a, b, c]) = self.triangles.get(i as usize) else { return };
        for v in [a, b, c] {
            prefetch(&self.positions, v);
            if let Some(normals) = &self.normals {
                prefetch(normals, v);
            }
        }
    }

    /// The normal for shading at barycentric `(u, v)` on triangle `i`: interpolated from the
    /// vertex normals when the mesh has them, the geometric normal otherwise.
    pub fn shading_normal(&self, i: u32, u: f32, v: f32) -> Vec3 {
        let Some(normals) = &self.normals else { return self.geometric_normal(i) };
        self.interpolated_normal(normals, i, u, v).unwrap_or_else(|| self.geometric_normal(i))
    }

    /// Both normals of triangle `i` at barycentric `(u, v)`: the geometric normal, and the
    /// shading normal if it differs from it (the mesh has vertex normals and they do not cancel
    /// out there). The same numbers as [`TriangleMesh::geometric_normal`] and
    /// [`TriangleMesh::shading_normal`], the triangle read once.
    #[inline]
    pub fn normals_at(&self, i: u32, u: f32, v: f32) -> (Vec3, Option<Vec3>) {
        let geometric = self.geometric_normal(i);
        (geometric, self.normals.as_ref().and_then(|normals| self.interpolated_normal(normals, i, u, v)))
    }

    /// The vertex normals of triangle `i` interpolated at `(u, v)` and normalised, if they do not
    /// cancel out.
    #[inline]
    fn interpolated_normal(&self, normals: &[Vec3], i: u32, u: f32, v: f32) -> Option<Vec3> {
        let [a, b, c] = self.triangles[i as usize];
        (normals[a as usize] * (1.0 - u - v) + normals[b as usize] * u + normals[c as usize] * v).try_normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> TriangleMesh {
        TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y], vec![[0, 1, 2], [0, 2, 3]])
            .unwrap()
    }

    #[test]
    fn bad_meshes_are_refused() {
        let e = TriangleMesh::new(vec![Vec3::ZERO; 3], vec![[0, 1, 3]]).unwrap_err();
        assert!(matches!(e, MeshError::IndexOutOfRange { index: 3, .. }), "{e}");
        let e = TriangleMesh::new(vec![Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0)], vec![]).unwrap_err();
        assert!(matches!(e, MeshError::NonFiniteVertex { vertex: 1, .. }), "{e}");
        assert!(quad().with_normals(vec![Vec3::Z]).is_err());
        assert!(quad().with_uvs1(vec![Vec2::ZERO; 3]).is_err());
    }

    #[test]
    fn two_texture_coordinate_sets() {
        let m = quad();
        assert!(m.uv_set(0).is_none() && m.uv_set(1).is_none());
        let m = m.with_uvs(vec![Vec2::ZERO; 4]).unwrap().with_uvs1(vec![Vec2::ONE; 4]).unwrap();
        assert_eq!(m.uv_set(0), Some(&[Vec2::ZERO; 4][..]));
        assert_eq!(m.uv_set(1), Some(&[Vec2::ONE; 4][..]));
        assert_eq!(m.uv_set(2), None);
    }

    #[test]
    fn triangles_of_a_mesh_are_hit() {
        let m = quad();
        let ray = Ray::new(Vec3::new(0.2, 0.7, 1.0), -Vec3::Z);
        assert!(m.intersect(0, &ray).is_none());
        assert_eq!(m.intersect(1, &ray).unwrap().t, 1.0);
        assert_eq!(m.geometric_normal(1), Vec3::Z);
        assert_eq!(m.bounds(), Aabb::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0)));
    }

    #[test]
    fn shading_normals_interpolate() {
        let m = quad().with_normals(vec![Vec3::Z, Vec3::Z, Vec3::X, Vec3::Z]).unwrap();
        let n = m.shading_normal(0, 0.0, 1.0);
        assert_eq!(n, Vec3::X);
        let n = m.shading_normal(0, 0.0, 0.5);
        assert!((n - Vec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-6);
    }

    #[test]
    fn prefetching_is_a_hint_for_any_index() {
        // A hint reads nothing into the program: the mesh answers the same after it, and an index
        // past the end (or the largest) is no error.
        let m = quad().with_normals(vec![Vec3::Z; 4]).unwrap();
        for i in [0, 1, 2, u32::MAX] {
            m.prefetch_triangle(i);
            quad().prefetch_triangle(i);
        }
        assert_eq!(m.geometric_normal(1), Vec3::Z);
        assert_eq!(m.shading_normal(0, 0.2, 0.3), Vec3::Z);
    }
}
