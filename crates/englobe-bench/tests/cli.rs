//! The `englobe-bench` command end to end on a small mesh: the table, the CSV (columns, one row
//! per measurement, written atomically) and its path as the last line; bad input refused.

use std::path::Path;
use std::process::{Command, Output};

use englobe_bench::LibraryKind;
use englobe_bench::results::CSV_COLUMNS;
use englobe_scene::shared_data::shared_meshes_or_panic;

fn bench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_englobe-bench")).args(args).output().expect("the englobe-bench binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn cornell_box() -> String {
    let meshes = shared_meshes_or_panic(Path::new(env!("CARGO_MANIFEST_DIR")));
    meshes.join("cornell-box/CornellBox-Original.obj").to_string_lossy().into_owned()
}

#[test]
fn a_small_run_writes_the_csv_and_names_it_last() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("out/bench.csv");
    let scene = format!("box={}", cornell_box());
    let tiled = format!("{}@2x1x2", cornell_box());
    let args = [
        scene.as_str(),
        tiled.as_str(),
        "--resolution",
        "32",
        "--rays",
        "1000",
        "--reps",
        "2",
        "--threads",
        "1,2",
        "-q",
        "-o",
        csv.to_str().unwrap(),
    ];
    let out = bench(&args);
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", text(&out.stderr));
    assert_eq!(stdout.lines().last().unwrap(), csv.to_str().unwrap());
    assert!(stdout.contains("box: 36 triangles, 2 threads; Mrays/s"), "{stdout}");
    assert!(stdout.contains("CornellBox-Original-2x1x2: 144 triangles, 1 thread"), "{stdout}");
    assert!(stdout.contains("every library within tolerance"), "{stdout}");

    let written = std::fs::read_to_string(&csv).unwrap();
    let mut lines = written.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header, CSV_COLUMNS);
    for required in ["scene", "library", "rays", "query", "threads", "mrays_per_s", "build_ms"] {
        assert!(header.contains(&required), "{required}");
    }
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let libraries = LibraryKind::available_kinds();
    // Two scenes, two thread counts, four cells per library.
    assert_eq!(rows.len(), 2 * 2 * 4 * libraries.len());
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    for row in &rows {
        assert!(libraries.iter().any(|l| l.name() == row[column("library")]), "{row:?}");
        assert!(["primary", "random", "bounce"].contains(&row[column("rays")]));
        assert!(["closest", "any"].contains(&row[column("query")]));
        assert!(["1", "2"].contains(&row[column("threads")]));
        let speed: f64 = row[column("mrays_per_s")].parse().unwrap();
        let build: f64 = row[column("build_ms")].parse().unwrap();
        assert!(speed > 0.0 && build > 0.0, "{row:?}");
        // The build's memory is measured where the system reports it (Linux); a scene this small
        // may add no page at all.
        let bytes = row[column("build_bytes_per_triangle")];
        if cfg!(target_os = "linux") {
            assert!(bytes.parse::<f64>().is_ok_and(|b| b >= 0.0), "{row:?}");
        }
        assert_eq!(row[column("mismatches")], "0", "{row:?}");
        let ratio = row[column("ratio_to_obvhs")];
        if row[column("library")] == "obvhs" {
            assert_eq!(ratio, "1.0000");
        }
    }
    // Nothing but the CSV is left in its folder.
    let names: Vec<_> = std::fs::read_dir(csv.parent().unwrap()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, vec![std::ffi::OsString::from("bench.csv")]);
}

#[test]
fn two_libraries_on_one_thread_write_four_rows_each() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("bench.csv");
    let box_ = cornell_box();
    let args = [box_.as_str(), "--resolution", "16", "--rays", "256", "--reps", "1", "--threads", "1"];
    let out = bench(&[&args[..], &["--libraries", "englobe,obvhs", "-q", "-o", csv.to_str().unwrap()]].concat());
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", text(&out.stderr));
    assert_eq!(stdout.lines().last().unwrap(), csv.to_str().unwrap());
    let written = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(written.lines().count(), 1 + 2 * 4, "{written}");
}

