//! `Shape`: triangle meshes (inline `trianglemesh`, `plymesh` files read by englobe's PLY reader,
//! `bilinearmesh` split into triangles, `loopsubdiv` as its control mesh, `disk` tessellated) and
//! spheres (tessellated when they emit, so that the path tracer samples them), placed by the current transformation matrix with the current material and area light.
//!
//! Orientation follows pbrt-v4 (`Triangle::InteractionFromIntersection`): a triangle faces the
//! side its winding gives, flipped under `ReverseOrientation` and under a transform that swaps
//! handedness; with vertex normals `N`, it faces the side of its normals instead. englobe's
//! triangles face their winding's side, so the windings are reordered to face where pbrt's do,
//! which decides the side an area light emits from and whether a ray enters or leaves glass.

use std::sync::Arc;

use englobe::{Object, Sphere, TriangleMesh, Vec2, Vec3};
use glam::{DMat3, DVec3};

use super::builder::{Builder, Part, Placed};
use super::params::{Params, Type, Values};
use super::source::{Fail, Place, Res, fail};
use super::transform::{is_affine, swaps_handedness};
use crate::error::SceneError;
use crate::mesh::load_mesh_file;

/// A mesh in the space of its shape, before the transformation matrix moves it.
#[derive(Default)]
pub(super) struct ObjMesh {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    pub normals: Option<Vec<DVec3>>,
    pub uvs: Option<Vec<Vec2>>,
}

/// Segments of a full disk's tessellation.
const DISK_SEGMENTS: u32 = 128;

impl Builder {
    /// The `Shape` directive.
    pub fn shape(&mut self, at: Place, kind: &str, params: &Params) -> Res<()> {
        self.require_world(at, "Shape")?;
        let what = format!("Shape \"{kind}\"");
        if let Some(p) = params.get("alpha", &[Type::Float, Type::Texture])? {
            if !matches!(&p.values, Values::Numbers(v) if v[0] == 1.0) {
                let shown = p.shown();
                self.report.skipped(p.at, "alpha", || {
                    format!("{what}: {shown}: alpha cut-outs are not supported: the shape is opaque")
                })?;
            }
        }
        let ctm = self.gs.ctm;
        if !is_affine(&ctm) || DMat3::from_mat4(ctm).determinant() == 0.0 {
            for p in params.unused().map(|p| p.name.clone()).collect::<Vec<_>>() {
                params.touch(&p);
            }
            return self.report.skipped(at, "singular transform", || {
                format!("{what}: the transformation matrix is singular or projective: the shape is not drawn")
            });
        }
        let mesh = match kind {
            "trianglemesh" => self.triangle_mesh(at, params, &what, 3)?,
            "bilinearmesh" => self.bilinear_mesh(at, params, &what)?,
            "loopsubdiv" => {
                let levels = params.integer("levels")?.or(params.integer("nlevels")?).unwrap_or(3);
                let mesh = self.triangle_mesh(at, params, &what, 3)?;
                self.report.approximated(at, "loopsubdiv", || {
                    format!("{what}: Loop subdivision ({levels} levels) is not supported: the control mesh is drawn as it is")
                })?;
                mesh
            }
            "plymesh" => self.ply_mesh(at, params, &what)?,
            "disk" => self.disk(at, params, &what)?,
            "sphere" => {
                self.sphere(at, params, &what)?;
                return self.report_unused(params, "Shape sphere", &what);
            }
            _ => {
                for p in params.unused().map(|p| p.name.clone()).collect::<Vec<_>>() {
                    params.touch(&p);
                }
                return self.report.skipped(at, &format!("shape {kind}"), || {
                    format!("{what}: shapes of this type are not supported: not drawn")
                });
            }
        };
        self.report_unused(params, &format!("Shape {kind}"), &what)?;
        self.place_mesh(at, mesh, &what)
    }

    /// The arrays of a `trianglemesh` (and of `loopsubdiv`, which has the same ones); `corners`
    /// is 3 (the indices are triangles).
    fn triangle_mesh(&mut self, at: Place, params: &Params, what: &str, corners: usize) -> Res<ObjMesh> {
        let mut mesh = self.vertices(at, params, what)?;
        let n = mesh.positions.len();
        let indices = match params.numbers("indices", &[Type::Integer])? {
            Some((v, i_at)) => indices(v, i_at, n, corners, what)?,
            None if n == corners => (0..n as u32).collect(),
            None => {
                return fail(
                    at,
                    format!(
                        "{what} needs \"integer indices\" (only a mesh of exactly {corners} vertices may leave them out)"
                    ),
                );
            }
        };
        mesh.triangles = indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        Ok(mesh)
    }

