//! glTF materials on small files made here (JSON with base64 buffers, images as files, data URIs
//! and GLB buffer views), and on the DamagedHelmet sample: factors, textures in their slots,
//! samplers, alpha, extensions, tangents, and the warnings of what cannot be read.

mod common;

use std::path::Path;

use common::{base64, png, write};
use englobe::{Vec2, Vec3};
use englobe_scene::mesh::{LoadedMesh, load_mesh_file};
use englobe_scene::shared_data::shared_meshes_or_panic;
use englobe_scene::{AlphaMode, MISSING_TEXTURE_COLOR, MaterialModel, NormalEncoding, Wrap, load_scene};
use serde_json::json;

/// A unit quad in the xy plane facing +z: positions, normals, texture coordinates (the image
/// upright: u along +x, v down along -y) and indices.
fn quad_buffer() -> Vec<u8> {
    let mut bin = Vec::new();
    let f = |bin: &mut Vec<u8>, v: &[f32]| v.iter().for_each(|c| bin.extend(c.to_le_bytes()));
    f(&mut bin, &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0]);
    f(&mut bin, &[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
    f(&mut bin, &[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0]);
    [0u16, 1, 2, 0, 2, 3].iter().for_each(|i| bin.extend(i.to_le_bytes()));
    bin
}

fn quad_doc(buffer_uri: Option<String>, buffer_len: usize) -> serde_json::Value {
    let mut buffer = json!({"byteLength": buffer_len});
    if let Some(uri) = buffer_uri {
        buffer["uri"] = json!(uri);
    }
    json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
        "buffers": [buffer],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 48},
            {"buffer": 0, "byteOffset": 96, "byteLength": 32},
            {"buffer": 0, "byteOffset": 128, "byteLength": 12}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ]
    })
}

/// The quad with a material using a texture file beside it (base colour), a data URI
/// (metallic-roughness) and a missing file (emission), and a normal map.
fn textured(dir: &Path) -> LoadedMesh {
    let bin = quad_buffer();
    let mut doc = quad_doc(Some(format!("data:application/octet-stream;base64,{}", base64(&bin))), bin.len());
    // Base colour: left half sRGB 188 red, right half white, alpha 0 then 255.
    write(dir, "base color.png", &png(2, 1, &[[188, 0, 0, 0], [255, 255, 255, 255]]));
    let mr = png(1, 1, &[[0, 128, 255, 255]]);
    let normal = png(1, 1, &[[128, 128, 255, 255]]);
    doc["images"] = json!([
        {"uri": "base%20color.png"},
        {"uri": format!("data:image/png;base64,{}", base64(&mr))},
        {"uri": "missing.png"},
        {"uri": format!("data:image/png;base64,{}", base64(&normal))}
    ]);
    doc["samplers"] = json!([{"wrapS": 33071, "wrapT": 33648, "magFilter": 9728}]);
    doc["textures"] = json!([{"source": 0, "sampler": 0}, {"source": 1}, {"source": 2}, {"source": 3}]);
    doc["extensionsUsed"] = json!([
        "KHR_materials_emissive_strength",
        "KHR_materials_ior",
        "KHR_materials_transmission",
        "KHR_texture_transform"
    ]);
    doc["materials"] = json!([{
        "name": "painted",
        "pbrMetallicRoughness": {
            "baseColorFactor": [1.0, 0.5, 1.0, 0.8],
            "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [1.0, 1.0], "offset": [0.0, 0.0]}}},
            "metallicFactor": 0.5,
            "roughnessFactor": 0.25,
            "metallicRoughnessTexture": {"index": 1, "texCoord": 1}
        },
        "normalTexture": {"index": 3, "scale": 2.0},
        "emissiveFactor": [1.0, 0.5, 0.25],
        "emissiveTexture": {"index": 2},
        "alphaMode": "MASK",
        "alphaCutoff": 0.3,
        "doubleSided": true,
        "extensions": {
            "KHR_materials_emissive_strength": {"emissiveStrength": 4.0},
            "KHR_materials_ior": {"ior": 1.33},
            "KHR_materials_transmission": {"transmissionFactor": 0.75}
        }
    }]);
    let file = write(dir, "quad.gltf", serde_json::to_string(&doc).unwrap().as_bytes());
    load_mesh_file(&file).unwrap()
}

