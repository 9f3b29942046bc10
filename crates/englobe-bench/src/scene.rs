//! The scenes the benchmark measures: one triangle mesh read through englobe's own loaders (OBJ,
//! PLY, glTF), optionally tiled into a grid of copies to make a large scene out of a small one.
//! Every library is given the same indexed triangles, in the same order, so that triangle ids
//! agree across libraries.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, bail};
use englobe::{Aabb, TriangleMesh, Vec3};
use englobe_scene::mesh::load_mesh_file;

/// A grid of copies: `x` by `y` by `z`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tiling {
    /// Copies along x.
    pub x: u32,
    /// Copies along y.
    pub y: u32,
    /// Copies along z.
    pub z: u32,
}

impl Tiling {
    /// Number of copies.
    pub fn copies(self) -> u64 {
        self.x as u64 * self.y as u64 * self.z as u64
    }
}

/// Gap between neighbouring copies, as a fraction of the mesh's extent along that axis.
pub const TILE_GAP: f32 = 0.2;

/// Largest number of triangles a tiled scene may have (the structures index triangles with 32-bit
/// integers, and Embree's and obvhs's builders need several times the mesh in memory).
pub const MAX_TILED_TRIANGLES: u64 = 1 << 28;

/// One scene: a name for the tables and the mesh.
#[derive(Clone, Debug)]
pub struct BenchScene {
    /// Name in tables and the CSV.
    pub name: String,
    /// The triangles (degenerate ones already dropped by the loader).
    pub mesh: Arc<TriangleMesh>,
    /// Where the primary rays come from, if not from the camera that frames the mesh's bounding
    /// sphere: a camera inside the scene, as a renderer's would be.
    pub view: Option<View>,
}

/// A pinhole camera for the primary rays: square image, up +y.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Eye position.
    pub eye: Vec3,
    /// Viewing direction (unit).
    pub dir: Vec3,
    /// Field of view, in degrees, across the (square) image.
    pub fov_degrees: f32,
}

/// A view for the scene `name`: `NAME=EX,EY,EZ,DX,DY,DZ,FOV` on the command line.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSpec {
    /// The scene it is for.
    pub scene: String,
    /// The camera.
    pub view: View,
}

impl ViewSpec {
    /// Parses `NAME=EX,EY,EZ,DX,DY,DZ,FOV`.
    pub fn parse(s: &str) -> Result<Self, String> {
        let bad = || format!("`{s}`: expected NAME=EX,EY,EZ,DX,DY,DZ,FOV (eye, direction, field of view in degrees)");
        let (scene, numbers) = s.split_once('=').ok_or_else(bad)?;
        let n: Vec<f32> =
            numbers.split(',').map(|x| x.trim().parse::<f32>().map_err(|_| bad())).collect::<Result<_, _>>()?;
        let [ex, ey, ez, dx, dy, dz, fov] = n[..] else { return Err(bad()) };
        let (eye, dir) = (Vec3::new(ex, ey, ez), Vec3::new(dx, dy, dz));
        if scene.is_empty()
            || !eye.is_finite()
            || !dir.is_finite()
            || dir.length() == 0.0
            || !(fov > 0.0 && fov < 180.0)
        {
            return Err(bad());
        }
        if dir.normalize().cross(Vec3::Y).length() < 1e-3 {
            return Err(format!("`{s}`: the direction must not be vertical (the image's up is +y)"));
        }
        Ok(ViewSpec { scene: scene.to_owned(), view: View { eye, dir: dir.normalize(), fov_degrees: fov } })
    }
}

impl BenchScene {
    /// Reads `path` with englobe's loaders and tiles it if asked.
    pub fn load(name: &str, path: &Path, tiling: Option<Tiling>) -> anyhow::Result<Self> {
        let loaded = load_mesh_file(path).with_context(|| format!("cannot read the mesh {}", path.display()))?;
        let mut mesh = loaded.mesh;
        if mesh.is_empty() {
            bail!("{}: the mesh has no triangle", path.display());
        }
        if let Some(t) = tiling {
            mesh = tile(&mesh, t)?;
        }
        Ok(BenchScene { name: name.to_owned(), mesh: Arc::new(mesh), view: None })
    }

    /// A scene from a mesh already in memory.
    pub fn from_mesh(name: &str, mesh: TriangleMesh) -> Self {
        BenchScene { name: name.to_owned(), mesh: Arc::new(mesh), view: None }
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.mesh.len()
    }

    /// The box around every vertex.
    pub fn bounds(&self) -> Aabb {
        self.mesh.bounds()
    }

    /// The sphere the primary camera frames: centred on the box, through its corners.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        let b = self.bounds();
        (b.center(), 0.5 * (b.max - b.min).length())
    }

    /// The triangles as vertex triples (for libraries that take a triangle soup).
    pub fn triangle_soup(&self) -> impl ExactSizeIterator<Item = [Vec3; 3]> + '_ {
        (0..self.mesh.len() as u32).map(|i| self.mesh.triangle(i).vertices)
    }
}