    /// `P`, `N` and `uv` of a mesh, checked against each other.
    fn vertices(&mut self, at: Place, params: &Params, what: &str) -> Res<ObjMesh> {
        let Some((p, _)) = params.numbers("P", &[Type::Point3])? else {
            return fail(at, format!("{what} needs its vertices, \"point3 P\""));
        };
        let n = p.len() / 3;
        if n > u32::MAX as usize {
            return fail(at, format!("{what}: {n} vertices, more than 32-bit indices can address"));
        }
        let positions: Vec<DVec3> = p.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect();
        let normals = match params.numbers("N", &[Type::Normal])? {
            Some((v, n_at)) if v.len() != p.len() => {
                return fail(n_at, format!("{what}: {} normals for {n} vertices", v.len() / 3));
            }
            Some((v, _)) => Some(v.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect()),
            None => None,
        };
        let uv = match params.numbers("uv", &[Type::Point2, Type::Float])? {
            Some(found) => Some(found),
            None => params.numbers("st", &[Type::Point2, Type::Float])?,
        };
        let uvs = match uv {
            Some((v, uv_at)) if v.len() != 2 * n => {
                return fail(uv_at, format!("{what}: {} texture coordinates for {n} vertices", v.len() / 2));
            }
            Some((v, _)) => Some(v.chunks_exact(2).map(|c| Vec2::new(c[0] as f32, c[1] as f32)).collect()),
            None => None,
        };
        for (name, why) in [("S", "tangents"), ("faceIndices", "face indices")] {
            if params.touch(name).is_some() {
                self.report
                    .ignored(at, &format!("mesh {name}"), || format!("{what}: the {why} \"{name}\" are not used"))?;
            }
        }
        Ok(ObjMesh { positions, triangles: Vec::new(), normals, uvs })
    }

    /// A `bilinearmesh`: each patch `p00 p10 p01 p11` as the triangles `p00 p10 p11` and
    /// `p00 p11 p01`, exact when the patch is planar.
    fn bilinear_mesh(&mut self, at: Place, params: &Params, what: &str) -> Res<ObjMesh> {
        let mut mesh = self.vertices(at, params, what)?;
        let n = mesh.positions.len();
        let quads = match params.numbers("indices", &[Type::Integer])? {
            Some((v, i_at)) => indices(v, i_at, n, 4, what)?,
            None if n == 4 => vec![0, 1, 2, 3],
            None => return fail(at, format!("{what} needs \"integer indices\" (four per patch)")),
        };
        let mut curved = 0usize;
        for q in quads.chunks_exact(4) {
            let [a, b, c, d] = [q[0], q[1], q[2], q[3]];
            let p = |i: u32| mesh.positions[i as usize];
            let (n1, n2) = ((p(b) - p(a)).cross(p(d) - p(a)), (p(d) - p(a)).cross(p(c) - p(a)));
            if n1.normalize_or_zero().dot(n2.normalize_or_zero()) < 1.0 - 1e-6 {
                curved += 1;
            }
            mesh.triangles.push([a, b, d]);
            mesh.triangles.push([a, d, c]);
        }
        if curved > 0 {
            self.report.approximated(at, "bilinear", || {
                format!("{what}: {curved} curved bilinear patches are drawn as two flat triangles each")
            })?;
        }
        Ok(mesh)
    }