#[test]
fn factors_extensions_and_alpha() {
    let dir = tempfile::tempdir().unwrap();
    let m = textured(dir.path());
    let (name, mat) = &m.materials[0];
    assert_eq!(name, "painted");
    assert_eq!(mat.diffuse, Vec3::new(1.0, 0.5, 1.0));
    assert_eq!(mat.model, MaterialModel::MetallicRoughness { metallic: 0.5, roughness: 0.25, transmission: 0.75 });
    assert_eq!(mat.emission, Vec3::new(4.0, 2.0, 1.0), "emissive strength 4");
    assert_eq!((mat.ior, mat.double_sided), (1.33, true));
    assert_eq!((mat.alpha.mode, mat.alpha.factor), (AlphaMode::Mask { cutoff: 0.3 }, 0.8));
    assert!(mat.textures.base_color.unwrap().transform.is_some());
    assert_eq!(mat.textures.metallic_roughness.unwrap().uv_set, 1);
}

#[test]
fn textures_land_in_their_slots_and_sample_by_hand() {
    let dir = tempfile::tempdir().unwrap();
    let m = textured(dir.path());
    let mat = &m.materials[0].1;
    let t = &mat.textures;
    let texture = |r: englobe_scene::TextureRef| m.textures[r.texture as usize].clone();
    assert_eq!(texture(t.base_color.unwrap()).name, "base color.png");
    let s = texture(t.base_color.unwrap()).sampler;
    assert_eq!(
        (s.wrap_u, s.wrap_v, s.filter),
        (Wrap::ClampToEdge, Wrap::MirroredRepeat, englobe_scene::texture::Filter::Nearest)
    );
    assert!(texture(t.metallic_roughness.unwrap()).image.is_some(), "data URI decoded");
    assert!(texture(t.emission.unwrap()).image.is_none(), "missing file kept as unreadable");
    let n = t.normal.unwrap();
    assert_eq!((n.scale, n.encoding), (2.0, NormalEncoding::TangentSpace));

    // The left texel (nearest filter): sRGB 188 -> 0.5029, times the factor's red 1; alpha 0
    // times 0.8 is under the cutoff: cut out. The right texel: white, alpha 0.8: kept.
    let left = mat.evaluate(&m.textures, Some(Vec2::new(0.25, 0.5)));
    assert!((left.base_color - Vec3::new(0.5029, 0.0, 0.0)).abs().max_element() < 1e-3, "{left:?}");
    assert!(mat.is_cut_out(&m.textures, Some(Vec2::new(0.25, 0.5))));
    assert!(!mat.is_cut_out(&m.textures, Some(Vec2::new(0.75, 0.5))));
    // Metal in blue (255), roughness in green (128), times the factors.
    assert!((left.metallic - 0.5).abs() < 1e-6 && (left.roughness - 0.25 * 128.0 / 255.0).abs() < 1e-6);
    // The missing emissive texture: no glow.
    assert_eq!(left.emission, Vec3::ZERO);
    // Normal texel (128, 128, 255): nearly +z, with x and y scaled by 2.
    let nz = left.normal_ts.unwrap();
    let c = 2.0 * 128.0 / 255.0 - 1.0;
    assert!((nz - Vec3::new(2.0 * c, 2.0 * c, 1.0).normalize()).length() < 1e-6);

    let warnings = m.warnings.join("\n");
    assert!(
        warnings.contains("`painted`") && warnings.contains("missing.png") && warnings.contains("does not glow"),
        "{warnings}"
    );
    // The metallic-roughness texture asks for TEXCOORD_1, which the quad has not: it reads
    // TEXCOORD_0 (as sampled above), the mesh keeps no second set, and a warning says so.
    assert!(
        warnings.contains("`painted`: its metallic_roughness texture reads TEXCOORD_1")
            && warnings.contains("TEXCOORD_0 is read there instead"),
        "{warnings}"
    );
    assert!(m.mesh.uvs1().is_none());
}

