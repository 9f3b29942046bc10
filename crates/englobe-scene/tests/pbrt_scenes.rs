//! pbrt-v4 scenes: the reference Cornell box read to its known camera, film, lights and
//! materials; pbrt-v3's killeroo read with a report of what is not supported; transforms,
//! orientation and units against pbrt's definitions; and every kind of malformed file refused at
//! its file, line and column.

use std::path::{Path, PathBuf};

use englobe::{Object, Vec2, Vec3};
use englobe_scene::pbrt::{is_pbrt_path, load, parse};
use englobe_scene::shared_data::locate_shared;
use englobe_scene::{Light, MaterialModel, PixelFilter, SamplerKind, Scene, SceneError};

fn shared_scenes() -> PathBuf {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    locate_shared(here)
        .unwrap_or_else(|| panic!("the shared scene data was not found above {}", here.display()))
        .join("scenes")
}

fn scene(text: &str) -> Scene {
    parse(text, "test.pbrt".as_ref(), false).unwrap_or_else(|e| panic!("{e}"))
}

fn error(text: &str, strict: bool) -> String {
    match parse(text, "test.pbrt".as_ref(), strict) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// `file:line:column` of the first occurrence of `what` in `text`.
fn place(file: &str, text: &str, what: &str) -> String {
    let at = text.find(what).unwrap_or_else(|| panic!("`{what}` not in the text"));
    let line = text[..at].matches('\n').count() + 1;
    let column = at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
    format!("{file}:{line}:{column}")
}

fn close(a: Vec3, b: Vec3, eps: f32) -> bool {
    (a - b).abs().max_element() <= eps
}

#[test]
fn the_cornell_box_reads_as_its_readme_says() {
    let path = shared_scenes().join("cornell-bitterli/scene-v4.pbrt");
    assert!(is_pbrt_path(&path));
    // Nothing in it changes the picture, so strict reading accepts it.
    let s = load(&path, true).unwrap_or_else(|e| panic!("{e}"));
    let c = &s.camera;
    assert!(close(c.position, Vec3::new(0.0, 1.0, 6.8), 1e-5), "{}", c.position);
    assert!(close((c.look_at - c.position).normalize(), Vec3::new(0.0, 0.0, -1.0), 1e-6));
    assert!(close(c.look_at, Vec3::new(0.0, 1.0, 0.0), 1e-5), "looks at the box's centre: {}", c.look_at);
    assert!(close(c.up, Vec3::Y, 1e-6));
    assert!((c.fov_degrees - 19.5).abs() < 1e-4, "square image: the shorter axis is the vertical one");
    // The matrix flips z, so its frame is right-handed like englobe's: no mirroring needed.
    assert!(!c.left_handed);
    let i = &s.image;
    assert_eq!((i.width, i.height, i.samples, i.max_depth), (1024, 1024, 64, 65));
    assert_eq!(i.filter, PixelFilter::Triangle { radius: Vec2::splat(1.0) });
    assert_eq!(i.integrator, englobe_scene::IntegratorKind::Path);
    assert_eq!(s.objects.len(), 8);
    assert!(s.lights.is_empty() && i.background == Vec3::ZERO);
    let material = |name: &str| &s.materials[s.material_names.iter().position(|n| n == name).unwrap()];
    assert_eq!(material("LeftWall").diffuse, Vec3::new(0.63, 0.065, 0.05));
    assert_eq!(material("RightWall").diffuse, Vec3::new(0.14, 0.45, 0.091));
    assert_eq!(material("BackWall").diffuse, Vec3::new(0.725, 0.71, 0.68));
    // The quad at y = 1.98 emits (17, 12, 4) downwards, from a black diffuse material.
    let emitters: Vec<_> =
        s.objects.iter().filter(|o| s.materials[o.material as usize].emission != Vec3::ZERO).collect();
    assert_eq!(emitters.len(), 1);
    let light = &s.materials[emitters[0].material as usize];
    assert_eq!((light.emission, light.diffuse), (Vec3::new(17.0, 12.0, 4.0), Vec3::ZERO));
    let Object::Mesh(quad) = &emitters[0].object else { panic!("the light is a mesh") };
    assert!(quad.positions().iter().all(|p| (p.y - 1.98).abs() < 1e-6));
    for t in 0..quad.len() as u32 {
        assert!(close(quad.geometric_normal(t), -Vec3::Y, 1e-5), "faces down");
    }
    // The red wall is the mesh at x = -1.
    let red = s.objects.iter().find(|o| s.material_names[o.material as usize] == "LeftWall").unwrap();
    let Object::Mesh(wall) = &red.object else { panic!() };
    assert!(wall.positions().iter().all(|p| (p.x + 1.0).abs() < 1e-6));
    // Only what does not change the picture is reported: the film's file name (its "sobol"
    // sampler is englobe's Sobol sampler).
    assert_eq!(s.image.sampler, englobe_scene::SamplerKind::Sobol);
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert!(s.warnings.iter().all(|w| w.contains(": ignored: ")), "{:?}", s.warnings);
    assert!(s.warnings[0].contains("scene-v4.pbrt:10:5") && s.warnings[0].contains("cornell-box.png"));
}

#[test]
fn the_killeroo_names_what_it_does_not_support() {
    let path = shared_scenes().join("meshes/pbrt-killeroo/killeroo-simple.pbrt");
    let s = load(&path, false).unwrap_or_else(|e| panic!("{e}"));
    let all = s.warnings.join("\n");
    let sub = s.warnings.iter().find(|w| w.contains("loopsubdiv")).unwrap_or_else(|| panic!("{all}"));
    assert!(sub.contains("geometry/killeroo.pbrt:1:5: approximated: ") && sub.contains("2 times"), "{sub}");
    assert!(all.contains("plastic"), "{all}");
    assert_eq!((s.image.width, s.image.height, s.image.samples), (700, 700, 8));
    // Two killeroos of 4158 control triangles, two quads and the tessellated lamp.
    assert_eq!(s.objects.len(), 5);
    assert!(s.materials.iter().any(|m| m.emission == Vec3::splat(2000.0)));
    // LookAt makes pbrt's left-handed camera frame.
    assert!(s.camera.left_handed);
    // Strict: refused at the first approximation, the light's tessellated sphere.
    let e = load(&path, true).unwrap_err().to_string();
    assert!(e.contains("killeroo-simple.pbrt:24:1: ") && e.contains("refused under --strict"), "{e}");
}

#[test]
fn the_camera_follows_pbrts_frame_and_field_of_view() {
    let base = |film: &str, transform: &str| {
        scene(&format!("{transform}\nCamera \"perspective\" \"float fov\" [ 60 ]\n{film}\nWorldBegin\n"))
    };
    // LookAt: pbrt's camera x is up x dir, a left-handed frame.
    let s = base("Film \"rgb\" \"integer xresolution\" 200 \"integer yresolution\" 100", "LookAt 0 0 5  0 0 0  0 1 0");
    assert!(s.camera.left_handed);
    assert!(close(s.camera.position, Vec3::new(0.0, 0.0, 5.0), 1e-6));
    assert!((s.camera.fov_degrees - 60.0).abs() < 1e-4, "landscape: the shorter axis is vertical");
    // The usual `Scale -1 1 1` before LookAt mirrors it back to a right-handed frame.
    let s = base(
        "Film \"rgb\" \"integer xresolution\" 200 \"integer yresolution\" 100",
        "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0",
    );
    assert!(!s.camera.left_handed);
    // Portrait: 60 degrees across the width, so tan(v / 2) = tan(30) * 2 vertically.
    let s = base("Film \"rgb\" \"integer xresolution\" 100 \"integer yresolution\" 200", "");
    let v = 2.0 * (30f32.to_radians().tan() * 2.0).atan().to_degrees();
    assert!((s.camera.fov_degrees - v).abs() < 1e-3, "{} vs {v}", s.camera.fov_degrees);
    // No camera: pbrt's default at the origin looking down +z, fov 90, 1280x720.
    let s = scene("WorldBegin\n");
    assert_eq!((s.image.width, s.image.height), (1280, 720));
    assert!(close(s.camera.look_at - s.camera.position, Vec3::Z, 1e-6) && s.camera.fov_degrees == 90.0);
}

#[test]
fn transforms_compose_as_pbrt_writes_them() {
    // Translate then Rotate: the sphere's centre (at 1 0 0 in its space) is turned, then moved.
    let s =
        scene("WorldBegin\nTranslate 0 0 10\nRotate 90 0 0 1\nTranslate 1 0 0\nShape \"sphere\" \"float radius\" 2\n");
    let Object::Shape(englobe::Shape::Sphere(sp)) = &s.objects[0].object else { panic!() };
    assert!(close(sp.center, Vec3::new(0.0, 1.0, 10.0), 1e-6), "{}", sp.center);
    // Attributes restore the matrix and the material; TransformBegin only the matrix.
    let s = scene(
        "WorldBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0.1 0.2 0.3]\nAttributeBegin\nTranslate 5 0 0\n\
         Material \"diffuse\"\nAttributeEnd\nTransformBegin\nScale 2 2 2\nTransformEnd\n\
         Shape \"sphere\"\nCoordinateSystem \"here\"\nTranslate 1 1 1\nCoordSysTransform \"here\"\nShape \"sphere\"",
    );
    for o in &s.objects {
        let Object::Shape(englobe::Shape::Sphere(sp)) = &o.object else { panic!() };
        assert_eq!((sp.center, sp.radius), (Vec3::ZERO, 1.0));
        assert_eq!(s.materials[o.material as usize].diffuse, Vec3::new(0.1, 0.2, 0.3));
    }
    // Transform takes its numbers by columns: the translation is last.
    let s = scene("WorldBegin\nTransform [1 0 0 0  0 1 0 0  0 0 1 0  3 4 5 1]\nShape \"sphere\"");
    let Object::Shape(englobe::Shape::Sphere(sp)) = &s.objects[0].object else { panic!() };
    assert_eq!(sp.center, Vec3::new(3.0, 4.0, 5.0));
}

/// The geometric normal of the first triangle of the scene's only mesh.
fn facing(text: &str) -> Vec3 {
    let s = scene(text);
    let Object::Mesh(m) = &s.objects[0].object else { panic!("a mesh") };
    m.geometric_normal(0)
}

#[test]
fn triangles_face_where_pbrt_says() {
    let tri = "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]";
    assert!(close(facing(&format!("WorldBegin\n{tri}")), Vec3::Z, 1e-6), "the winding's side");
    assert!(close(facing(&format!("WorldBegin\nReverseOrientation\n{tri}")), -Vec3::Z, 1e-6));
    // A mirroring transform swaps handedness: pbrt flips the normal back to the transformed one.
    assert!(close(facing(&format!("WorldBegin\nScale 1 1 -1\n{tri}")), -Vec3::Z, 1e-6));
    assert!(close(facing(&format!("WorldBegin\nScale -1 1 1\n{tri}")), Vec3::Z, 1e-6));
    // With normals, the normals decide, whatever the winding or ReverseOrientation.
    let with_n = format!("{tri} \"normal N\" [0 0 -1 0 0 -1 0 0 -1]");
    assert!(close(facing(&format!("WorldBegin\n{with_n}")), -Vec3::Z, 1e-6));
    assert!(close(facing(&format!("WorldBegin\nReverseOrientation\n{with_n}")), -Vec3::Z, 1e-6));
}

#[test]
fn lights_are_converted_to_englobes_units() {
    let s = scene(
        "WorldBegin\nAttributeBegin\nTranslate 0 3 0\nLightSource \"point\" \"rgb I\" [2 4 6] \"float scale\" 1.5\nAttributeEnd\n\
         LightSource \"distant\" \"point3 from\" [0 10 0] \"point3 to\" [0 0 0] \"rgb L\" [3 3 3]\n\
         LightSource \"infinite\" \"rgb L\" [0.1 0.2 0.3]\nLightSource \"infinite\" \"rgb L\" [0.1 0.1 0.1] \"float scale\" 2\n\
         LightSource \"point\" \"float power\" 100\n",
    );
    let pi = std::f32::consts::PI;
    // englobe's point light power is pbrt's intensity over pi; its directional radiance pbrt's
    // over pi; the sky's radiance is a radiance in both.
    assert_eq!(s.lights[0], Light::Point { position: Vec3::new(0.0, 3.0, 0.0), power: Vec3::new(3.0, 6.0, 9.0) / pi });
    let Light::Directional { direction, radiance } = s.lights[1] else { panic!() };
    assert!(close(direction, -Vec3::Y, 1e-6) && close(radiance, Vec3::splat(3.0 / pi), 1e-6));
    assert!(close(s.image.background, Vec3::new(0.3, 0.4, 0.5), 1e-6));
    // A power of 100 W from a point is an intensity of 100 / (4 pi).
    let Light::Point { power, .. } = s.lights[2] else { panic!() };
    assert!(close(power, Vec3::splat(100.0 / (4.0 * pi) / pi), 1e-5), "{power}");
    // An area light's power spreads over its shape's area: a unit quad emitting 10 W one-sidedly
    // has radiance 10 / (pi * 1).
    let s = scene(
        "WorldBegin\nAreaLightSource \"diffuse\" \"float power\" 10\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 1 0 0 1 0] \"integer indices\" [0 1 2 0 2 3]",
    );
    assert!(close(s.materials[s.objects[0].material as usize].emission, Vec3::splat(10.0 / pi), 1e-5));
    // A black body has luminance 1; an environment map is reported, not read.
    let s = scene(
        "WorldBegin\nLightSource \"point\" \"blackbody I\" [3000]\nLightSource \"infinite\" \"string filename\" \"sky.exr\"",
    );
    let Light::Point { power, .. } = s.lights[0] else { panic!() };
    let y = (0.2126 * power.x + 0.7152 * power.y + 0.0722 * power.z) * pi;
    assert!((y - 1.0).abs() < 0.01 && power.x > power.z, "{power}");
    assert!(
        s.warnings.iter().any(|w| w.contains("test.pbrt:3:24: skipped: ") && w.contains("sky.exr")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn materials_map_to_their_bsdfs_and_say_what_is_approximated() {
    let s = scene(
        "WorldBegin\nMakeNamedMaterial \"glass\" \"string type\" \"dielectric\" \"float eta\" 1.33\n\
         MakeNamedMaterial \"chrome\" \"string type\" \"conductor\" \"rgb reflectance\" [0.9 0.9 0.9]\n\
         MakeNamedMaterial \"frosted\" \"string type\" \"dielectric\" \"float roughness\" 0.3\n\
         MakeNamedMaterial \"coat\" \"string type\" \"coateddiffuse\" \"rgb reflectance\" [0.5 0.2 0.1]\n\
         MakeNamedMaterial \"gold\" \"string type\" \"conductor\" \"spectrum eta\" \"metal-Au-eta\"\n\
           \"spectrum k\" \"metal-Au-k\" \"float roughness\" 0.01\n\
         MakeNamedMaterial \"brushed\" \"string type\" \"conductor\" \"rgb eta\" [0.2 0.9 1.1] \"rgb k\" [3.9 2.4 2.1]\n\
           \"float uroughness\" 0.04 \"float vroughness\" 0.16\n\
         MakeNamedMaterial \"raw\" \"string type\" \"dielectric\" \"float roughness\" 0.2 \"bool remaproughness\" false\n\
         NamedMaterial \"later\"\nShape \"sphere\"\nMakeNamedMaterial \"later\" \"string type\" \"diffuse\"\n",
    );
    let m = |name: &str| s.materials[s.material_names.iter().position(|n| n == name).unwrap()].clone();
    assert_eq!((m("glass").model, m("glass").ior), (MaterialModel::Dielectric { alpha: 0.0 }, 1.33));
    // pbrt-v4 maps roughness to alpha = sqrt(roughness) unless told not to.
    assert_eq!((m("frosted").model, m("frosted").ior), (MaterialModel::Dielectric { alpha: 0.3f32.sqrt() }, 1.5));
    assert_eq!(m("raw").model, MaterialModel::Dielectric { alpha: 0.2 });
    // A conductor given its reflectance r: eta = 1, k = 2 sqrt(r / (1 - r)) = 6 for r = 0.9, whose
    // normal-incidence reflectance k^2 / (4 + k^2) is r again.
    let MaterialModel::Conductor { eta, k, alpha } = m("chrome").model else { panic!("{:?}", m("chrome").model) };
    assert!(eta == Vec3::ONE && close(k, Vec3::splat(6.0), 1e-5) && alpha == 0.0, "{eta} {k}");
    // Named spectra: gold's reflectance (red above green above blue), roughness 0.01 as alpha 0.1.
    let MaterialModel::Conductor { k, alpha, .. } = m("gold").model else { panic!("{:?}", m("gold").model) };
    assert!(k.x > k.y && k.y > k.z && (alpha - 0.1).abs() < 1e-6, "{k} {alpha}");
    // Explicit indices are kept; two roughness axes become their mean alpha, (0.2 + 0.4) / 2.
    let MaterialModel::Conductor { eta, k, alpha } = m("brushed").model else { panic!() };
    assert!(eta == Vec3::new(0.2, 0.9, 1.1) && k == Vec3::new(3.9, 2.4, 2.1) && (alpha - 0.3).abs() < 1e-6);
    assert_eq!((m("coat").model, m("coat").ior), (MaterialModel::CoatedDiffuse { alpha: 0.0 }, 1.5));
    assert_eq!(m("coat").diffuse, Vec3::new(0.5, 0.2, 0.1));
    // The classic fields keep a stand-in for the Whitted integrator.
    assert!((m("coat").reflectivity - 0.04).abs() < 1e-6, "the coat's Fresnel reflectance at normal incidence");
    assert_eq!((m("glass").transparency, m("glass").diffuse), (1.0, Vec3::ZERO));
    // NamedMaterial may come before its definition, as in pbrt-v4.
    let later = &s.materials[s.objects[0].material as usize];
    assert_eq!((later.model, later.diffuse), (MaterialModel::Classic, Vec3::splat(0.5)));
    let said = |name: &str, what: &str| {
        s.warnings
            .iter()
            .any(|w| w.contains(&format!("material \"{name}\"")) && w.contains(what) && w.contains("test.pbrt:"))
    };
    assert!(said("coat", "approximated: ") && said("coat", "coateddiffuse"), "{:?}", s.warnings);
    assert!(said("brushed", "anisotropic roughness"), "{:?}", s.warnings);
    assert!(said("gold", "metal-Au-eta") && said("gold", "approximated: "), "{:?}", s.warnings);
    for exact in ["glass", "frosted", "chrome", "raw"] {
        assert!(!said(exact, ""), "{exact} is rendered as pbrt defines it: {:?}", s.warnings);
    }
}

#[test]
fn samplers_follow_the_sampler_directive() {
    let with = |sampler: &str| scene(&format!("{sampler}\nWorldBegin\nShape \"sphere\"\n"));
    // pbrt-v4's default is zsobol: a low-discrepancy sampler, as englobe's Sobol one.
    assert_eq!(with("").image.sampler, SamplerKind::Sobol);
    assert_eq!(with("Sampler \"zsobol\"").image.sampler, SamplerKind::Sobol);
    let independent = with("Sampler \"independent\" \"integer pixelsamples\" 4 \"integer seed\" 7");
    assert_eq!(
        (independent.image.sampler, independent.image.samples, independent.image.seed),
        (SamplerKind::Independent, 4, 7)
    );
    let halton = with("Sampler \"halton\"");
    assert_eq!(halton.image.sampler, SamplerKind::Sobol);
    assert!(
        halton.warnings.iter().any(|w| w.contains("test.pbrt:1:1: approximated: ") && w.contains("halton")),
        "{:?}",
        halton.warnings
    );
}

#[test]
fn includes_and_imports_read_files_beside_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("geometry")).unwrap();
    let quad = "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 1 0] \"integer indices\" [0 1 2]\n";
    std::fs::write(dir.path().join("geometry/a.pbrt"), format!("{quad}Include \"geometry/b.pbrt\"\n")).unwrap();
    std::fs::write(dir.path().join("geometry/b.pbrt"), format!("Translate 0 0 1\n{quad}")).unwrap();
    std::fs::write(dir.path().join("geometry/imp.pbrt"), format!("Translate 0 0 5\nMaterial \"diffuse\"\n{quad}"))
        .unwrap();
    let main = dir.path().join("main.pbrt");
    std::fs::write(&main, "WorldBegin\nInclude \"geometry/a.pbrt\"\nImport \"geometry/imp.pbrt\"\nShape \"sphere\"\n")
        .unwrap();
    let s = load(&main, false).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.objects.len(), 4);
    // The Include's Translate carries over to the sphere; the Import's does not add to it.
    let Object::Shape(englobe::Shape::Sphere(sp)) = &s.objects[3].object else { panic!() };
    assert_eq!(sp.center, Vec3::new(0.0, 0.0, 1.0));
    assert_eq!(s.objects[3].material, 0);
}

#[test]
fn meshes_of_every_kind_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
               element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
    std::fs::create_dir(dir.path().join("geometry")).unwrap();
    std::fs::write(dir.path().join("geometry/quad.ply"), ply).unwrap();
    let main = dir.path().join("main.pbrt");
    let text = "WorldBegin\nTranslate 0 0 2\nShape \"plymesh\" \"string filename\" \"geometry/quad.ply\"\n\
                Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"point2 uv\" [0 0 1 0 0 1]\n\
                Shape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0]\n\
                Shape \"disk\" \"float radius\" 2\n\
                Shape \"plymesh\" \"string filename\" \"geometry/quad.ply\"\n";
    std::fs::write(&main, text).unwrap();
    let s = load(&main, false).unwrap_or_else(|e| panic!("{e}"));
    let meshes: Vec<_> = s
        .objects
        .iter()
        .map(|o| match &o.object {
            Object::Mesh(m) => m.clone(),
            _ => panic!("a mesh"),
        })
        .collect();
    assert_eq!(meshes.iter().map(|m| m.len()).collect::<Vec<_>>(), vec![2, 1, 2, 128, 2]);
    // The PLY file is read once and placed by the transform; the inline mesh keeps its uvs.
    assert!(meshes[0].positions().iter().all(|p| p.z == 2.0) && meshes[0].positions()[2] == Vec3::new(1.0, 1.0, 2.0));
    assert_eq!(meshes[1].uvs().map(<[Vec2]>::len), Some(3));
    // A flat bilinear patch is exact; the disk's tessellation is reported; its area is pi r^2 to 0.1 %.
    assert!(!s.warnings.iter().any(|w| w.contains("bilinear")), "{:?}", s.warnings);
    assert!(s.warnings.iter().any(|w| w.contains("approximated: Shape \"disk\"")), "{:?}", s.warnings);
    let area: f32 = (0..128).map(|t| meshes[3].triangle(t).double_area() / 2.0).sum();
    assert!((area / (4.0 * std::f32::consts::PI) - 1.0).abs() < 1e-3, "{area}");
    // A missing PLY file is an error at its name, saying where it was looked for.
    let text = "WorldBegin\nShape \"plymesh\" \"string filename\" \"gone.ply\"\n";
    std::fs::write(&main, text).unwrap();
    let e = load(&main, false).unwrap_err();
    assert!(matches!(e, SceneError::Mesh { .. }));
    let e = e.to_string();
    assert!(
        e.starts_with(&format!(
            "{}: cannot load the mesh \"gone.ply\"",
            place(&main.display().to_string(), text, "\"string filename\"")
        )),
        "{e}"
    );
}

