//! glTF texture coordinate sets on small files made here: a texture with `texCoord: 1` (or a
//! `KHR_texture_transform` that says so) reads `TEXCOORD_1`, every slot reads its own set, the
//! coverage follows the base colour texture's set and generated tangents the normal texture's;
//! sets a mesh lacks fall back to set 0 with a warning; a malformed `TEXCOORD_1` is refused with
//! the file, the primitive and the accessor named.

mod common;

use std::path::{Path, PathBuf};

use common::{base64, png, write};
use englobe::Vec3;
use englobe_scene::mesh::{LoadedMesh, MeshFileError, load_mesh_file};
use englobe_scene::{Scene, SceneObject, TexCoords, load_scene};
use serde_json::{Value, json};

const FLOAT: u32 = 5126;
const UNSIGNED_BYTE: u32 = 5121;
const UNSIGNED_SHORT: u32 = 5123;

/// The unit quad in the xy plane facing +z, corners (0,0), (1,0), (1,1), (0,1).
const CORNERS: [[f32; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];

/// Set 0 maps the quad into the left texel of a 2 x 1 image (u from 0.05 to 0.45 along +x, v
/// down along -y); set 1 into the right texel, turned: u from 0.55 to 0.95 along +y.
fn set0() -> Vec<f32> {
    CORNERS.iter().flat_map(|&[x, y]| [0.05 + 0.4 * x, 1.0 - y]).collect()
}
fn set1() -> Vec<f32> {
    CORNERS.iter().flat_map(|&[x, y]| [0.55 + 0.4 * y, x]).collect()
}

/// A document under construction: one base64 buffer, a view and an accessor per attribute.
#[derive(Default)]
struct Doc {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Doc {
    /// An accessor of `count` `ty` elements of `component` over `bytes`, with `extra` fields;
    /// its index.
    fn accessor(&mut self, bytes: &[u8], component: u32, ty: &str, count: usize, extra: Value) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        self.views.push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend(bytes);
        let mut a = json!({"bufferView": self.views.len() - 1, "componentType": component, "count": count, "type": ty});
        for (k, v) in extra.as_object().into_iter().flatten() {
            a[k] = v.clone();
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    fn floats(&mut self, v: &[f32], ty: &str, dims: usize) -> usize {
        let bytes: Vec<u8> = v.iter().flat_map(|c| c.to_le_bytes()).collect();
        self.accessor(&bytes, FLOAT, ty, v.len() / dims, json!({}))
    }

    /// The quad's attributes (positions, normals, set 0 and, when given, set 1) and indices,
    /// for a primitive of `material`.
    fn quad(&mut self, uvs1: Option<&[f32]>, material: usize) -> Value {
        let positions: Vec<f32> = CORNERS.iter().flat_map(|&[x, y]| [x, y, 0.0]).collect();
        let mut attributes = json!({
            "POSITION": self.floats(&positions, "VEC3", 3),
            "NORMAL": self.floats(&[0.0, 0.0, 1.0].repeat(4), "VEC3", 3),
            "TEXCOORD_0": self.floats(&set0(), "VEC2", 2),
        });
        if let Some(uvs) = uvs1 {
            attributes["TEXCOORD_1"] = json!(self.floats(uvs, "VEC2", 2));
        }
        let indices: Vec<u8> = [0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()).collect();
        let indices = self.accessor(&indices, UNSIGNED_SHORT, "SCALAR", 6, json!({}));
        json!({"attributes": attributes, "indices": indices, "material": material})
    }

    /// The document: `primitives` of one mesh at the root, `materials`, and one texture, a
    /// 2 x 1 image red | green (alpha 0 | 255), nearest and clamped.
    fn finish(self, primitives: Vec<Value>, materials: Value) -> Value {
        let image = png(2, 1, &[[255, 0, 0, 0], [0, 255, 0, 255]]);
        json!({
            "asset": {"version": "2.0"},
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": primitives}],
            "buffers": [{"byteLength": self.bin.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&self.bin))}],
            "bufferViews": self.views,
            "accessors": self.accessors,
            "images": [{"uri": format!("data:image/png;base64,{}", base64(&image))}],
            "samplers": [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33071}],
            "textures": [{"source": 0, "sampler": 0}],
            "extensionsUsed": ["KHR_texture_transform"],
            "materials": materials
        })
    }
}

/// The quad with both sets and one material.
fn quad_file(dir: &Path, material: Value) -> PathBuf {
    let mut doc = Doc::default();
    let prim = doc.quad(Some(&set1()), 0);
    let doc = doc.finish(vec![prim], json!([material]));
    write(dir, "quad.gltf", serde_json::to_string(&doc).unwrap().as_bytes())
}

