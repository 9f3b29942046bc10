//! `englobe bench` forwards to the benchmark harness.

use std::path::Path;
use std::process::Command;

use englobe_scene::shared_data::shared_meshes_or_panic;

#[test]
fn bench_runs_the_harness() {
    let meshes = shared_meshes_or_panic(Path::new(env!("CARGO_MANIFEST_DIR")));
    let mesh = meshes.join("cornell-box/CornellBox-Original.obj");
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("bench.csv");
    let out = Command::new(env!("CARGO_BIN_EXE_englobe"))
        .args(["bench", mesh.to_str().unwrap(), "--resolution", "16", "--rays", "256", "--reps", "1", "--threads", "1"])
        .args(["--libraries", "englobe,obvhs", "-q", "-o", csv.to_str().unwrap()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(stdout.lines().last().unwrap(), csv.to_str().unwrap());
    let written = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(written.lines().count(), 1 + 2 * 4, "{written}");
}
