//! `englobe bench`: with the `bench` cargo feature it forwards to the benchmark harness (whose own
//! end-to-end tests, run by `cargo test --workspace`, are in `englobe-bench/tests/cli.rs`); without
//! it, the command is still listed and says how to run the benchmark. The first test runs with
//! `cargo test -p englobe-cli --features bench --test bench_cli`.

use std::process::Command;

fn englobe() -> Command {
    Command::new(env!("CARGO_BIN_EXE_englobe"))
}

#[cfg(feature = "bench")]
#[test]
fn bench_runs_the_harness() {
    use std::path::Path;

    use englobe_scene::shared_data::shared_meshes_or_panic;

    let meshes = shared_meshes_or_panic(Path::new(env!("CARGO_MANIFEST_DIR")));
    let mesh = meshes.join("cornell-box/CornellBox-Original.obj");
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("bench.csv");
    let out = englobe()
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

#[cfg(not(feature = "bench"))]
#[test]
fn without_the_feature_bench_says_how_to_run_the_benchmark() {
    let help = englobe().arg("--help").output().unwrap();
    assert!(help.status.success());
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(help.lines().any(|l| l.trim_start().starts_with("bench ")), "bench is listed:\n{help}");
    for args in [&["bench"][..], &["bench", "mesh.obj", "--threads", "1,2", "-o", "out.csv"], &["bench", "--help"]] {
        let out = englobe().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        for expected in ["`bench` cargo feature", "cargo run --release -p englobe-bench -- MESH...", "--features bench"]
        {
            assert!(err.contains(expected), "{args:?}: {expected} in\n{err}");
        }
    }
}
