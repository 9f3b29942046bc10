//! glTF 2.0 files (Khronos Group 2017, "glTF 2.0 Specification"), `.gltf` with its buffers and
//! `.glb`: every mesh primitive of the default scene, with node transforms applied, becomes part
//! of one triangle mesh; materials and their textures are read by [`super::gltf_material`].
//! Vertex tangents (`TANGENT`) are kept when every primitive has them.
//!
//! Texture coordinates: `TEXCOORD_0` is kept when every primitive has it. `TEXCOORD_1` is read
//! only when a material of the file samples it (a texture's `texCoord: 1`), so that the many files
//! carrying a second set no material uses (light-map coordinates, mostly) cost nothing; a
//! primitive without it gets a copy of its `TEXCOORD_0` in its place, which is what reading
//! set 0 instead means, and a warning names the materials that wanted set 1 there.
//!
//! The `gltf` crate parses the JSON into its document model; englobe does the rest: the GLB
//! container (whose header the crate subtracts from without checking), the required extensions
//! (a file that needs Draco or meshopt compression is refused, naming the extension), every index
//! from one object to another (the crate's own validation indexes the accessor list unchecked and
//! panics on a bad `POSITION`, so it is not used), a bounded walk over the node hierarchy (cycles
//! and exponential sharing refused), and every accessor through [`super::gltf_data`].

use std::collections::BTreeMap;
use std::path::Path;

use englobe::{Vec2, Vec3};
use glam::{Mat3, Mat4, Quat, Vec4};
use gltf::json;
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::Checked;

use super::build::{MeshParts, finish};
use super::error::{MeshErrorKind, MeshFileError, Position};
use super::gltf_data::Buffers;
use super::loaded::{LoadedMesh, MeshFormat, NO_MATERIAL};
use super::read::guarded;

/// Most node instances a scene may expand to (a node reachable along many paths counts once per
/// path).
const MAX_NODE_INSTANCES: usize = 1 << 20;
/// Most triangles one glTF file may expand to.
const MAX_TRIANGLES: usize = 1 << 28;

/// Loads the glTF (`.gltf` or `.glb`) file `path` whose content is `bytes`.
pub(super) fn load(path: &Path, bytes: &[u8], format: MeshFormat) -> Result<LoadedMesh, MeshFileError> {
    let (json_bytes, bin) = if bytes.starts_with(b"glTF") { split_glb(path, bytes)? } else { (bytes, None) };
    if format == MeshFormat::Glb && bin.is_none() && !bytes.starts_with(b"glTF") {
        return Err(MeshFileError::byte(
            path,
            0,
            MeshErrorKind::Malformed("a .glb file must start with `glTF`".into()),
        ));
    }
    let parsed = guarded(path, "glTF JSON", || json::deserialize::from_slice::<json::Root>(json_bytes))?;
    let root = parsed.map_err(|e| {
        let where_ = if bin.is_some() { " (in the GLB's JSON chunk)" } else { "" };
        MeshFileError::new(
            path,
            Some(Position::LineColumn(e.line(), e.column())),
            MeshErrorKind::Malformed(format!("invalid glTF JSON{where_}: {e}")),
        )
    })?;
    for (i, ext) in root.extensions_required.iter().enumerate() {
        // Texture and material extensions only refine what englobe approximates anyway; anything
        // else (compression, quantisation) changes how geometry is stored.
        let harmless = ["KHR_texture_", "KHR_materials_", "EXT_texture_"].iter().any(|p| ext.starts_with(p));
        if !harmless {
            return Err(MeshFileError::new(
                path,
                Some(Position::Json(format!("extensionsRequired[{i}]"))),
                MeshErrorKind::UnsupportedExtension(ext.clone()),
            ));
        }
    }
    let mut buffers = Buffers::new(path, &root, bin);
    let read = super::gltf_material::materials(path, &root, &mut buffers);
    // The slots of each material that sample set 1.
    let set1_slots: Vec<Vec<&'static str>> = read
        .materials
        .iter()
        .map(|(_, m)| m.textures.slots().into_iter().filter(|(_, r)| r.uv_set == 1).map(|(slot, _)| slot).collect())
        .collect();
    let mut builder = Builder {
        path,
        root: &root,
        buffers,
        parts: MeshParts::default(),
        normals: Vec::new(),
        uvs: Vec::new(),
        uvs1: Vec::new(),
        want_uvs1: set1_slots.iter().any(|s| !s.is_empty()),
        set1_slots: &set1_slots,
        lacking_uvs1: BTreeMap::new(),
        tangents: Vec::new(),
        ids: Vec::new(),
        all_normals: true,
        all_uvs: true,
        all_tangents: true,
        warnings: read.warnings,
    };
    for (node, transform) in scene_nodes(path, &root)? {
        if let Some(mesh) = root.nodes[node].mesh {
            builder.add_mesh(node, mesh.value(), &transform)?;
        }
    }
    let vertices = builder.parts.positions.len();
    if !builder.uvs1.is_empty() {
        builder.pad_uvs1(vertices);
    }
    let Builder {
        mut parts,
        mut warnings,
        normals,
        uvs,
        uvs1,
        lacking_uvs1,
        tangents,
        ids,
        all_normals,
        all_uvs,
        all_tangents,
        ..
    } = builder;
    if parts.positions.is_empty() {
        return Err(MeshFileError::file(path, MeshErrorKind::NoTriangles(" in the default scene".into())));
    }
    if !all_normals && !normals.is_empty() {
        warnings.push("some primitives have no normals; shading uses face normals".into());
    }
    for (material, (first, count)) in lacking_uvs1 {
        let slots = set1_slots[material as usize].join(" and ");
        let more = if count > 1 { format!(" (and {} more primitives)", count - 1) } else { String::new() };
        warnings.push(format!(
            "material `{}`: its {slots} texture reads TEXCOORD_1, which {first}{more} has not; TEXCOORD_0 is read there instead",
            read.materials[material as usize].0
        ));
    }
    parts.normals = (all_normals && !normals.is_empty()).then_some(normals);
    parts.uvs = (all_uvs && !uvs.is_empty()).then_some(uvs);
    parts.uvs1 = (!uvs1.is_empty()).then_some(uvs1);
    parts.tangents = (all_tangents && all_normals && !tangents.is_empty()).then_some(tangents);
    parts.triangle_materials = Some(ids);
    finish(path, format, parts, (read.materials, read.textures), warnings)
}

