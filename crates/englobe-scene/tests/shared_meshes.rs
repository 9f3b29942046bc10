//! Every file of the shared mesh folder either loads or is refused with an error that names it;
//! none panics. Known meshes load to their known sizes.

use std::path::{Path, PathBuf};

use englobe_scene::mesh::{MeshErrorKind, load_mesh_file};
use englobe_scene::shared_data::shared_meshes_or_panic;

fn meshes() -> PathBuf {
    shared_meshes_or_panic(Path::new(env!("CARGO_MANIFEST_DIR")))
}

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() { files(&p, out) } else { out.push(p) }
    }
}

#[test]
fn every_shared_file_loads_or_is_refused_without_panic() {
    let root = meshes();
    let mut all = Vec::new();
    files(&root, &mut all);
    assert!(all.len() > 80, "only {} files under {}", all.len(), root.display());
    let mut panicked = Vec::new();
    let mut report = String::new();
    let (mut loaded, mut refused) = (0, 0);
    for file in &all {
        let rel = file.strip_prefix(&root).unwrap().display().to_string();
        match std::panic::catch_unwind(|| load_mesh_file(file)) {
            Err(_) => panicked.push(rel),
            Ok(Ok(m)) => {
                loaded += 1;
                report += &format!("ok      {rel}: {} triangles, {} warnings\n", m.mesh.len(), m.warnings.len());
            }
            Ok(Err(e)) => {
                refused += 1;
                let shown = e.to_string();
                assert!(shown.starts_with(&file.display().to_string()), "the error does not name the file: {shown}");
                report += &format!("refused {rel}: {shown}\n");
            }
        }
    }
    println!("{report}{loaded} loaded, {refused} refused");
    assert!(panicked.is_empty(), "panicked on: {panicked:?}");
}

#[test]
fn known_meshes_load_to_their_sizes() {
    let root = meshes();
    for (file, triangles) in [
        ("bunny/stanford-bunny.obj", 69_451),
        ("bunny/bun_zipper.ply", 69_451),
        ("bunny/bun_zipper_binary.ply", 69_451),
        ("dragon-lowres/dragon_lowres_22k.ply", 22_866),
        ("teapot/teapot.obj", 6_320),
        ("suzanne/suzanne.obj", 968),
        ("cornell-box/CornellBox-Original.obj", 36),
        ("gltf/Box/Box.gltf", 12),
        ("gltf/Box/Box.glb", 12),
        ("gltf/DamagedHelmet/DamagedHelmet.gltf", 15_452),
        ("gltf/DamagedHelmet/GLBDamagedHelmet.glb", 15_452),
    ] {
        let m = load_mesh_file(&root.join(file)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.mesh.len(), triangles, "{file}: {:?}", m.warnings);
    }
    // Sponza holds one degenerate triangle, dropped with a warning.
    let sponza = load_mesh_file(&root.join("sponza-dabrovic/sponza.obj")).unwrap();
    assert_eq!(sponza.mesh.len(), 66_453);
    assert!(sponza.warnings.iter().any(|w| w.contains("dropped 1 degenerate triangle")), "{:?}", sponza.warnings);
    assert!(sponza.mesh.normals().is_some());
}

#[test]
fn files_that_need_draco_are_refused_naming_the_extension() {
    for file in ["gltf/draco-required/Box_draco.glb", "gltf/draco-required/BoxTextured_draco.glb"] {
        let e = load_mesh_file(&meshes().join(file)).unwrap_err();
        assert!(matches!(&e.kind, MeshErrorKind::UnsupportedExtension(x) if x == "KHR_draco_mesh_compression"), "{e}");
        assert!(e.to_string().contains("KHR_draco_mesh_compression"));
    }
}
