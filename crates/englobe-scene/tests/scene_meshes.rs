//! `[[mesh]]` entries of scene files: placement, instances, materials, errors that name both
//! the scene line and the mesh file, and the loading of each file told to an observer.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use englobe::{Object, Vec3};
use englobe_scene::{LoadObserver, Scene, SceneError, load_scene, load_scene_observed};

const HEAD: &str = "[image]\nwidth = 8\nheight = 8\n[camera]\nposition = [0, 0, -5]\nlook_at = [0, 0, 0]\n";

/// A folder with a unit-triangle OBJ (`tri.obj`) and a two-material quad with its MTL.
fn folder() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    std::fs::write(dir.path().join("quad.mtl"), "newmtl red\nKd 1 0 0\nnewmtl glow\nKd 0 0 0\nKe 2 2 2\n").unwrap();
    std::fs::write(
        dir.path().join("quad.obj"),
        "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl red\nf 1 2 3\nusemtl glow\nf 1 3 4\n",
    )
    .unwrap();
    dir
}

fn scene(dir: &Path, body: &str) -> Result<Scene, SceneError> {
    let file: PathBuf = dir.join("scene.toml");
    std::fs::write(&file, format!("{HEAD}{body}")).unwrap();
    load_scene(&file)
}

fn error(dir: &Path, body: &str) -> (usize, String) {
    let e = scene(dir, body).unwrap_err();
    let line = e.location().unwrap_or_else(|| panic!("no location in {e}")).line;
    (line, e.to_string())
}

fn mesh_positions(o: &Object) -> Vec<Vec3> {
    match o {
        Object::Mesh(m) => m.positions().to_vec(),
        other => panic!("not a mesh: {other:?}"),
    }
}

#[test]
fn a_placed_mesh_has_its_transform_baked_in() {
    let dir = folder();
    let s = scene(dir.path(), "[[mesh]]\npath = \"tri.obj\"\nscale = 2\nrotate = [0, 0, 90]\ntranslate = [1, 2, 3]\n")
        .unwrap();
    let p = mesh_positions(&s.objects[0].object);
    // x scaled to 2 then turned onto +y, then moved.
    assert!((p[1] - Vec3::new(1.0, 4.0, 3.0)).length() < 1e-5, "{p:?}");
    let s = scene(
        dir.path(),
        "[[mesh]]\npath = \"tri.obj\"\nmatrix = [[1, 0, 0, 5], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n",
    )
    .unwrap();
    assert_eq!(mesh_positions(&s.objects[0].object)[1], Vec3::new(6.0, 0.0, 0.0));
}

#[test]
fn instances_share_one_mesh() {
    let dir = folder();
    let body = "[[mesh]]\npath = \"tri.obj\"\ninstances = [{ translate = [1, 0, 0] }, { scale = [1, 2, 1] }, {}]\n\
                [[mesh]]\npath = \"tri.obj\"\ngrid = { counts = [2, 1, 3], spacing = [4, 0, 4], rotate_step = [0, 90, 0] }\n";
    let s = scene(dir.path(), body).unwrap();
    assert_eq!(s.objects.len(), 9);
    let meshes: Vec<_> = s
        .objects
        .iter()
        .map(|o| match &o.object {
            Object::Instance(i) => i.mesh().clone(),
            other => panic!("not an instance: {other:?}"),
        })
        .collect();
    assert!(meshes.iter().all(|m| Arc::ptr_eq(m, &meshes[0])), "one file, one mesh");
    let Object::Instance(fifth) = &s.objects[4].object else { unreachable!() };
    // Grid cell (1, 0, 0), turned 90 degrees once: the triangle's +x corner goes to -z.
    let corner = fifth.to_world().transform_point3(Vec3::X);
    assert!((corner - Vec3::new(4.0, 0.0, -1.0)).length() < 1e-5, "{corner}");
}

#[test]
fn file_materials_apply_per_triangle_unless_overridden() {
    let dir = folder();
    let s = scene(dir.path(), "[materials.blue]\ndiffuse = [0, 0, 1]\n[[mesh]]\npath = \"quad.obj\"\n").unwrap();
    assert_eq!(s.material_names, ["default", "blue", "quad.obj:red", "quad.obj:glow"]);
    let o = &s.objects[0];
    assert_eq!((o.material_of(0), o.material_of(1)), (2, 3));
    assert_eq!(s.materials[3].emission, Vec3::splat(2.0));
    let s = scene(
        dir.path(),
        "[materials.blue]\ndiffuse = [0, 0, 1]\n[[mesh]]\npath = \"quad.obj\"\nmaterial = \"blue\"\n",
    )
    .unwrap();
    assert_eq!((s.objects[0].material_of(0), s.objects[0].material_of(1)), (1, 1));
    let (line, shown) = error(dir.path(), "[[mesh]]\npath = \"quad.obj\"\nmaterial = \"quad.obj:red\"\n");
    assert_eq!(line, 9, "{shown}");
    assert!(shown.contains("unknown material"), "{shown}");
}