/// `mesh` copied on a grid of `t.x * t.y * t.z` cells, each copy shifted by the mesh's extent plus
/// a gap of [`TILE_GAP`] of it; copy `k` holds triangles `k * n .. (k + 1) * n`.
pub fn tile(mesh: &TriangleMesh, t: Tiling) -> anyhow::Result<TriangleMesh> {
    let copies = t.copies();
    if copies == 0 {
        bail!("a tiling needs at least one copy along each axis");
    }
    let triangles = copies * mesh.len() as u64;
    if triangles > MAX_TILED_TRIANGLES {
        bail!("tiling {}x{}x{} would make {triangles} triangles; at most {MAX_TILED_TRIANGLES}", t.x, t.y, t.z);
    }
    let b = mesh.bounds();
    let step = (b.max - b.min) * (1.0 + TILE_GAP);
    let n = mesh.positions().len() as u32;
    let mut positions = Vec::with_capacity(mesh.positions().len() * copies as usize);
    let mut tris = Vec::with_capacity(triangles as usize);
    let mut copy = 0u32;
    for k in 0..t.z {
        for j in 0..t.y {
            for i in 0..t.x {
                let shift = step * Vec3::new(i as f32, j as f32, k as f32);
                positions.extend(mesh.positions().iter().map(|p| *p + shift));
                let base = copy * n;
                tris.extend(mesh.triangles().iter().map(|tri| tri.map(|v| v + base)));
                copy += 1;
            }
        }
    }
    Ok(TriangleMesh::new(positions, tris)?)
}

/// A scene named on the command line: `[NAME=]PATH[@XxYxZ]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneSpec {
    /// Name in tables (the file's stem when not given, with the tiling appended).
    pub name: String,
    /// The mesh file.
    pub path: PathBuf,
    /// Copies on a grid, if any.
    pub tiling: Option<Tiling>,
}

impl SceneSpec {
    /// Parses `[NAME=]PATH[@XxYxZ]`.
    pub fn parse(s: &str) -> Result<Self, String> {
        let (name, rest) = match s.split_once('=') {
            Some((n, r)) if !n.is_empty() && !n.contains(['/', '\\']) => (Some(n.to_owned()), r),
            _ => (None, s),
        };
        let (path, tiling) = match rest.rsplit_once('@') {
            Some((p, t)) => (p, Some(parse_tiling(t)?)),
            None => (rest, None),
        };
        if path.is_empty() {
            return Err(format!("`{s}`: expected [NAME=]PATH[@XxYxZ]"));
        }
        let path = PathBuf::from(path);
        let name = name.unwrap_or_else(|| {
            let stem = path.file_stem().map_or_else(|| "mesh".to_owned(), |s| s.to_string_lossy().into_owned());
            match tiling {
                Some(t) => format!("{stem}-{}x{}x{}", t.x, t.y, t.z),
                None => stem,
            }
        });
        Ok(SceneSpec { name, path, tiling })
    }
}

fn parse_tiling(s: &str) -> Result<Tiling, String> {
    let bad = || format!("`{s}`: expected a tiling such as 4x2x2");
    let parts: Vec<u32> = s.split('x').map(|p| p.parse::<u32>().map_err(|_| bad())).collect::<Result<_, _>>()?;
    match parts[..] {
        [x, y, z] if x > 0 && y > 0 && z > 0 => Ok(Tiling { x, y, z }),
        _ => Err(bad()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one_triangle() -> TriangleMesh {
        TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]).unwrap()
    }

    #[test]
    fn specs_parse() {
        let s = SceneSpec::parse("bunny=a/b/stanford-bunny.obj").unwrap();
        assert_eq!((s.name.as_str(), s.path.to_str().unwrap(), s.tiling), ("bunny", "a/b/stanford-bunny.obj", None));
        let s = SceneSpec::parse("a/b/stanford-bunny.obj@4x2x2").unwrap();
        assert_eq!(s.name, "stanford-bunny-4x2x2");
        assert_eq!(s.tiling, Some(Tiling { x: 4, y: 2, z: 2 }));
        assert!(SceneSpec::parse("x.obj@4x2").is_err());
        assert!(SceneSpec::parse("x.obj@0x1x1").is_err());
        assert!(SceneSpec::parse("name=").is_err());
    }

    #[test]
    fn tiling_copies_and_shifts() {
        let m = tile(&one_triangle(), Tiling { x: 2, y: 3, z: 1 }).unwrap();
        assert_eq!(m.len(), 6);
        assert_eq!(m.positions().len(), 18);
        // The last copy sits 1.2 extents along x and 2.4 along y.
        let last = m.triangle(5).vertices[0];
        assert!((last - Vec3::new(1.2, 2.4, 0.0)).length() < 1e-6, "{last}");
        assert!(tile(&one_triangle(), Tiling { x: 1 << 15, y: 1 << 15, z: 1 }).is_err());
    }
}
