//! OBJ + MTL materials end to end: texture statements resolved beside the MTL file, texture
//! coordinates flipped to englobe's convention, coverage from `map_d`, normal and bump maps with
//! tangents, missing textures as warnings, and the shared Cornell box's boxes.

use std::path::{Path, PathBuf};

use englobe::{Vec2, Vec3};
use englobe_scene::mesh::load_mesh_file;
use englobe_scene::shared_data::shared_meshes_or_panic;
use englobe_scene::{AlphaMode, Channel, MISSING_TEXTURE_COLOR, MaterialModel, NormalEncoding};

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    if let Some(parent) = p.parent() {
        std::fs::create_dir_all(parent).unwrap();
    }
    std::fs::write(&p, bytes).unwrap();
    p
}

fn png(w: u32, h: u32, texels: &[[u8; 4]]) -> Vec<u8> {
    let img = image::RgbaImage::from_raw(w, h, texels.iter().flatten().copied().collect()).unwrap();
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// A quad with texture coordinates in OBJ's convention (v up): the corner at y = 1 has vt v = 1.
const QUAD: &str = "mtllib lib/m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3 4/4\n";

#[test]
fn maps_resolve_beside_the_library_and_coordinates_flip() {
    let dir = tempfile::tempdir().unwrap();
    // Top row red, bottom row blue: in OBJ's convention the top of the image is v = 1.
    write(dir.path(), "lib/tex/rb.png", &png(1, 2, &[[255, 0, 0, 255], [0, 0, 255, 255]]));
    write(dir.path(), "lib/tex/cut.png", &png(2, 1, &[[0, 0, 0, 0], [255, 255, 255, 255]]));
    write(
        dir.path(),
        "lib/m.mtl",
        b"newmtl m\nKd 1 1 1\nd 0.9\nillum 2\nmap_Kd -clamp on tex/rb.png\nmap_d tex/cut.png\nmap_Ks missing.png\n",
    );
    let m = load_mesh_file(&write(dir.path(), "q.obj", QUAD.as_bytes())).unwrap();
    let uvs = m.mesh.uvs().unwrap();
    let top = m.mesh.positions().iter().position(|p| *p == Vec3::new(0.0, 1.0, 0.0)).unwrap();
    assert_eq!(uvs[top], Vec2::new(0.0, 0.0), "vt (0, 1) is the image's top-left corner");
    let mat = &m.materials[0].1;
    let at = |u: f32, v_obj: f32| Some(Vec2::new(u, 1.0 - v_obj));
    let red = mat.evaluate(&m.textures, at(0.5, 0.95)).base_color;
    let blue = mat.evaluate(&m.textures, at(0.5, 0.05)).base_color;
    assert!((red - Vec3::X).length() < 1e-6 && (blue - Vec3::Z).length() < 1e-6, "{red} {blue}");
    assert_eq!(
        m.textures[mat.textures.base_color.unwrap().texture as usize].sampler.wrap_v,
        englobe_scene::Wrap::ClampToEdge
    );
    // map_d: cut out on the left (alpha 0), kept on the right; the factor is d.
    assert_eq!((mat.alpha.mode, mat.alpha.factor), (AlphaMode::Mask { cutoff: 0.5 }, 0.9));
    assert_eq!(mat.textures.alpha.unwrap().channel, Channel::Alpha, "the image has alpha");
    assert!(mat.is_cut_out(&m.textures, at(0.1, 0.5)) && !mat.is_cut_out(&m.textures, at(0.9, 0.5)));
    // The missing map_Ks is a warning naming the material and the file; the texture is kept as
    // unreadable, which leaves the material's factors alone.
    let w = m.warnings.join("\n");
    assert!(w.contains("`m`") && w.contains("missing.png"), "{w}");
    let specular = mat.textures.specular.unwrap().texture as usize;
    assert!(m.textures[specular].image.is_none());
}

#[test]
fn bump_and_normal_maps_get_tangents() {
    let dir = tempfile::tempdir().unwrap();
    // A grey height ramp and a flat normal map.
    write(dir.path(), "lib/h.png", &png(2, 1, &[[0, 0, 0, 255], [255, 255, 255, 255]]));
    write(dir.path(), "lib/n.png", &png(1, 1, &[[128, 128, 255, 255]]));
    write(dir.path(), "lib/m.mtl", b"newmtl m\nKd 1 1 1\nbump -bm 0.5 -imfchan r h.png\nnewmtl n\nmap_Bump n.png\n");
    let m = load_mesh_file(&write(dir.path(), "q.obj", QUAD.as_bytes())).unwrap();
    let bump = m.materials[0].1.textures.normal.unwrap();
    assert_eq!((bump.scale, bump.encoding), (0.5, NormalEncoding::Height(Channel::Red)));
    let t = m.tangents.as_ref().expect("tangents for the bump map");
    // u along +x and the image upright (OBJ's v up along +y): tangent +x, bitangent +y.
    assert!(t.iter().all(|t| (t.truncate() - Vec3::X).length() < 1e-5 && t.w == 1.0), "{t:?}");
    // A bump map whose image is a normal map is read as one.
    let n = m.materials[1].1.textures.normal.unwrap();
    assert_eq!(n.encoding, NormalEncoding::TangentSpace);
}

#[test]
fn an_unreadable_diffuse_map_is_magenta_and_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "lib/broken.png", b"\x89PNG\r\n\x1a\n not really");
    write(dir.path(), "lib/m.mtl", b"newmtl m\nKd 0.5 0.5 0.5\nmap_Kd broken.png\n");
    let m = load_mesh_file(&write(dir.path(), "q.obj", QUAD.as_bytes())).unwrap();
    let mat = &m.materials[0].1;
    assert_eq!(mat.evaluate(&m.textures, Some(Vec2::ZERO)).base_color, MISSING_TEXTURE_COLOR);
    assert!(m.warnings.iter().any(|w| w.contains("broken.png") && w.contains("magenta")), "{:?}", m.warnings);
}