#[test]
fn tangents_are_generated_for_normal_maps_and_read_from_files() {
    let dir = tempfile::tempdir().unwrap();
    let m = textured(dir.path());
    // The quad's u runs along +x and its image is upright: tangent +x, bitangent +y (w = 1).
    let t = m.tangents.as_ref().expect("MikkTSpace tangents for the normal map");
    assert_eq!(t.len(), m.mesh.positions().len());
    for tangent in t {
        assert!((tangent.truncate() - Vec3::X).length() < 1e-5 && tangent.w == 1.0, "{tangent}");
    }

    // A file with its own TANGENT attribute, and a node that mirrors x: tangents move with the
    // surface and the handedness flips.
    let mut bin = quad_buffer();
    for _ in 0..4 {
        [0.0f32, 1.0, 0.0, -1.0].iter().for_each(|c| bin.extend(c.to_le_bytes()));
    }
    let mut doc = quad_doc(Some(format!("data:application/octet-stream;base64,{}", base64(&bin))), bin.len());
    doc["bufferViews"].as_array_mut().unwrap().push(json!({"buffer": 0, "byteOffset": 140, "byteLength": 64}));
    doc["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC4"}));
    doc["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = json!(4);
    doc["meshes"][0]["primitives"][0].as_object_mut().unwrap().remove("material");
    doc["nodes"][0]["scale"] = json!([-1.0, 2.0, 1.0]);
    let file = write(dir.path(), "tangents.gltf", serde_json::to_string(&doc).unwrap().as_bytes());
    let m = load_mesh_file(&file).unwrap();
    for tangent in m.tangents.as_ref().expect("the file's tangents") {
        assert!((tangent.truncate() - Vec3::Y).length() < 1e-6 && tangent.w == 1.0, "{tangent}");
    }
}

