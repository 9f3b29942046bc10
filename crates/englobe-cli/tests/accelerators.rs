//! `englobe compare --plot`: the SVG holds a bar per structure and panel, with the names.

use std::path::Path;
use std::process::Command;

use englobe::AccelKind;
use serde_json::Value;

fn scene(name: &str) -> String {
    format!("{}/../../scenes/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// Exact tests per ray of each structure of `accels` on `scene` at `width` x `height`; every
/// image must be brute force's.
fn tests_per_ray(scene: &str, width: u32, height: u32, accels: &[AccelKind], plot: Option<&Path>) -> Vec<f64> {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("compare.json");
    let names: Vec<&str> = accels.iter().map(|k| k.name()).collect();
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_englobe"));
    cmd.args(["compare", scene, "-q", "--budget", "0.5", "--json"]).arg(&json);
    cmd.args(["--width", &width.to_string(), "--height", &height.to_string(), "--accel", &names.join(",")]);
    if let Some(p) = plot {
        cmd.arg("--plot").arg(p);
    }
    let out = cmd.output().expect("englobe runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let rows = report["rows"].as_array().unwrap();
    accels
        .iter()
        .map(|k| {
            let row = rows.iter().find(|r| r["accel"] == k.name()).unwrap_or_else(|| panic!("no row for {k}"));
            assert_eq!(row["image_equal"], Value::Bool(true), "{row}");
            row["exact_tests_per_ray"].as_f64().unwrap()
        })
        .collect()
}

#[test]
fn compare_draws_its_plot() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("plot.svg");
    let kinds = [AccelKind::BvhSeedOrdered, AccelKind::KdTree, AccelKind::Grid];
    tests_per_ray(&scene("seed/test3.toml"), 48, 48, &kinds, Some(&svg));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
    for name in ["none", "bvh-seed-ordered", "kdtree", "grid", "rays per second", "exact tests per ray"] {
        assert!(text.contains(name), "{name} missing from the plot");
    }
    // Two bars per structure, brute force included.
    assert_eq!(text.matches("<rect x=").count(), 2 * 4);
}