#[test]
fn include_errors_name_the_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let main = dir.path().join("main.pbrt");
    let text = "WorldBegin\nInclude \"missing.pbrt\"\n";
    std::fs::write(&main, text).unwrap();
    let name = main.display().to_string();
    let e = load(&main, false).unwrap_err().to_string();
    assert!(e.starts_with(&format!("{name}:2:9: Include \"missing.pbrt\": cannot read it")), "{e}");
    // A cycle: a includes b includes a.
    std::fs::write(dir.path().join("a.pbrt"), "Include \"b.pbrt\"\n").unwrap();
    std::fs::write(dir.path().join("b.pbrt"), "\n  Include \"a.pbrt\"\n").unwrap();
    std::fs::write(&main, "WorldBegin\nInclude \"a.pbrt\"\n").unwrap();
    let e = load(&main, false).unwrap_err().to_string();
    let b = dir.path().join("b.pbrt").display().to_string();
    assert!(e.starts_with(&format!("{b}:2:11: Include \"a.pbrt\": an include cycle")), "{e}");
    assert!(e.contains(&format!("included from {}:1:9", dir.path().join("a.pbrt").display())), "{e}");
    assert!(e.contains(&format!("included from {name}:2:9")), "{e}");
    // An error inside an included file is at its own line, with the chain that led there.
    let a_text = "Shape \"sphere\" \"float radius\" [ \"big\" ]\n";
    std::fs::write(dir.path().join("a.pbrt"), a_text).unwrap();
    let e = load(&main, false).unwrap_err().to_string();
    let a = dir.path().join("a.pbrt").display().to_string();
    assert!(e.starts_with(&format!("{}: ", place(&a, a_text, "\"big\""))), "{e}");
    assert!(e.contains("expected a number") && e.contains(&format!("included from {name}:2:9")), "{e}");
}