#[test]
fn images_in_glb_buffer_views() {
    let dir = tempfile::tempdir().unwrap();
    let mut bin = quad_buffer();
    let image = png(1, 1, &[[10, 20, 30, 255]]);
    let image_at = bin.len();
    bin.extend(&image);
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let mut doc = quad_doc(None, bin.len());
    doc["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 0, "byteOffset": image_at, "byteLength": image.len()}));
    doc["images"] = json!([{"bufferView": 4, "mimeType": "image/png"}]);
    doc["textures"] = json!([{"source": 0}]);
    doc["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    let mut json_bytes = serde_json::to_vec(&doc).unwrap();
    while json_bytes.len() % 4 != 0 {
        json_bytes.push(b' ');
    }
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + json_bytes.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend((json_bytes.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json_bytes);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&bin);
    let m = load_mesh_file(&write(dir.path(), "q.glb", &glb)).unwrap();
    let (name, mat) = &m.materials[0];
    assert_eq!(name, "material 0");
    let p = mat.evaluate(&m.textures, Some(Vec2::new(0.5, 0.5)));
    let want = Vec3::new(10.0, 20.0, 30.0).map(|c| englobe_scene::texture::srgb_to_linear(c / 255.0));
    assert!((p.base_color - want).abs().max_element() < 1e-6, "{p:?}");
    assert_eq!(
        mat.model,
        MaterialModel::MetallicRoughness { metallic: 1.0, roughness: 1.0, transmission: 0.0 },
        "glTF defaults"
    );
    assert!(!mat.double_sided && mat.alpha.mode == AlphaMode::Opaque);
}

#[test]
fn a_scene_appends_file_textures_after_its_own() {
    let dir = tempfile::tempdir().unwrap();
    textured(dir.path());
    write(dir.path(), "wood.png", &png(1, 1, &[[200, 100, 50, 255]]));
    let scene = write(
        dir.path(),
        "s.toml",
        b"[image]\nwidth = 4\nheight = 4\n[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n\
          [materials.wood]\nbase_color_texture = \"wood.png\"\n[materials.lost]\nbase_color_texture = \"gone.png\"\n\
          [[mesh]]\npath = \"quad.gltf\"\n",
    );
    let scene = load_scene(&scene).unwrap();
    assert_eq!(scene.textures.len(), 2 + 4);
    let wood = &scene.materials[scene.material_names.iter().position(|n| n == "wood").unwrap()];
    assert_eq!(wood.textures.base_color.unwrap().texture, 1, "materials are read in name order: lost, wood");
    let lost = &scene.materials[scene.material_names.iter().position(|n| n == "lost").unwrap()];
    assert_eq!(lost.evaluate(&scene.textures, Some(Vec2::ZERO)).base_color, MISSING_TEXTURE_COLOR);
    assert!(scene.warnings.iter().any(|w| w.contains("`lost`") && w.contains("gone.png")), "{:?}", scene.warnings);
    let painted = &scene.materials[scene.material_names.iter().position(|n| n == "quad.gltf:painted").unwrap()];
    assert_eq!(scene.textures[painted.textures.base_color.unwrap().texture as usize].name, "base color.png");
    // The object's texture coordinates and tangents at a hit: barycentric (u, v) weighs
    // vertices 1 and 2 of the triangle, here corners (1, 0) and (1, 1) of the quad.
    let object = scene.objects.last().unwrap();
    let uv = object.uv(0, 0.25, 0.5).unwrap();
    // uv of vertex 0 (0, 1), 1 (1, 1), 2 (1, 0): 0.25 * (1, 1) + 0.5 * (1, 0) + 0.25 * (0, 1).
    assert!((uv - Vec2::new(0.75, 0.5)).length() < 1e-6, "{uv}");
    let t = object.tangent(0, 0.25, 0.5).unwrap();
    assert!((t.truncate() - Vec3::X).length() < 1e-5 && t.w == 1.0);
}

#[test]
fn the_damaged_helmet_has_its_five_textures() {
    let path =
        shared_meshes_or_panic(Path::new(env!("CARGO_MANIFEST_DIR"))).join("gltf/DamagedHelmet/DamagedHelmet.gltf");
    let m = load_mesh_file(&path).unwrap();
    assert_eq!(m.textures.len(), 5);
    for t in &m.textures {
        let image = t.image.as_ref().unwrap_or_else(|| panic!("{}: {:?}", t.name, t.error));
        assert_eq!((image.width(), image.height()), (2048, 2048), "{}", t.name);
    }
    let mat = &m.materials[0].1;
    let file = |r: Option<englobe_scene::TextureRef>| m.textures[r.unwrap().texture as usize].name.clone();
    let t = &mat.textures;
    assert_eq!(file(t.base_color), "Default_albedo.jpg");
    assert_eq!(file(t.metallic_roughness), "Default_metalRoughness.jpg");
    assert_eq!(file(t.emission), "Default_emissive.jpg");
    assert_eq!(file(t.normal.map(|n| n.texture)), "Default_normal.jpg");
    assert_eq!(file(t.occlusion.map(|o| o.texture)), "Default_AO.jpg");
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    let tangents = m.tangents.as_ref().expect("generated for the normal map");
    let normals = m.mesh.normals().unwrap();
    // Tangents are unit and perpendicular to the normals.
    let worst = tangents.iter().zip(normals).map(|(t, n)| t.truncate().dot(n.normalize()).abs()).fold(0.0, f32::max);
    assert!(worst < 1e-4, "{worst}");
    assert!(tangents.iter().all(|t| (t.truncate().length() - 1.0).abs() < 1e-4 && t.w.abs() == 1.0));
}
