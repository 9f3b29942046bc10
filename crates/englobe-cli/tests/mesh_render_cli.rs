//! Any mesh in one command: `englobe render MESH` frames the mesh with no scene file, `englobe
//! scene MESH` prints that scene (which renders the same image), `--turntable N` turns around it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use englobe_scene::shared_data::shared_meshes_or_panic;

fn englobe(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_englobe")).args(args).current_dir(dir).output().expect("englobe runs")
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    o
}

fn meshes() -> PathBuf {
    shared_meshes_or_panic(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
}

/// A folder holding a copy of `mesh` (and, for a .gltf, the files beside it).
fn with_copy(mesh: &str) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    let from = meshes().join(mesh);
    for entry in std::fs::read_dir(from.parent().unwrap()).unwrap() {
        let path = entry.unwrap().path();
        if path.is_file() {
            std::fs::copy(&path, dir.path().join(path.file_name().unwrap())).unwrap();
        }
    }
    (dir, from.file_name().unwrap().to_string_lossy().into_owned())
}

#[test]
fn a_mesh_is_rendered_framed_with_no_scene() {
    let (dir, name) = with_copy("suzanne/suzanne.obj");
    let o = ok(englobe(dir.path(), &["render", &name, "--scale", "0.25"]));
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(said.starts_with("wrote suzanne.png (160x120, 4 spp"), "{said}");
    let img = image::open(dir.path().join("suzanne.png")).unwrap().to_rgb8();
    // The mesh fills the middle of the picture: its clay colour, neither sky nor ground.
    let centre = img.get_pixel(80, 60).0;
    assert!(centre[0] > centre[2] + 20, "the centre is the reddish clay, not the blue sky: {centre:?}");
    let top = img.get_pixel(80, 1).0;
    assert!(top[2] > top[0], "the sky is at the top: {top:?}");
    for mesh in ["gltf/Box/Box.glb", "gltf/Box/Box.gltf"] {
        let (dir, name) = with_copy(mesh);
        ok(englobe(dir.path(), &["render", &name, "--scale", "0.1", "-o", "box.png"]));
    }
}

#[test]
fn the_printed_scene_parses_and_renders_the_same_image() {
    let (dir, name) = with_copy("suzanne/suzanne.obj");
    let o = ok(englobe(dir.path(), &["scene", &name]));
    std::fs::write(dir.path().join("suzanne-scene.toml"), &o.stdout).unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("path = \"suzanne.obj\""), "{text}");
    ok(englobe(dir.path(), &["render", &name, "--scale", "0.25", "-o", "direct.png"]));
    ok(englobe(dir.path(), &["render", "suzanne-scene.toml", "--scale", "0.25", "-o", "printed.png"]));
    assert_eq!(
        std::fs::read(dir.path().join("direct.png")).unwrap(),
        std::fs::read(dir.path().join("printed.png")).unwrap()
    );
    // Overrides apply to a framed mesh as to any scene.
    ok(englobe(
        dir.path(),
        &["render", &name, "--scale", "0.25", "-D", "materials.clay.diffuse=[0, 0, 1]", "-o", "blue.png"],
    ));
    assert_ne!(
        std::fs::read(dir.path().join("blue.png")).unwrap(),
        std::fs::read(dir.path().join("direct.png")).unwrap()
    );
}

#[test]
fn a_turntable_writes_one_frame_per_step_around_the_mesh() {
    let (dir, name) = with_copy("suzanne/suzanne.obj");
    let o = ok(englobe(dir.path(), &["render", &name, "--scale", "0.1", "--turntable", "4", "-o", "spin.png"]));
    assert_eq!(String::from_utf8_lossy(&o.stdout).lines().count(), 4);
    let frames: Vec<Vec<u8>> =
        (0..4).map(|k| std::fs::read(dir.path().join(format!("spin-{k:03}.png"))).unwrap()).collect();
    for i in 0..4 {
        for j in i + 1..4 {
            assert_ne!(frames[i], frames[j], "frames {i} and {j} differ");
        }
    }
    // Frame 0 is the unturned view.
    ok(englobe(dir.path(), &["render", &name, "--scale", "0.1", "-o", "still.png"]));
    assert_eq!(frames[0], std::fs::read(dir.path().join("still.png")).unwrap());
}

#[test]
fn a_bad_mesh_is_named_and_scene_needs_a_mesh() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.obj"), "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n").unwrap();
    let o = englobe(dir.path(), &["render", "bad.obj"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("bad.obj: line 3"), "{}", String::from_utf8_lossy(&o.stderr));
    let o = englobe(dir.path(), &["scene", "missing.ply"]);
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("missing.ply: cannot read"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