#[test]
fn malformed_files_are_refused_at_their_place() {
    let cases: &[(&str, &str, &str)] = &[
        ("WorldBegin\nShape \"sphere\n", "\"sphere", "unterminated string"),
        ("Camera \"perspective\" \"integer fov\" [ 45 ]\n", "\"integer fov\"", "wrong type"),
        ("WorldBegin\nShape \"sphere\" \"float radius\" [ 1 2 ]\n", "\"float radius\"", "takes one value"),
        ("WorldBegin\nNamedMaterial \"nowhere\"\nShape \"sphere\"\n", "NamedMaterial", "never defined"),
        ("WorldBegin\nAttributeEnd\n", "AttributeEnd", "without a matching AttributeBegin"),
        ("WorldBegin\nAttributeBegin\nTransformEnd\n", "TransformEnd", "does not match"),
        ("Shape \"sphere\"\n", "Shape", "only after WorldBegin"),
        ("WorldBegin\nCamera \"perspective\"\n", "Camera", "only before WorldBegin"),
        ("WorldBegin\nTranslate 1 2\n", "", "the file ends"),
        ("WorldBegin\nRotate 10 0 0 0\n", "Rotate", "axis is zero"),
        ("LookAt 0 0 0 0 0 0 0 1 0\n", "LookAt", "same point"),
        ("WorldBegin\n[ 1 2 ]\n", "[", "expected a directive"),
        (
            "WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 3]\n",
            "\"integer indices\"",
            "out of range",
        ),
        (
            "WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 0 0 1]\n",
            "Shape",
            "needs \"integer indices\"",
        ),
        (
            "WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"normal N\" [0 0 1]\n",
            "\"normal N\"",
            "1 normals for 3 vertices",
        ),
        ("Film \"rgb\" \"integer xresolution\" [ 0 ]\nWorldBegin\n", "\"integer xresolution\"", "at least 1"),
        (
            "Film \"rgb\" \"integer xresolution\" [ 100000 ] \"integer yresolution\" [ 100000 ]\nWorldBegin\n",
            "Film",
            "pixels",
        ),
        ("WorldBegin\nShape \"sphere\" \"float radius\" [ 1e999 ]\n", "1e999", "finite"),
        ("WorldBegin\nObjectBegin \"a\"\nShape \"sphere\"\n", "ObjectBegin", "never closed"),
        ("WorldBegin\nObjectInstance \"b\"\n", "ObjectInstance", "no object of that name"),
        ("WorldBegin\nMakeNamedMaterial \"m\" \"float x\" 1\n", "MakeNamedMaterial", "needs its type"),
        (
            "WorldBegin\nMaterial \"diffuse\" \"texture reflectance\" \"none\"\n",
            "\"texture reflectance\"",
            "names no spectrum texture",
        ),
    ];
    for &(text, at, expected) in cases {
        let e = error(text, false);
        let at = if at.is_empty() {
            format!("test.pbrt:{}:1", text.lines().count() + 1)
        } else {
            place("test.pbrt", text, at)
        };
        assert!(e.starts_with(&format!("{at}: ")), "{text:?}: expected at {at}, got {e}");
        assert!(e.contains(expected), "{text:?}: expected {expected:?}, got {e}");
    }
}