#[test]
fn missing_unreadable_and_broken_meshes_name_the_scene_line_and_the_file() {
    let dir = folder();
    std::fs::create_dir(dir.path().join("folder.obj")).unwrap();
    std::fs::write(dir.path().join("broken.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n").unwrap();
    std::fs::write(dir.path().join("notes.txt"), "not a mesh\n").unwrap();
    // Unreadable whoever runs the test (permissions do not stop root): a link to itself.
    #[cfg(unix)]
    std::os::unix::fs::symlink("loop.obj", dir.path().join("loop.obj")).unwrap();
    for (path, says) in [
        #[cfg(unix)]
        ("loop.obj", "symbolic links"),
        ("missing.obj", "No such file"),
        ("folder.obj", "directory"),
        ("tri.obj/inside.obj", "tri.obj/inside.obj"),
        ("broken.obj", "line 4: vertex index 4 is out of range"),
        ("notes.txt", "unknown mesh format"),
    ] {
        let (line, shown) = error(
            dir.path(),
            &format!("[[plane]]\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\n\n[[mesh]]\npath = \"{path}\"\n"),
        );
        assert_eq!(line, 12, "{shown}");
        assert!(shown.contains("scene.toml:12:8: cannot load the mesh"), "{shown}");
        assert!(shown.contains(&dir.path().join(path).display().to_string()), "{shown}");
        assert!(shown.contains(says), "{shown}");
    }
}

#[test]
fn bad_placements_are_refused_at_their_line() {
    let dir = folder();
    for (body, line, says) in [
        ("[[mesh]]\npath = \"tri.obj\"\nscale = 0\n", 9, "not zero"),
        ("[[mesh]]\npath = \"tri.obj\"\nscale = [1, 1, 0]\n", 9, "not zero"),
        ("[[mesh]]\npath = \"tri.obj\"\nscale = \"big\"\n", 9, "a number or [x, y, z]"),
        (
            "[[mesh]]\npath = \"tri.obj\"\nmatrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]\n",
            9,
            "last row",
        ),
        (
            "[[mesh]]\npath = \"tri.obj\"\nmatrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1]]\n",
            7,
            "singular",
        ),
        (
            "[[mesh]]\npath = \"tri.obj\"\ntranslate = [1, 0, 0]\nmatrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n",
            7,
            "cannot be combined",
        ),
        (
            "[[mesh]]\npath = \"tri.obj\"\ninstances = [{}]\ngrid = { counts = [1, 1, 1], spacing = [1, 1, 1] }\n",
            10,
            "not both",
        ),
        (
            "[[mesh]]\npath = \"tri.obj\"\ngrid = { counts = [4096, 4096, 4096], spacing = [1, 1, 1] }\n",
            9,
            "over the limit",
        ),
        ("[[mesh]]\npath = \"tri.obj\"\ninstances = [{ scale = 1e-30 }]\n", 9, "cannot be placed"),
        ("[[mesh]]\npath = \"tri.obj\"\nrotation = [0, 1, 0]\n", 9, "unknown field"),
    ] {
        let (l, shown) = error(dir.path(), body);
        assert_eq!(l, line, "{body}: {shown}");
        assert!(shown.contains(says), "{body}: {shown}");
    }
}

/// Records what a [`LoadObserver`] is told.
#[derive(Default)]
struct Recorder(std::cell::RefCell<Vec<String>>);

impl LoadObserver for Recorder {
    fn mesh_started(&self, path: &Path) {
        self.0.borrow_mut().push(format!("start {}", path.file_name().unwrap().to_string_lossy()));
    }
    fn mesh_loaded(&self, path: &Path, triangles: usize, elapsed: std::time::Duration) {
        assert!(elapsed.as_secs() < 60);
        self.0.borrow_mut().push(format!("loaded {} {triangles}", path.file_name().unwrap().to_string_lossy()));
    }
}

#[test]
fn each_mesh_file_is_told_to_the_observer_once_in_order() {
    let dir = folder();
    let file = dir.path().join("scene.toml");
    let body = "[[mesh]]\npath = \"quad.obj\"\n[[mesh]]\npath = \"tri.obj\"\n[[mesh]]\npath = \"quad.obj\"\n\
                translate = [2, 0, 0]\n";
    std::fs::write(&file, format!("{HEAD}{body}")).unwrap();
    let seen = Recorder::default();
    let scene = load_scene_observed(&file, &[], &seen).unwrap();
    assert_eq!(scene.objects.len(), 3);
    assert_eq!(*seen.0.borrow(), ["start quad.obj", "loaded quad.obj 2", "start tri.obj", "loaded tri.obj 1"]);
    // A file that fails is started and not loaded.
    std::fs::write(dir.path().join("bad.obj"), "v 0 0 0\nf 1 2 3\n").unwrap();
    std::fs::write(&file, format!("{HEAD}[[mesh]]\npath = \"tri.obj\"\n[[mesh]]\npath = \"bad.obj\"\n")).unwrap();
    let seen = Recorder::default();
    assert!(load_scene_observed(&file, &[], &seen).is_err());
    assert_eq!(*seen.0.borrow(), ["start tri.obj", "loaded tri.obj 1", "start bad.obj"]);
}