/// The JSON chunk and the optional binary chunk of a GLB container.
fn split_glb<'a>(path: &Path, bytes: &'a [u8]) -> Result<(&'a [u8], Option<&'a [u8]>), MeshFileError> {
    let u32_at = |at: usize| -> Option<u32> { Some(u32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?)) };
    let short = |at: usize, what: &str| MeshFileError::byte(path, at as u64, MeshErrorKind::Truncated(what.to_owned()));
    let version = u32_at(4).ok_or_else(|| short(4, "the GLB header is cut short"))?;
    if version != 2 {
        return Err(MeshFileError::byte(
            path,
            4,
            MeshErrorKind::Unsupported(format!("GLB version {version}: expected 2")),
        ));
    }
    let length = u32_at(8).ok_or_else(|| short(8, "the GLB header is cut short"))? as usize;
    if length > bytes.len() || length < 12 {
        return Err(MeshFileError::byte(
            path,
            8,
            MeshErrorKind::Truncated(format!("the header declares {length} bytes, the file has {}", bytes.len())),
        ));
    }
    let mut at = 12;
    let mut json = None;
    let mut bin = None;
    while at < length {
        let chunk_length = u32_at(at).ok_or_else(|| short(at, "a chunk header is cut short"))? as usize;
        let kind = u32_at(at + 4).ok_or_else(|| short(at + 4, "a chunk header is cut short"))?;
        let data = at + 8;
        if chunk_length > length - data.min(length) {
            return Err(MeshFileError::byte(
                path,
                at as u64,
                MeshErrorKind::Truncated(format!("a chunk of {chunk_length} bytes runs past the end of the file")),
            ));
        }
        let chunk = &bytes[data..data + chunk_length];
        match (&kind.to_le_bytes(), json.is_some()) {
            (b"JSON", false) => json = Some(chunk),
            (b"BIN\0", true) if bin.is_none() => bin = Some(chunk),
            (_, false) => {
                return Err(MeshFileError::byte(
                    path,
                    at as u64,
                    MeshErrorKind::Malformed("the first chunk must be JSON".into()),
                ));
            }
            _ => {} // unknown chunks are skipped, as the format asks
        }
        at = data + chunk_length;
    }
    let json = json.ok_or_else(|| short(12, "the file has no JSON chunk"))?;
    Ok((json, bin))
}