    /// A `plymesh`: the file read by englobe's PLY reader (once per file), in the shape's space.
    fn ply_mesh(&mut self, at: Place, params: &Params, what: &str) -> Res<ObjMesh> {
        let Some((name, name_at)) = params.string("filename")? else {
            return fail(at, format!("{what} needs its file, \"string filename\""));
        };
        for p in ["displacement", "edgelength"] {
            if let Some(param) = params.touch(p) {
                let shown = param.shown();
                self.report.skipped(param.at, "ply displacement", || {
                    format!("{what}: {shown}: displacement is not supported: ignored")
                })?;
            }
        }
        let candidates = self.candidates(name_at, name);
        let path = candidates.iter().find(|p| p.is_file()).unwrap_or(&candidates[0]).clone();
        let key = std::fs::canonicalize(&path).unwrap_or_else(|_| path.clone());
        let mesh = match self.mesh_files.get(&key) {
            Some(m) => m.clone(),
            None => {
                let loaded = load_mesh_file(&path).map_err(|mesh| {
                    let tried: Vec<String> = candidates.iter().map(|p| p.display().to_string()).collect();
                    let located = self.sources.located(
                        name_at,
                        format!("cannot load the mesh \"{name}\" (looked for {}): {mesh}", tried.join(" and ")),
                    );
                    Fail::Scene(SceneError::Mesh { located, mesh: Box::new(mesh) })
                })?;
                self.mesh_warnings.extend(loaded.warnings.iter().map(|w| format!("{}: {w}", path.display())));
                let m = Arc::new(loaded.mesh);
                self.mesh_files.insert(key, m.clone());
                m
            }
        };
        Ok(ObjMesh {
            positions: mesh.positions().iter().map(|p| p.as_dvec3()).collect(),
            triangles: mesh.triangles().to_vec(),
            normals: mesh.normals().map(|n| n.iter().map(|v| v.as_dvec3()).collect()),
            uvs: mesh.uvs().map(<[Vec2]>::to_vec),
        })
    }

    /// A `disk` (or annulus, or sector), tessellated; it faces +z in its own space, as in pbrt.
    fn disk(&mut self, at: Place, params: &Params, what: &str) -> Res<ObjMesh> {
        let height = params.float("height")?.unwrap_or(0.0);
        let radius = params.float("radius")?.unwrap_or(1.0);
        let inner = params.float("innerradius")?.unwrap_or(0.0);
        let phi_max = params.float("phimax")?.unwrap_or(360.0).clamp(0.0, 360.0).to_radians();
        if !(radius > 0.0) || !(0.0..radius).contains(&inner) || !(phi_max > 0.0) {
            return fail(at, format!("{what}: expected 0 <= innerradius < radius and phimax > 0"));
        }
        let segments = ((DISK_SEGMENTS as f64 * phi_max / std::f64::consts::TAU).ceil() as u32).max(1);
        let ring = |r: f64| {
            (0..=segments).map(move |i| {
                let phi = phi_max * i as f64 / segments as f64;
                DVec3::new(r * phi.cos(), r * phi.sin(), height)
            })
        };
        let mut mesh = ObjMesh::default();
        mesh.positions.extend(ring(radius));
        if inner > 0.0 {
            mesh.positions.extend(ring(inner));
            let k = segments + 1;
            for i in 0..segments {
                mesh.triangles.push([i, i + 1, k + i + 1]);
                mesh.triangles.push([i, k + i + 1, k + i]);
            }
        } else {
            mesh.positions.push(DVec3::new(0.0, 0.0, height));
            let centre = segments + 1;
            for i in 0..segments {
                mesh.triangles.push([centre, i, i + 1]);
            }
        }
        self.report.approximated(at, "disk", || {
            format!("{what}: a disk is drawn as {} flat triangles", mesh.triangles.len())
        })?;
        Ok(mesh)
    }

    /// A `sphere`, placed by the transformation matrix (whose scale must be uniform to keep it a
    /// sphere); partial spheres are drawn whole.
    fn sphere(&mut self, at: Place, params: &Params, what: &str) -> Res<()> {
        let radius = params.float("radius")?.unwrap_or(1.0);
        if !(radius > 0.0) {
            return fail(at, format!("{what}: the radius must be positive, found {radius}"));
        }
        let (zmin, zmax) = (params.float("zmin")?.unwrap_or(-radius), params.float("zmax")?.unwrap_or(radius));
        let phi_max = params.float("phimax")?.unwrap_or(360.0);
        if zmin > -radius || zmax < radius || phi_max < 360.0 {
            self.report.approximated(at, "partial sphere", || {
                format!("{what}: a partial sphere (zmin, zmax, phimax) is drawn whole")
            })?;
        }
        if self.gs.area_light.is_some() && self.defining.is_none() {
            // englobe's path tracer samples emissive triangles, not spheres: a lamp found by
            // bounces alone would be a rain of fireflies.
            let mesh = uv_sphere(radius);
            let n = mesh.triangles.len();
            self.report.approximated(at, "emissive sphere", || {
                format!("{what}: an emissive sphere is drawn as {n} triangles, so that it is sampled as a light")
            })?;
            return self.place_mesh(at, mesh, what);
        }
        if self.gs.reverse_orientation {
            self.report.approximated(at, "reverse sphere", || {
                format!("{what}: ReverseOrientation is not applied to spheres: they face outward")
            })?;
        }
        let Some(sphere) =
            self.placed_sphere(at, Sphere::new(Vec3::ZERO, radius as f32), &self.gs.ctm.clone(), what)?
        else {
            return Ok(());
        };
        let area = 4.0 * std::f64::consts::PI * (sphere.radius as f64).powi(2);
        self.push(at, Shape::Sphere(sphere), area, what)
    }