#[test]
fn unknown_directives_are_warnings_or_errors_as_asked() {
    let text = "WorldBegin\n  Frobnicate \"x\" [ 1 2 ] \"float y\" 3\nShape \"sphere\"\nFrobnicate\n";
    let s = scene(text);
    assert_eq!(s.objects.len(), 1, "the arguments are skipped up to the next directive");
    let w: Vec<_> = s.warnings.iter().filter(|w| w.contains("Frobnicate")).collect();
    assert_eq!(w.len(), 1, "once: {:?}", s.warnings);
    assert!(
        w[0].starts_with("test.pbrt:2:3: skipped: unknown directive `Frobnicate`") && w[0].contains("2 times"),
        "{}",
        w[0]
    );
    let e = error(text, true);
    assert!(e.starts_with("test.pbrt:2:3: unknown directive `Frobnicate`") && e.contains("--strict"), "{e}");
    // Unsupported parameters and shapes are reported the same way.
    let s = scene(
        "WorldBegin\nShape \"curve\" \"point3 P\" [0 0 0 1 1 1 2 2 2 3 3 3]\nShape \"sphere\" \"float nonsense\" 1\n",
    );
    assert!(s.warnings.iter().any(|w| w.starts_with("test.pbrt:2:1: skipped: Shape \"curve\"")), "{:?}", s.warnings);
    assert!(
        s.warnings
            .iter()
            .any(|w| w.starts_with("test.pbrt:3:16: skipped: Shape \"sphere\": parameter \"float nonsense\"")),
        "{:?}",
        s.warnings
    );
    assert!(error("WorldBegin\nShape \"curve\"\n", true).starts_with("test.pbrt:2:1: "));
}