/// Every node of the default scene (or, without scenes, every root node) with its transform to
/// the scene, depth first.
fn scene_nodes(path: &Path, root: &json::Root) -> Result<Vec<(usize, Mat4)>, MeshFileError> {
    let missing = |at: String, what: &str| {
        MeshFileError::new(
            path,
            Some(Position::Json(at)),
            MeshErrorKind::Malformed(format!("refers to a missing {what}")),
        )
    };
    let starts: Vec<usize> = match root.scene.map(|s| s.value()).or((!root.scenes.is_empty()).then_some(0)) {
        Some(s) => root
            .scenes
            .get(s)
            .ok_or_else(|| missing("scene".into(), "scene"))?
            .nodes
            .iter()
            .map(|n| n.value())
            .collect(),
        None => {
            let mut is_child = vec![false; root.nodes.len()];
            for n in &root.nodes {
                for c in n.children.iter().flatten() {
                    if let Some(flag) = is_child.get_mut(c.value()) {
                        *flag = true;
                    }
                }
            }
            (0..root.nodes.len()).filter(|&n| !is_child[n]).collect()
        }
    };
    let mut out = Vec::new();
    let mut stack: Vec<(usize, Mat4, usize)> = starts.iter().rev().map(|&n| (n, Mat4::IDENTITY, 0)).collect();
    while let Some((n, parent, depth)) = stack.pop() {
        let at = || Some(Position::Json(format!("nodes[{n}]")));
        if depth > root.nodes.len() {
            return Err(MeshFileError::new(
                path,
                at(),
                MeshErrorKind::Malformed("the node hierarchy has a cycle".into()),
            ));
        }
        if out.len() >= MAX_NODE_INSTANCES {
            return Err(MeshFileError::new(
                path,
                at(),
                MeshErrorKind::Malformed(format!("the node hierarchy expands to more than {MAX_NODE_INSTANCES} nodes")),
            ));
        }
        let node =
            root.nodes.get(n).ok_or_else(|| missing(format!("a child of or scene entry for nodes[{n}]"), "node"))?;
        if node.mesh.is_some_and(|m| m.value() >= root.meshes.len()) {
            return Err(missing(format!("nodes[{n}].mesh"), "mesh"));
        }
        let local = match node.matrix {
            Some(m) => Mat4::from_cols_array(&m),
            None => Mat4::from_scale_rotation_translation(
                Vec3::from(node.scale.unwrap_or([1.0; 3])),
                Quat::from_array(node.rotation.map_or([0.0, 0.0, 0.0, 1.0], |r| r.0)),
                Vec3::from(node.translation.unwrap_or([0.0; 3])),
            ),
        };
        if !local.is_finite() {
            return Err(MeshFileError::new(
                path,
                at(),
                MeshErrorKind::NonFinite { what: "the node's transform".into(), value: format!("{local:?}") },
            ));
        }
        let global = parent * local;
        out.push((n, global));
        for c in node.children.iter().flatten().rev() {
            stack.push((c.value(), global, depth + 1));
        }
    }
    Ok(out)
}

/// The mesh under construction.
struct Builder<'a> {
    path: &'a Path,
    root: &'a json::Root,
    buffers: Buffers<'a>,
    parts: MeshParts,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    /// Set 1, from the first primitive that has it on (empty until then, and when no material
    /// samples it).
    uvs1: Vec<Vec2>,
    /// Whether a material samples set 1, and so whether `TEXCOORD_1` is read at all.
    want_uvs1: bool,
    /// For each material, the slots that sample set 1.
    set1_slots: &'a [Vec<&'static str>],
    /// Materials that sample set 1 on primitives without it: the first such primitive and how
    /// many there are.
    lacking_uvs1: BTreeMap<u32, (String, usize)>,
    tangents: Vec<Vec4>,
    ids: Vec<u32>,
    all_normals: bool,
    all_uvs: bool,
    all_tangents: bool,
    warnings: Vec<String>,
}