/// The scene of the file `quad.gltf` in `dir`: its one object and material.
fn scene_of(dir: &Path) -> Scene {
    let toml = "[image]\nwidth = 4\nheight = 4\n[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n\
                [[mesh]]\npath = \"quad.gltf\"\n";
    load_scene(&write(dir, "s.toml", toml.as_bytes())).unwrap()
}

/// The coordinates of every set a material reads at barycentric (0.25, 0.25) of triangle 0.
fn at_hit(object: &SceneObject, set1: bool) -> TexCoords {
    object.tex_coords(set1, 0, 0.25, 0.25)
}

const RED: Vec3 = Vec3::new(1.0, 0.0, 0.0);
const GREEN: Vec3 = Vec3::new(0.0, 1.0, 0.0);

#[test]
fn each_texture_reads_the_set_its_tex_coord_names() {
    let dir = tempfile::tempdir().unwrap();
    quad_file(
        dir.path(),
        json!({
            "name": "two sets",
            "pbrMetallicRoughness": {
                "baseColorTexture": {"index": 0, "texCoord": 1},
                "roughnessFactor": 1.0,
                "metallicFactor": 1.0,
                // texCoord 0, overridden by the transform's.
                "metallicRoughnessTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"texCoord": 1}}}
            },
            "emissiveFactor": [1.0, 1.0, 1.0],
            "emissiveTexture": {"index": 0},
            "alphaMode": "MASK"
        }),
    );
    let scene = scene_of(dir.path());
    assert!(!scene.warnings.iter().any(|w| w.contains("TEXCOORD")), "{:?}", scene.warnings);
    let object = scene.objects.last().unwrap();
    let mat = &scene.materials[object.material_of(0) as usize];
    let t = &mat.textures;
    assert_eq!((t.base_color.unwrap().uv_set, t.metallic_roughness.unwrap().uv_set), (1, 1));
    assert_eq!(t.emission.unwrap().uv_set, 0);
    assert!(t.reads_set1() && t.coverage_set() == 1);

    // The base colour in set 1 reads green, the emission in set 0 red; the metallic-roughness
    // texture in set 1 reads green: roughness 1, metal (blue) 0.
    let p = mat.evaluate_at(&scene.textures, &at_hit(object, true));
    assert!((p.base_color - GREEN).length() < 1e-6, "{p:?}");
    assert!((p.emission - RED).length() < 1e-6, "{p:?}");
    assert_eq!((p.roughness, p.metallic), (1.0, 0.0));
    // Read as set 0 everywhere, the same material would be red and smooth: the test can tell.
    let wrong = mat.evaluate(&scene.textures, object.uv(0, 0.25, 0.25));
    assert!((wrong.base_color - RED).length() < 1e-6 && wrong.roughness == 0.0, "{wrong:?}");

    // The coverage is the base colour texture's alpha, in its set: 255 in the right texel.
    let set1 = t.coverage_set() == 1;
    assert!(!mat.is_cut_out(&scene.textures, at_hit(object, set1)));
    assert!(mat.is_cut_out(&scene.textures, object.uv(0, 0.25, 0.25)), "set 0's texel has alpha 0");
}

#[test]
fn generated_tangents_follow_the_normal_texture_set() {
    let dir = tempfile::tempdir().unwrap();
    // Set 0's u runs along +x, set 1's along +y.
    for (set, want) in [(0, Vec3::X), (1, Vec3::Y)] {
        let file = quad_file(dir.path(), json!({"normalTexture": {"index": 0, "texCoord": set}}));
        let m = load_mesh_file(&file).unwrap();
        for tangent in m.tangents.as_ref().expect("tangents for the normal map") {
            assert!((tangent.truncate() - want).length() < 1e-5, "set {set}: {tangent}");
        }
    }
}

fn warnings(m: &LoadedMesh) -> String {
    m.warnings.join("\n")
}