#[test]
fn bad_input_is_refused_with_a_clear_error() {
    let missing = bench(&["no/such/mesh.obj", "-q"]);
    assert_eq!(missing.status.code(), Some(2));
    assert!(text(&missing.stderr).contains("no/such/mesh.obj"), "{}", text(&missing.stderr));
    let box_ = cornell_box();
    for (args, expected) in [
        (vec![box_.as_str(), "--threads", "0"], "--threads"),
        (vec![box_.as_str(), "--resolution", "30"], "--resolution"),
        (vec![box_.as_str(), "--libraries", "optix"], "unknown library"),
        (vec![box_.as_str(), "--cells", "shadow-any"], "unknown cell"),
        (vec![box_.as_str(), "--englobe-accel", "octree"], "unknown accelerator"),
        (vec![box_.as_str(), "--englobe-presplit", "5000"], "--englobe-presplit must be at most"),
        (vec![box_.as_str(), "--englobe-accel", "bvh-sah", "--englobe-presplit", "0"], "only triangle-bvh"),
    ] {
        let out = bench(&args);
        assert!(!out.status.success());
        let err = text(&out.stderr);
        assert!(err.contains(expected), "{args:?}: {err}");
    }
}

#[test]
fn a_bad_file_anywhere_in_the_list_stops_the_run_before_anything_is_measured() {
    let dir = tempfile::tempdir().unwrap();
    let broken = dir.path().join("broken.obj");
    std::fs::write(&broken, "v 0 0 0\nv 1 0 0\nf 1 2 7\n").unwrap();
    let csv = dir.path().join("bench.csv");
    let good = format!("box={}", cornell_box());
    let bad = format!("bad={}", broken.display());
    let out = bench(&[
        &good,
        &bad,
        "--resolution",
        "32",
        "--rays",
        "500",
        "--reps",
        "1",
        "--threads",
        "1",
        "-o",
        csv.to_str().unwrap(),
        "-q",
    ]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(err.contains("scene `bad` refused before measuring anything") && err.contains("broken.obj"), "{err}");
    assert!(!text(&out.stdout).contains("rays hitting"), "nothing was measured: {}", text(&out.stdout));
    assert!(!csv.exists());
}

#[test]
fn a_camera_inside_the_sponza_sees_walls_in_almost_every_pixel() {
    let meshes = shared_meshes_or_panic(Path::new(env!("CARGO_MANIFEST_DIR")));
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("bench.csv");
    let sponza = meshes.join("sponza-dabrovic/sponza.obj").to_string_lossy().into_owned();
    let scenes = [format!("outside={sponza}"), format!("inside={sponza}")];
    let common = ["--resolution", "64", "--rays", "500", "--reps", "1", "--threads", "1", "--libraries", "englobe"];
    let mut args: Vec<&str> = scenes.iter().map(String::as_str).collect();
    args.extend(common);
    args.extend(["--view", "inside=-10.43876,7.37331,0.00149,1,0,0,60", "-o", csv.to_str().unwrap(), "-q"]);
    let out = bench(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let primary = |scene: &str| -> f64 {
        let line = stdout.lines().find(|l| l.starts_with(&format!("{scene}:")) && l.contains("rays hitting")).unwrap();
        line.split("primary ").nth(1).unwrap().split(" %").next().unwrap().parse().unwrap()
    };
    assert!(primary("inside") > 90.0, "{stdout}");
    assert!(primary("outside") < 50.0, "the framing camera sees the building from outside: {stdout}");
    let err = text(&bench(&[&scenes[0], "--view", "nowhere=0,0,0,1,0,0,60", "-q"]).stderr);
    assert!(err.contains("--view nowhere=...: no scene of that name"), "{err}");
    let err = text(&bench(&[&scenes[0], "--view", "outside=0,0,0,0,1,0,60", "-q"]).stderr);
    assert!(err.contains("must not be vertical"), "{err}");
}
