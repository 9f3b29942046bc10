//! `englobe render --noise-threshold` end to end: fewer samples than the maximum, said in the
//! summary and the statistics; the map of samples per pixel; tiles that assemble to the bytes of
//! one render; a time limit that keeps whole passes; the map refused, before rendering, where
//! there is no threshold.

use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn englobe(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_englobe")).args(args).current_dir(dir).output().expect("englobe runs")
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    o
}

/// The default scene, path traced: sky around noisy spheres.
const ADAPTIVE: [&str; 10] =
    ["--width", "48", "--height", "36", "--integrator", "path", "--spp", "64", "--noise-threshold", "0.05"];

#[test]
fn fewer_samples_said_in_the_summary_the_statistics_and_the_map() {
    let dir = tempfile::tempdir().unwrap();
    let mut args = vec!["render", "-o", "a.png", "--stats", "--stats-json", "s.json", "--samples-map", "spp.png"];
    args.extend(ADAPTIVE);
    let o = ok(englobe(dir.path(), &args));
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(said.contains("adaptive ") && said.contains(" spp of at most 64, threshold 0.05"), "{said}");
    // The first pass, as Cycles chooses it: 16 / 0.05^0.3 = 39.3.
    assert!(said.contains("per pixel on average (40 to "), "{said}");
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.path().join("s.json")).unwrap()).unwrap();
    let total = json["samples_total"].as_u64().unwrap();
    let mean = json["samples_mean"].as_f64().unwrap();
    assert!((48 * 36 * 40..48 * 36 * 64).contains(&total), "{total}");
    assert!((mean - total as f64 / (48.0 * 36.0)).abs() < 1e-9);
    assert_eq!(json["noise_threshold"].as_f64().unwrap() as f32, 0.05);
    // Every sample is one primary ray.
    let primary = json["kinds"].as_array().unwrap().iter().find(|k| k["kind"] == "primary").unwrap();
    assert_eq!(primary["rays"].as_u64().unwrap(), total);
    let map = image::open(dir.path().join("spp.png")).unwrap().to_rgb8();
    assert_eq!(map.width(), 48);
    assert!(map.height() > 36, "the colour bar below");
    // The top-left block is sky: the fewest samples, the darkest colour of the map.
    let (corner, centre) = (map.get_pixel(0, 0).0, map.get_pixel(24, 20).0);
    assert_ne!(corner, centre);
    // The uniform render takes every sample.
    let mut uniform = vec!["render", "-o", "u.png", "--stats-json", "u.json"];
    uniform.extend(&ADAPTIVE[..8]);
    ok(englobe(dir.path(), &uniform));
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.path().join("u.json")).unwrap()).unwrap();
    assert_eq!(json["samples_total"].as_u64().unwrap(), 48 * 36 * 64);
    assert!(json["noise_threshold"].is_null());
}

#[test]
fn adaptive_tiles_assemble_to_the_bytes_of_one_render() {
    let dir = tempfile::tempdir().unwrap();
    let mut whole = vec!["render", "-q", "-o", "whole.exr"];
    whole.extend(ADAPTIVE);
    ok(englobe(dir.path(), &whole));
    // Three strips of 12 rows: their edges cut the 8x8 blocks.
    let mut names = Vec::new();
    for k in 0..3 {
        let name = format!("t{k}.exr");
        let tile = format!("{k}/3");
        let mut args = vec!["render", "-q", "--tile", &tile, "-o", &name];
        args.extend(ADAPTIVE);
        ok(englobe(dir.path(), &args));
        names.push(name);
    }
    let mut args = vec!["assemble", "-o", "tiled.exr"];
    args.extend(names.iter().map(String::as_str));
    ok(englobe(dir.path(), &args));
    assert_eq!(
        std::fs::read(dir.path().join("whole.exr")).unwrap(),
        std::fs::read(dir.path().join("tiled.exr")).unwrap()
    );
    // A tile of another threshold is another render: assembly refuses it.
    let mut other = vec!["render", "-q", "--tile", "2/3", "-o", "other.exr"];
    other.extend(&ADAPTIVE[..9]);
    other.push("0.02");
    ok(englobe(dir.path(), &other));
    let o = englobe(dir.path(), &["assemble", "-o", "mixed.exr", "t0.exr", "t1.exr", "other.exr"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("other.exr"), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn a_time_limit_keeps_whole_adaptive_passes() {
    let dir = tempfile::tempdir().unwrap();
    let start = Instant::now();
    let o = englobe(
        dir.path(),
        &[
            "render",
            "--width",
            "64",
            "--integrator",
            "path",
            "--spp",
            "65536",
            "--noise-threshold",
            "0.0001",
            "-D",
            "image.min_samples=4",
            "--time-limit",
            "1.5s",
            "-o",
            "t.png",
        ],
    );
    assert!(start.elapsed() < Duration::from_secs(60), "the limit stopped the render");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.starts_with("time limit of 1.5 s reached: stopped at "), "{e}");
    assert!(e.contains("of at most 65536 samples per pixel; writing the image of the passes complete"), "{e}");
    assert!(dir.path().join("t.png").exists());
}

#[test]
fn a_samples_map_without_a_threshold_is_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let o = englobe(dir.path(), &["render", "--width", "32", "--spp", "4", "--samples-map", "m.png", "-o", "x.png"]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("m.png: every pixel takes 4 sample(s) without a noise threshold"), "{e}");
    assert!(!dir.path().join("x.png").exists() && !dir.path().join("m.png").exists());
    let o = englobe(dir.path(), &["render", "--noise-threshold=-1"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("expected a relative error of 0 or more"));
    // The scene key works through the generic override as well.
    let o = ok(englobe(
        dir.path(),
        &[
            "render",
            "--width",
            "32",
            "--integrator",
            "path",
            "--spp",
            "32",
            "-D",
            "image.noise_threshold=0.05",
            "-o",
            "d.png",
        ],
    ));
    assert!(String::from_utf8_lossy(&o.stdout).contains("spp of at most 32, threshold 0.05"));
}