#[test]
fn sets_the_mesh_lacks_fall_back_to_set_0_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    // TEXCOORD_2: never kept; the reference reads set 0 and says so.
    let m = load_mesh_file(&quad_file(
        dir.path(),
        json!({"name": "third", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 2}}}),
    ))
    .unwrap();
    assert!(warnings(&m).contains("`third`") && warnings(&m).contains("TEXCOORD_2"), "{}", warnings(&m));
    assert_eq!(m.materials[0].1.textures.base_color.unwrap().uv_set, 0);
    assert!(m.mesh.uvs1().is_none(), "no material reads set 1: not kept");

    // Set 1 asked for on a mesh without TEXCOORD_1: set 0 is read, and the warning names the
    // material, the slot and the primitive.
    let mut doc = Doc::default();
    let prim = doc.quad(None, 0);
    let material =
        json!([{"name": "decal", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}}}]);
    let doc = doc.finish(vec![prim], material);
    write(dir.path(), "quad.gltf", serde_json::to_string(&doc).unwrap().as_bytes());
    let scene = scene_of(dir.path());
    let shown = scene.warnings.join("\n");
    for part in ["`decal`", "base_color", "TEXCOORD_1", "meshes[0].primitives[0]", "TEXCOORD_0 is read"] {
        assert!(shown.contains(part), "{part} in {shown}");
    }
    let object = scene.objects.last().unwrap();
    let mat = &scene.materials[object.material_of(0) as usize];
    let p = mat.evaluate_at(&scene.textures, &at_hit(object, true));
    assert!((p.base_color - RED).length() < 1e-6, "{p:?}");

    // Two primitives of that material, the second without TEXCOORD_1: its vertices' set 1 is
    // their set 0, and the warning names it alone.
    let mut doc = Doc::default();
    let prims = vec![doc.quad(Some(&set1()), 0), doc.quad(None, 0)];
    let doc = doc.finish(prims, material_with_set1("decal"));
    let m = load_mesh_file(&write(dir.path(), "two.gltf", serde_json::to_string(&doc).unwrap().as_bytes())).unwrap();
    let (uvs0, uvs1) = (m.mesh.uvs().unwrap(), m.mesh.uvs1().expect("set 1 kept"));
    assert_eq!(uvs1.len(), 8);
    assert_eq!(uvs1[..4].iter().flat_map(|v| v.to_array()).collect::<Vec<_>>(), set1());
    assert_eq!(uvs1[4..], uvs0[4..]);
    assert!(warnings(&m).contains("meshes[0].primitives[1] has not"), "{}", warnings(&m));
    assert!(!warnings(&m).contains("primitives[0]"), "{}", warnings(&m));
}

fn material_with_set1(name: &str) -> Value {
    json!([{"name": name, "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}}}])
}

/// The quad whose set 1 is the accessor `patch` makes.
fn with_set1(dir: &Path, patch: impl Fn(&mut Doc) -> usize) -> Result<LoadedMesh, MeshFileError> {
    let mut doc = Doc::default();
    let mut prim = doc.quad(None, 0);
    prim["attributes"]["TEXCOORD_1"] = json!(patch(&mut doc));
    let doc = doc.finish(vec![prim], material_with_set1("m"));
    load_mesh_file(&write(dir, "bad set.gltf", serde_json::to_string(&doc).unwrap().as_bytes()))
}

#[test]
fn texcoord_1_is_checked_like_texcoord_0() {
    let dir = tempfile::tempdir().unwrap();
    // Three coordinates for four vertices: refused, naming the file, the attribute of the
    // primitive and the accessor.
    let e = with_set1(dir.path(), |d| d.floats(&set1()[..6], "VEC2", 2)).unwrap_err();
    let shown = e.to_string();
    for part in [
        "bad set.gltf",
        "meshes[0].primitives[0].attributes.TEXCOORD_1",
        "accessors[4] has 3 elements",
        "POSITION has 4",
    ] {
        assert!(shown.contains(part), "{part} in {shown}");
    }
    // A VEC3 accessor: the type is named.
    let e = with_set1(dir.path(), |d| d.floats(&[0.5; 12], "VEC3", 3)).unwrap_err().to_string();
    assert!(e.contains("accessors[4]") && e.contains("TEXCOORD_1 must be"), "{e}");
    // Unsigned bytes must be normalised.
    let e = with_set1(dir.path(), |d| d.accessor(&[0; 8], UNSIGNED_BYTE, "VEC2", 4, json!({}))).unwrap_err();
    assert!(e.to_string().contains("accessors[4].normalized"), "{e}");
    // Normalised unsigned bytes and shorts are read as fractions of their range.
    let bytes = [0u8, 255, 51, 102, 255, 0, 0, 0];
    let m =
        with_set1(dir.path(), |d| d.accessor(&bytes, UNSIGNED_BYTE, "VEC2", 4, json!({"normalized": true}))).unwrap();
    assert_eq!(m.mesh.uvs1().unwrap()[1].to_array(), [0.2, 0.4]);
    let shorts: Vec<u8> = [65535u16, 0, 0, 65535, 0, 0, 0, 0].iter().flat_map(|s| s.to_le_bytes()).collect();
    let m =
        with_set1(dir.path(), |d| d.accessor(&shorts, UNSIGNED_SHORT, "VEC2", 4, json!({"normalized": true}))).unwrap();
    assert_eq!(m.mesh.uvs1().unwrap()[..2].iter().map(|v| v.to_array()).collect::<Vec<_>>(), [[1.0, 0.0], [0.0, 1.0]]);
}
