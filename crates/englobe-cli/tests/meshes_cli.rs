//! The `englobe` command on meshes: `info` on mesh and scene files, errors and exit codes, and
//! the memory cost of instancing measured on the example scenes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use englobe_scene::shared_data::shared_meshes_or_panic;

fn englobe(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_englobe")).args(args).output().expect("the englobe binary runs")
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn info_describes_mesh_files() {
    let bunny = shared_meshes_or_panic(&repo()).join("bunny/bun_zipper_binary.ply");
    let out = englobe(&["info", bunny.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let shown = text(&out.stdout);
    for line in ["format:     PLY", "triangles:  69451", "vertices:   34834", "warnings:   0"] {
        assert!(shown.contains(line), "{line:?} missing from:\n{shown}");
    }
    let cornell = shared_meshes_or_panic(&repo()).join("cornell-box/CornellBox-Original.obj");
    let shown = text(&englobe(&["info", cornell.to_str().unwrap()]).stdout);
    assert!(
        shown.contains("materials:  8")
            && shown.contains("light: metallic_roughness, base colour [0.78, 0.78, 0.78],")
            && shown.contains(
                "shortBox: metallic_roughness, base colour [0.725, 0.71, 0.68], metallic 0, roughness 0.3154421"
            )
            && shown.contains("emission [17, 12, 4], 2 triangles")
            && shown.contains("textures:   0 (0 unreadable)"),
        "{shown}"
    );
}

#[test]
fn info_lists_materials_and_textures_and_what_could_not_be_read() {
    let helmet = shared_meshes_or_panic(&repo()).join("gltf/DamagedHelmet/DamagedHelmet.gltf");
    let out = englobe(&["info", helmet.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let shown = text(&out.stdout);
    for line in [
        "Material_MR: metallic_roughness, base colour [1, 1, 1], metallic 1, roughness 1",
        "normal texture Default_normal.jpg",
        "textures:   5 (0 unreadable)",
        "Default_albedo.jpg): 2048x2048, 3 channels, 8 bits; used as Material_MR base_color",
        "uvs:        yes (set 0)",
        "tangents:   yes",
    ] {
        assert!(shown.contains(line), "{line:?} missing from:\n{shown}");
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.mtl"), "newmtl m\nmap_Kd lost.png\n").unwrap();
    let obj = dir.path().join("q.obj");
    std::fs::write(&obj, "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl m\nf 1/1 2/1 3/1\n").unwrap();
    let shown = text(&englobe(&["info", obj.to_str().unwrap()]).stdout);
    assert!(
        shown.contains("textures:   1 (1 unreadable)") && shown.contains("lost.png") && shown.contains("UNREADABLE"),
        "{shown}"
    );
    assert!(shown.contains("material `m`: the base colour texture"), "{shown}");
}

#[test]
fn info_refuses_broken_files_with_a_non_zero_exit() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("bad.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 999999\n").unwrap();
    let out = englobe(&["info", obj.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(err.contains(&format!("{}: line 4: vertex index 999999 is out of range", obj.display())), "{err}");
    let out = englobe(&["info", dir.path().join("absent.glb").to_str().unwrap()]);
    assert!(!out.status.success() && text(&out.stderr).contains("absent.glb"));
}

#[test]
fn info_and_render_name_the_scene_line_of_a_missing_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(
        &scene,
        "[image]\nwidth = 4\nheight = 4\n[camera]\nposition = [0, 0, -5]\nlook_at = [0, 0, 0]\n[[mesh]]\npath = \"gone.ply\"\n",
    )
    .unwrap();
    for args in [vec!["info"], vec!["render", "-q", "-o", dir.path().join("x.png").to_str().unwrap()]] {
        let mut args = args;
        args.push(scene.to_str().unwrap());
        let out = englobe(&args);
        assert!(!out.status.success(), "{args:?}");
        let err = text(&out.stderr);
        assert!(err.contains(&format!("{}:8:8: cannot load the mesh `gone.ply`", scene.display())), "{err}");
        assert!(err.contains(&dir.path().join("gone.ply").display().to_string()), "{err}");
    }
    assert!(!dir.path().join("x.png").exists());
}

/// A copy of the example scene `name` in `dir`, reading its meshes from wherever the shared data
/// was found (the example files name it relative to the repository, `../shared`).
fn example_scene(name: &str, dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(repo().join(format!("scenes/{name}.toml"))).unwrap();
    let meshes = shared_meshes_or_panic(&repo());
    assert!(text.contains("\"../../shared/scenes/meshes/"), "{name} does not read the shared meshes");
    let text = text.replace("\"../../shared/scenes/meshes/", &format!("\"{}/", meshes.display()));
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, text).unwrap();
    file
}

#[test]
fn info_describes_the_instanced_field() {
    let dir = tempfile::tempdir().unwrap();
    let out = englobe(&["info", example_scene("bunny-field", dir.path()).to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let shown = text(&out.stdout);
    assert!(shown.contains("meshes 0, instances 1000"), "{shown}");
    assert!(shown.contains("triangles:  69451000 in the picture, 69451 stored"), "{shown}");
    assert!(shown.contains("meshes:     1 distinct"), "{shown}");
}

/// Peak resident memory of `englobe render` on `scene` (a tiny image: the cost measured is the
/// scene's, not the film's), from its statistics.
fn peak_memory(scene: &str, dir: &Path) -> u64 {
    let json = dir.join(format!("{scene}.json"));
    let out = englobe(&[
        "render",
        "-q",
        "--width",
        "8",
        "--height",
        "8",
        "--threads",
        "1",
        "-o",
        dir.join(format!("{scene}.png")).to_str().unwrap(),
        "--stats-json",
        json.to_str().unwrap(),
        example_scene(scene, dir).to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    stats["peak_memory_bytes"].as_u64().expect("peak memory is reported on Linux")
}

#[cfg(target_os = "linux")]
#[test]
fn a_thousand_instanced_bunnies_cost_little_more_than_one() {
    let dir = tempfile::tempdir().unwrap();
    let one = peak_memory("bunny", dir.path());
    let thousand = peak_memory("bunny-field", dir.path());
    println!("peak memory: one bunny {one} bytes, 1000 instanced bunnies {thousand} bytes");
    assert!(thousand < 3 * one, "1000 bunnies take {thousand} bytes, one takes {one}");
    // A thousand copies of the bunny's triangles alone would take over a gigabyte.
    assert!(thousand < 200 << 20, "{thousand}");
}

#[test]
fn compare_reports_the_quality_of_every_bvh_on_the_dragon() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("compare.json");
    let scene = example_scene("dragon", dir.path());
    let out = englobe(&[
        "compare",
        scene.to_str().unwrap(),
        "--width",
        "24",
        "--height",
        "24",
        "--accel",
        "bvh-seed,bvh-sah,bvh-ploc,bvh-sweep",
        "-q",
        "--json",
        json.to_str().unwrap(),
    ]);
    let shown = text(&out.stdout);
    assert!(out.status.success(), "{shown}\n{}", text(&out.stderr));
    assert!(shown.contains("Quality: SAH cost") && shown.contains("0.5 per interior node"), "{shown}");
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    assert_eq!(report["sah_constants"]["traversal"].as_f64(), Some(0.5));
    assert_eq!(report["sah_constants"]["intersection"].as_f64(), Some(1.0));
    let rows = report["rows"].as_array().unwrap();
    let row = |name: &str| rows.iter().find(|r| r["accel"] == name).unwrap_or_else(|| panic!("no {name} row"));
    assert!(row("none")["sah_cost"].is_null());
    for (name, at_most) in [("bvh-sah", 1.05), ("bvh-ploc", 1.10), ("bvh-sweep", 1.0)] {
        let r = row(name);
        let ratio = r["sah_vs_sweep"].as_f64().unwrap();
        assert!(ratio <= at_most, "{name}: SAH cost {ratio} times the full sweep's");
        let sizes: Vec<u64> = r["leaf_sizes"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
        assert_eq!(sizes.len(), 9);
        assert_eq!(sizes.iter().sum::<u64>(), r["leaves"].as_u64().unwrap(), "{r}");
        assert_eq!(r["interior_nodes"].as_u64().unwrap() + 1, r["leaves"].as_u64().unwrap(), "a binary tree: {r}");
        assert!(r["speedup_vs_none"].as_f64().unwrap() > 0.0, "{r}");
        assert_eq!(r["image_equal"], serde_json::Value::Bool(true));
    }
    // The seed's tree: one primitive per leaf, and an SAH cost far above the others.
    let seed = row("bvh-seed");
    assert_eq!(seed["leaves"].as_u64(), Some(22_866));
    assert!(seed["sah_vs_sweep"].as_f64().unwrap() > 10.0, "{seed}");
}

/// With no `--accel`, a render goes through the fast path, on a mesh scene and on an instanced
/// one, and says so in its statistics; the same image as brute force's on the Sponza.
#[test]
fn renders_default_to_the_fast_path() {
    let dir = tempfile::tempdir().unwrap();
    for scene in ["sponza", "bunny-field"] {
        let file = example_scene(scene, dir.path());
        let json = dir.path().join(format!("{scene}.json"));
        let png = dir.path().join(format!("{scene}.png"));
        let out = englobe(&[
            "render",
            "-q",
            "--width",
            "32",
            "--height",
            "18",
            "--stats-json",
            json.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            file.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{scene}: {}", text(&out.stderr));
        let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        assert_eq!(stats["accel"], "bvh-wide", "{scene}");
    }
    let brute = dir.path().join("brute.png");
    let file = dir.path().join("sponza.toml");
    let args = ["render", "-q", "--width", "32", "--height", "18", "--accel", "none", "-o"];
    let out = englobe(&[&args[..], &[brute.to_str().unwrap(), file.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(std::fs::read(&brute).unwrap(), std::fs::read(dir.path().join("sponza.png")).unwrap());
}

#[test]
fn a_ply_of_triangle_strips_is_drawn_and_one_with_no_faces_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let header = "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n";
    let vertices: String = (0..4).map(|i| format!("{i} 0 0\n{i} 1 0\n")).collect();
    let strips = dir.path().join("strips.ply");
    std::fs::write(
        &strips,
        format!("{header}element tristrips 1\nproperty list int int vertex_indices\nend_header\n{vertices}9 0 1 2 3 -1 4 5 6 7\n"),
    )
    .unwrap();
    let out = englobe(&["info", strips.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("triangles:  4\n"), "two strips of four vertices: {}", text(&out.stdout));

    let points = dir.path().join("points.ply");
    std::fs::write(&points, format!("{header}end_header\n{vertices}")).unwrap();
    let out = englobe(&["info", points.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("no `face` or `tristrips` element, so no surface to draw; its elements: vertex (8)"),
        "{}",
        text(&out.stderr)
    );
    assert!(!text(&out.stderr).contains('?'), "no guess: {}", text(&out.stderr));
}