    /// `sphere` moved by `m`: its centre moved, its radius scaled (by the mean of the axes' scales
    /// when they differ, reported).
    pub fn placed_sphere(&mut self, at: Place, s: Sphere, m: &glam::DMat4, what: &str) -> Res<Option<Sphere>> {
        let linear = DMat3::from_mat4(*m);
        let scales = [linear.x_axis.length(), linear.y_axis.length(), linear.z_axis.length()];
        let mean = (scales[0] + scales[1] + scales[2]) / 3.0;
        let skew = linear.x_axis.dot(linear.y_axis).abs()
            + linear.y_axis.dot(linear.z_axis).abs()
            + linear.z_axis.dot(linear.x_axis).abs();
        if scales.iter().any(|s| (s - mean).abs() > 1e-4 * mean) || skew > 1e-4 * mean * mean {
            self.report.approximated(at, "ellipsoid", || {
                format!("{what}: a sphere under a non-uniform scale or shear is drawn as a sphere (radius times the mean scale)")
            })?;
        }
        let centre = m.transform_point3(s.center.as_dvec3()).as_vec3();
        let radius = (s.radius as f64 * mean) as f32;
        if !centre.is_finite() || !(radius > 0.0) || !radius.is_finite() {
            self.report.skipped(at, "sphere range", || {
                format!("{what}: the sphere is beyond what 32-bit floats hold: not drawn")
            })?;
            return Ok(None);
        }
        Ok(Some(Sphere::new(centre, radius)))
    }

    /// Moves `mesh` into the world, faces its triangles as pbrt does, and places it.
    fn place_mesh(&mut self, at: Place, mesh: ObjMesh, what: &str) -> Res<()> {
        let m = self.gs.ctm;
        let positions: Vec<Vec3> = mesh.positions.iter().map(|&p| m.transform_point3(p).as_vec3()).collect();
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return fail(at, format!("{what}: the transform carries vertex {i} beyond the range of 32-bit floats"));
        }
        let to_world = DMat3::from_mat4(m).inverse().transpose();
        let normals: Option<Vec<Vec3>> =
            mesh.normals.map(|n| n.iter().map(|&v| (to_world * v).normalize_or_zero().as_vec3()).collect());
        let flip_all = self.gs.reverse_orientation ^ swaps_handedness(&m);
        let before = mesh.triangles.len();
        let mut triangles = Vec::with_capacity(before);
        for [a, b, c] in mesh.triangles {
            let [pa, pb, pc] = [a, b, c].map(|i| positions[i as usize]);
            if englobe::shapes::is_degenerate(pa, pb, pc) || a == b || b == c || a == c {
                continue;
            }
            let flip = match &normals {
                Some(n) => (pb - pa).cross(pc - pa).dot(n[a as usize] + n[b as usize] + n[c as usize]) < 0.0,
                None => flip_all,
            };
            triangles.push(if flip { [a, c, b] } else { [a, b, c] });
        }
        if triangles.len() < before {
            let dropped = before - triangles.len();
            self.report
                .ignored(at, "degenerate", || format!("{what}: {dropped} degenerate triangles (zero area) dropped"))?;
        }
        if triangles.is_empty() {
            return self
                .report
                .ignored(at, "empty mesh", || format!("{what}: the mesh has no triangles: nothing drawn"));
        }
        let area: f64 = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize].as_dvec3());
                0.5 * (b - a).cross(c - a).length()
            })
            .sum();
        let bad = |e: englobe::shapes::MeshError| Fail::At(at, format!("{what}: {e}"));
        let mut out = TriangleMesh::new(positions, triangles).map_err(bad)?;
        if let Some(n) = normals {
            out = out.with_normals(n).map_err(bad)?;
        }
        if let Some(uv) = mesh.uvs {
            out = out.with_uvs(uv).map_err(bad)?;
        }
        self.push(at, Shape::Mesh(Arc::new(out)), area, what)
    }

    /// Places a shape with the current material and area light (or adds it to the object being
    /// defined). `area` is its surface area, which an area light's `power` needs.
    fn push(&mut self, at: Place, shape: Shape, area: f64, what: &str) -> Res<()> {
        let material = self.gs.material.clone();
        if let Some((name, _, parts)) = &mut self.defining {
            let name = name.clone();
            parts.push(match shape {
                Shape::Mesh(m) => Part::Mesh(m, material),
                Shape::Sphere(s) => Part::Sphere(s, material),
            });
            if self.gs.area_light.is_some() {
                self.report.skipped(at, "instanced area light", || {
                    format!(
                        "{what}: area lights in object \"{name}\" are not supported (as in pbrt-v4): it does not emit"
                    )
                })?;
            }
            return Ok(());
        }
        let emission = match self.gs.area_light {
            None => Vec3::ZERO,
            Some(light) => match light.power {
                Some(power) if area > 0.0 => {
                    let sides = if light.two_sided { 2.0 } else { 1.0 };
                    light.radiance * (power / (std::f64::consts::PI * area * sides)) as f32
                }
                _ => light.radiance,
            },
        };
        let object = match shape {
            Shape::Mesh(m) => Object::Mesh(m),
            Shape::Sphere(s) => Object::from(s),
        };
        self.placed.push(Placed { object, material, emission });
        Ok(())
    }
}