impl Builder<'_> {
    /// Extends set 1 to `vertices` entries with the vertices' set 0 (`(0, 0)` where they have
    /// none): those vertices read set 0 wherever set 1 is asked for. `uvs` holds every vertex's
    /// set 0 from the first up to the first primitive without it, after which it grows no more.
    fn pad_uvs1(&mut self, vertices: usize) {
        let from = self.uvs1.len();
        self.uvs1.extend((from..vertices).map(|i| self.uvs.get(i).copied().unwrap_or(Vec2::ZERO)));
    }

    /// Texture coordinate set `set` of primitive `at` (accessor `index`), one per vertex of its
    /// `count`: VEC2 of floats, or of unsigned bytes or shorts normalised to `0..=1` (the only
    /// types glTF 2.0 allows for `TEXCOORD_n`, section 3.7.2.1; the integers read as such
    /// without `normalized: true` would be texel-sized steps of a whole image).
    fn tex_coords(&mut self, index: usize, set: u32, at: &str, count: usize) -> Result<Vec<Vec2>, MeshFileError> {
        let path = self.path;
        let what = format!("TEXCOORD_{set}");
        let kinds = [ComponentType::F32, ComponentType::U8, ComponentType::U16];
        let acc = self.buffers.accessor(self.root, index, &what, &[Type::Vec2], &kinds)?;
        if !acc.is_normalized() {
            return Err(MeshFileError::new(
                path,
                Some(Position::Json(format!("accessors[{index}].normalized"))),
                MeshErrorKind::Malformed(format!(
                    "{what} of unsigned integers must be normalized (`\"normalized\": true`), as glTF 2.0 requires"
                )),
            ));
        }
        check_count(path, at, &what, index, acc.count, count)?;
        Ok(acc.vectors::<2>(path, "a texture coordinate")?.into_iter().map(Vec2::from).collect())
    }

    fn add_mesh(&mut self, node: usize, mesh: usize, transform: &Mat4) -> Result<(), MeshFileError> {
        let (path, root) = (self.path, self.root);
        let normal_matrix = Mat3::from_mat4(*transform).inverse().transpose();
        for (p, prim) in root.meshes[mesh].primitives.iter().enumerate() {
            let at = format!("meshes[{mesh}].primitives[{p}]");
            let mode = match prim.mode {
                Checked::Valid(m) => m,
                Checked::Invalid => Mode::Triangles,
            };
            if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
                self.warnings.push(format!("{at} (node {node}): {mode:?} skipped (englobe renders surfaces)"));
                continue;
            }
            let Some(position) = prim.attributes.get(&Checked::Valid(Semantic::Positions)) else {
                self.warnings.push(format!("{at}: no POSITION attribute; skipped"));
                continue;
            };
            let f32_only = [ComponentType::F32];
            let positions = self
                .buffers
                .accessor(root, position.value(), "POSITION", &[Type::Vec3], &f32_only)?
                .vectors::<3>(path, "a position")?;
            let count = positions.len();
            let base = self.parts.positions.len();
            if base + count > u32::MAX as usize {
                return Err(MeshFileError::new(
                    path,
                    Some(Position::Json(at)),
                    MeshErrorKind::Malformed("more than 2^32 vertices".into()),
                ));
            }
            for v in &positions {
                self.parts.positions.push(transform.transform_point3(Vec3::from(*v)));
            }
            let normal = prim.attributes.get(&Checked::Valid(Semantic::Normals));
            match normal {
                Some(n) if self.all_normals => {
                    let acc = self.buffers.accessor(root, n.value(), "NORMAL", &[Type::Vec3], &f32_only)?;
                    check_count(path, &at, "NORMAL", n.value(), acc.count, count)?;
                    let normals = acc.vectors::<3>(path, "a normal")?;
                    self.normals.extend(normals.iter().map(|n| (normal_matrix * Vec3::from(*n)).normalize_or_zero()));
                }
                _ => self.all_normals = false,
            }
            match prim.attributes.get(&Checked::Valid(Semantic::Tangents)) {
                Some(t) if self.all_tangents => {
                    let acc = self.buffers.accessor(root, t.value(), "TANGENT", &[Type::Vec4], &f32_only)?;
                    check_count(path, &at, "TANGENT", t.value(), acc.count, count)?;
                    // Tangents move with the surface (not the inverse transpose); a mirroring
                    // transform flips the bitangent, so the handedness flips with it.
                    let linear = Mat3::from_mat4(*transform);
                    let flip = if linear.determinant() < 0.0 { -1.0 } else { 1.0 };
                    self.tangents.extend(acc.vectors::<4>(path, "a tangent")?.into_iter().map(|t| {
                        let xyz = (linear * Vec3::new(t[0], t[1], t[2])).normalize_or_zero();
                        xyz.extend(if t[3] < 0.0 { -flip } else { flip })
                    }));
                }
                _ => self.all_tangents = false,
            }
            let material = prim.material.map_or(NO_MATERIAL, |m| m.value() as u32);
            if material != NO_MATERIAL && material as usize >= root.materials.len() {
                return Err(MeshFileError::new(
                    path,
                    Some(Position::Json(format!("{at}.material"))),
                    MeshErrorKind::Malformed("refers to a missing material".into()),
                ));
            }
            match prim.attributes.get(&Checked::Valid(Semantic::TexCoords(0))) {
                Some(t) if self.all_uvs => {
                    let uvs = self.tex_coords(t.value(), 0, &at, count)?;
                    self.uvs.extend(uvs);
                }
                _ => self.all_uvs = false,
            }
            if self.want_uvs1 {
                match prim.attributes.get(&Checked::Valid(Semantic::TexCoords(1))) {
                    Some(t) => {
                        let uvs = self.tex_coords(t.value(), 1, &at, count)?;
                        self.pad_uvs1(base);
                        self.uvs1.extend(uvs);
                    }
                    None => {
                        if self.set1_slots.get(material as usize).is_some_and(|s| !s.is_empty()) {
                            self.lacking_uvs1.entry(material).or_insert_with(|| (at.clone(), 0)).1 += 1;
                        }
                        if !self.uvs1.is_empty() {
                            self.pad_uvs1(base + count);
                        }
                    }
                }
            }

            let indices: Vec<u32> = match prim.indices {
                Some(i) => {
                    let kinds = [ComponentType::U8, ComponentType::U16, ComponentType::U32];
                    let acc = self.buffers.accessor(root, i.value(), "indices", &[Type::Scalar], &kinds)?;
                    let mut out = Vec::with_capacity(acc.count);
                    for k in 0..acc.count {
                        let index = acc.index(k);
                        if index as usize >= count {
                            return Err(acc.element_error(
                                path,
                                k,
                                MeshErrorKind::IndexOutOfRange {
                                    what: "vertex",
                                    index: index.to_string(),
                                    available: count as u64,
                                    context: " in the primitive's POSITION accessor",
                                },
                            ));
                        }
                        out.push(index + base as u32);
                    }
                    out
                }
                None => (base as u32..(base + count) as u32).collect(),
            };
            let before = self.parts.triangles.len();
            let tris = &mut self.parts.triangles;
            match mode {
                Mode::TriangleStrip => tris.extend(
                    indices
                        .windows(3)
                        .enumerate()
                        .map(|(k, w)| if k % 2 == 0 { [w[0], w[1], w[2]] } else { [w[1], w[0], w[2]] }),
                ),
                Mode::TriangleFan => {
                    tris.extend((1..indices.len().saturating_sub(1)).map(|k| [indices[0], indices[k], indices[k + 1]]))
                }
                _ => {
                    if indices.len() % 3 != 0 {
                        self.warnings.push(format!(
                            "{at}: {} indices is not a multiple of 3; the rest is ignored",
                            indices.len()
                        ));
                    }
                    tris.extend(indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]));
                }
            }
            if tris.len() > MAX_TRIANGLES {
                return Err(MeshFileError::new(
                    path,
                    Some(Position::Json(at)),
                    MeshErrorKind::Malformed(format!("the scene expands to more than {MAX_TRIANGLES} triangles")),
                ));
            }
            self.ids.resize(self.ids.len() + tris.len() - before, material);
        }
        Ok(())
    }
}

/// Refuses attribute `what` of primitive `at`, accessor `index`, when its count differs from the
/// positions'.
fn check_count(path: &Path, at: &str, what: &str, index: usize, got: usize, want: usize) -> Result<(), MeshFileError> {
    if got == want {
        return Ok(());
    }
    Err(MeshFileError::new(
        path,
        Some(Position::Json(format!("{at}.attributes.{what}"))),
        MeshErrorKind::Malformed(format!("accessors[{index}] has {got} elements but POSITION has {want}")),
    ))
}