#[test]
fn object_instances_share_their_meshes() {
    let s = scene(
        "WorldBegin\nObjectBegin \"tri\"\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\nObjectEnd\n\
         Translate 5 0 0\nObjectInstance \"tri\"\nTranslate 5 0 0\nObjectInstance \"tri\"\n",
    );
    assert_eq!(s.objects.len(), 2);
    let (Object::Instance(a), Object::Instance(b)) = (&s.objects[0].object, &s.objects[1].object) else { panic!() };
    assert!(std::sync::Arc::ptr_eq(a.mesh(), b.mesh()));
    assert_eq!(b.to_world().transform_point3(Vec3::ZERO), Vec3::new(10.0, 0.0, 0.0));
}

#[test]
fn overrides_are_refused_for_pbrt_scenes() {
    let e = englobe_scene::pbrt::refuse_overrides(&["camera.fov=30".parse().unwrap()]).unwrap_err();
    let SceneError::Invalid(l) = e else { panic!() };
    assert!(l.file == "-D camera.fov=30" && l.message.contains("not to pbrt scenes"), "{l}");
    assert!(englobe_scene::pbrt::refuse_overrides(&[]).is_ok());
}

/// The body of the `pbrt_scene` fuzz target.
fn fuzz_one(data: &[u8]) {
    const PATH: &str = "no-such-folder/fuzz.pbrt";
    if let Ok(text) = std::str::from_utf8(data) {
        for strict in [false, true] {
            if let Err(e) = parse(text, PATH.as_ref(), strict) {
                // Located in the scene (or, for an absolute Include, in the file it names).
                let shown = e.to_string();
                let first = shown.lines().next().unwrap_or("");
                let mut parts = first.splitn(4, ':');
                let (file, line, column) = (parts.next(), parts.next(), parts.next());
                assert!(
                    file.is_some_and(|f| !f.is_empty())
                        && line.is_some_and(|l| l.parse::<u32>().is_ok())
                        && column.is_some_and(|c| c.parse::<u32>().is_ok()),
                    "an error without a place: {shown}"
                );
            }
        }
    }
}

#[test]
fn cut_and_scrambled_scenes_never_panic() {
    let cornell = std::fs::read(shared_scenes().join("cornell-bitterli/scene-v4.pbrt")).unwrap();
    for end in (0..cornell.len()).step_by(37) {
        fuzz_one(&cornell[..end]);
    }
    let mut x = 0x2545_f491_4f6c_dd1du64;
    for _ in 0..300 {
        let mut data = cornell[..2000].to_vec();
        for _ in 0..8 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let i = (x % data.len() as u64) as usize;
            data[i] = b"\"[]#0.-e \nShape\x00"[(x >> 40) as usize % 16];
        }
        fuzz_one(&data);
    }
}