#[test]
fn the_cornell_box_boxes_are_white() {
    let path =
        shared_meshes_or_panic(Path::new(env!("CARGO_MANIFEST_DIR"))).join("cornell-box/CornellBox-Original.obj");
    let m = load_mesh_file(&path).unwrap();
    for name in ["shortBox", "tallBox"] {
        let mat = &m.materials.iter().find(|(n, _)| n == name).unwrap().1;
        // The file gives the boxes Kd 0 0 0 and their white as Ka (and Ks).
        assert_eq!(mat.diffuse, Vec3::new(0.725, 0.71, 0.68), "{name}");
        // Ks white, Ns 200, Ni 1.44: a white plastic, its layer rough by alpha = sqrt(2 / 202).
        let roughness = (2.0f32 / 202.0).sqrt().sqrt();
        assert_eq!(mat.model, MaterialModel::MetallicRoughness { metallic: 0.0, roughness, transmission: 0.0 });
        assert_eq!(mat.ior, 1.44, "{name}");
    }
    let walls = &m.materials.iter().find(|(n, _)| n == "leftWall").unwrap().1;
    assert_eq!(walls.diffuse, Vec3::new(0.63, 0.065, 0.05));
    // Ks 0: Lambert, no specular layer (index 1).
    assert_eq!(walls.ior, 1.0);
    assert!(matches!(walls.model, MaterialModel::MetallicRoughness { metallic: 0.0, transmission: 0.0, .. }));
    // The walls and box faces meet at about right angles: smoothing at 60 degrees joins only the
    // two slightly bent halves of each quad (the measured box is not square), never two faces,
    // which would tilt normals by about 45 degrees.
    let normals = m.mesh.normals().unwrap();
    let mut worst = 0.0f32;
    for i in 0..m.mesh.len() as u32 {
        for &v in &m.mesh.triangles()[i as usize] {
            worst = worst.max(normals[v as usize].angle_between(m.mesh.geometric_normal(i)).to_degrees());
        }
    }
    assert!(worst < 1.0, "a shading normal {worst} degrees off its face");
}

#[test]
fn the_teapot_is_smooth() {
    let path = shared_meshes_or_panic(Path::new(env!("CARGO_MANIFEST_DIR"))).join("teapot/teapot.obj");
    let m = load_mesh_file(&path).unwrap();
    let normals = m.mesh.normals().expect("generated normals");
    // Smooth: most vertices are shared by their triangles (few creases split them), and the
    // normals vary inside triangles.
    assert!(m.mesh.positions().len() < 2 * 3644, "{} vertices", m.mesh.positions().len());
    let varying = (0..m.mesh.len())
        .filter(|&i| {
            let [a, b, c] = m.mesh.triangles()[i];
            normals[a as usize].dot(normals[b as usize]) < 0.9999
                || normals[a as usize].dot(normals[c as usize]) < 0.9999
        })
        .count();
    assert!(varying > m.mesh.len() * 9 / 10, "{varying} of {}", m.mesh.len());
}