/// Rings and segments of an emissive sphere's tessellation.
const SPHERE_RINGS: u32 = 32;
const SPHERE_SEGMENTS: u32 = 64;

/// A sphere of `radius` about the origin as triangles wound outward: rings of constant z from
/// pole to pole.
fn uv_sphere(radius: f64) -> ObjMesh {
    let mut mesh = ObjMesh::default();
    mesh.positions.push(DVec3::new(0.0, 0.0, radius));
    for ring in 1..SPHERE_RINGS {
        let theta = std::f64::consts::PI * ring as f64 / SPHERE_RINGS as f64;
        for seg in 0..SPHERE_SEGMENTS {
            let phi = std::f64::consts::TAU * seg as f64 / SPHERE_SEGMENTS as f64;
            mesh.positions.push(radius * DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()));
        }
    }
    mesh.positions.push(DVec3::new(0.0, 0.0, -radius));
    let south = mesh.positions.len() as u32 - 1;
    let at = |ring: u32, seg: u32| 1 + (ring - 1) * SPHERE_SEGMENTS + seg % SPHERE_SEGMENTS;
    for seg in 0..SPHERE_SEGMENTS {
        mesh.triangles.push([0, at(1, seg), at(1, seg + 1)]);
        mesh.triangles.push([south, at(SPHERE_RINGS - 1, seg + 1), at(SPHERE_RINGS - 1, seg)]);
        for ring in 1..SPHERE_RINGS - 1 {
            let (a, b, c, d) = (at(ring, seg), at(ring, seg + 1), at(ring + 1, seg), at(ring + 1, seg + 1));
            mesh.triangles.push([a, c, d]);
            mesh.triangles.push([a, d, b]);
        }
    }
    mesh
}

/// What [`Builder::push`] places.
enum Shape {
    Mesh(Arc<TriangleMesh>),
    Sphere(Sphere),
}

/// Vertex indices from an integer list: a multiple of `corners`, each below `vertices`.
fn indices(v: &[f64], at: Place, vertices: usize, corners: usize, what: &str) -> Res<Vec<u32>> {
    if v.len() % corners != 0 {
        return fail(at, format!("{what}: {} indices, not a multiple of {corners}", v.len()));
    }
    let mut out = Vec::with_capacity(v.len());
    for &i in v {
        if !(i >= 0.0 && (i as usize) < vertices) {
            return fail(at, format!("{what}: vertex index {i} is out of range: the mesh has {vertices} vertices"));
        }
        out.push(i as u32);
    }
    Ok(out)
}
