//! End-to-end runs of `englobe render`: the default scene, statistics, thread independence, and
//! every kind of bad input refused with a located error and a non-zero exit.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn englobe(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_englobe")).args(args).current_dir(dir).output().expect("englobe runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn render_with_no_arguments_writes_the_default_scene_and_says_where() {
    let dir = tempfile::tempdir().unwrap();
    let out = englobe(dir.path(), &["render"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).starts_with("wrote englobe.png (640x480"), "{}", stdout(&out));
    let img = image::open(dir.path().join("englobe.png")).unwrap();
    assert_eq!((img.width(), img.height()), (640, 480));
}

#[test]
fn stats_table_and_json() {
    let dir = tempfile::tempdir().unwrap();
    let out = englobe(
        dir.path(),
        &[
            "render",
            "--width",
            "40",
            "--height",
            "30",
            "--spp",
            "1",
            "--stats",
            "--stats-json",
            "s.json",
            "--accel",
            "none",
            "-o",
            "a.png",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    for row in ["primary", "shadow", "reflected", "refracted", "total"] {
        assert!(text.lines().any(|l| l.starts_with(row)), "no `{row}` row in:\n{text}");
    }
    let primary: Vec<&str> = text.lines().find(|l| l.starts_with("primary")).unwrap().split_whitespace().collect();
    assert_eq!(primary[1], "1200", "40 x 30 primary rays");
    assert_eq!(primary[2], "7200", "6 objects tested per primary ray by brute force");

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.json")).unwrap()).unwrap();
    assert_eq!(json["accel"], "none");
    assert_eq!(json["kinds"][0]["kind"], "primary");
    assert_eq!(json["kinds"][0]["rays"], 1200);
    assert_eq!(json["kinds"][0]["exact_tests"], 7200);
    assert!(json["total"]["rays"].as_u64().unwrap() > 1200);
}

#[test]
fn one_and_two_threads_write_identical_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let common = ["render", "--width", "64", "--height", "48", "--spp", "2", "--quiet"];
    let one = englobe(dir.path(), &[&common[..], &["--threads", "1", "-o", "one.png"]].concat());
    let two = englobe(dir.path(), &[&common[..], &["--threads", "2", "-o", "two.png"]].concat());
    assert!(one.status.success() && two.status.success());
    assert!(stdout(&one).is_empty(), "--quiet prints nothing");
    let a = std::fs::read(dir.path().join("one.png")).unwrap();
    let b = std::fs::read(dir.path().join("two.png")).unwrap();
    assert_eq!(a, b);
    // And a second run, the path tracer's random sequences included.
    let again = englobe(dir.path(), &[&common[..], &["--threads", "2", "-o", "again.png"]].concat());
    assert!(again.status.success());
    assert_eq!(a, std::fs::read(dir.path().join("again.png")).unwrap());
    for name in ["path-1.png", "path-2.png"] {
        let path = englobe(dir.path(), &[&common[..], &["--integrator", "path", "-o", name]].concat());
        assert!(path.status.success(), "{}", stderr(&path));
    }
    let (p1, p2) =
        (std::fs::read(dir.path().join("path-1.png")).unwrap(), std::fs::read(dir.path().join("path-2.png")));
    assert_eq!(p1, p2.unwrap());
}

#[test]
fn example_scenes_render_with_statistics() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = repo_root().join("scenes");
    for name in ["default.toml", "glass.toml", "mirrors.toml"] {
        let path = scenes.join(name);
        let out =
            englobe(dir.path(), &["render", path.to_str().unwrap(), "--width", "48", "--height", "36", "--stats"]);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        assert!(stdout(&out).contains("exact tests"), "{name}");
        let png = PathBuf::from(name).with_extension("png");
        assert!(dir.path().join(png).exists(), "{name}: the image is named after the scene");
    }
}

/// Bad scene files: each must exit non-zero with `bad.toml:LINE:COLUMN:` and the expectation.
#[test]
fn bad_scenes_fail_with_file_line_and_column() {
    let good = std::fs::read_to_string(repo_root().join("scenes/default.toml")).unwrap();
    let cases: &[(&str, &str, &str)] = &[
        ("radius = 1.0", "radius = 1.0\nweight = 2", "unknown field `weight`"),
        ("radius = 1.0", "", "missing field `radius`"),
        ("radius = 1.0", "radius = \"big\"", "invalid type"),
        ("material = \"red\"", "material = \"crimson\"", "unknown material `crimson`"),
        ("radius = 1.0", "radius = 0", "greater than 0"),
        ("radius = 1.0", "radius = -1", "greater than 0"),
        ("look_at = [0.0, 0.8, 0.0]", "look_at = [0.0, 1.6, -7.0]", "must differ"),
        ("up = [0.0, 1.0, 0.0]", "up = [0.0, -0.8, 7.0]", "parallel"),
        ("radius = 1.0", "radius = nan", "finite"),
        ("intensity = 45", "intensity = inf", "finite"),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (from, to, expected) in cases {
        assert!(good.contains(from), "{from}");
        std::fs::write(dir.path().join("bad.toml"), good.replacen(from, to, 1)).unwrap();
        let out = englobe(dir.path(), &["render", "bad.toml", "-o", "bad.png"]);
        let err = stderr(&out);
        assert!(!out.status.success(), "accepted: {to}");
        let located = err.strip_prefix("error: bad.toml:").unwrap_or_else(|| panic!("{to}: {err}"));
        let mut parts = located.splitn(3, ':');
        let line: usize = parts.next().unwrap().parse().unwrap_or_else(|_| panic!("{err}"));
        let column: usize = parts.next().unwrap().parse().unwrap_or_else(|_| panic!("{err}"));
        assert!(line > 1 && column >= 1);
        assert!(err.contains(expected), "{to}: {err}");
        assert!(!dir.path().join("bad.png").exists());
        assert!(!err.contains("panicked"));
    }
}

#[test]
fn bad_arguments_and_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let refused = |args: &[&str], expected: &str| {
        let out = englobe(dir.path(), args);
        assert!(!out.status.success(), "{args:?} was accepted");
        assert!(stderr(&out).contains(expected), "{args:?}: {}", stderr(&out));
        assert!(!stderr(&out).contains("panicked"));
    };
    refused(&["render", "--width", "0"], "at least 1");
    refused(&["render", "--width", "100000", "--height", "100000"], "more than the limit");
    refused(&["render", "--spp", "0"], "samples per pixel");
    refused(&["render", "--spp", "100000000"], "samples per pixel");
    refused(&["render", "--width", "4294967296"], "--width");
    refused(&["render", "--width", "65536", "--height", "65536"], "more than the limit");
    refused(&["render", "--height=-3"], "--height");
    refused(&["render", "--threads", "0"], "--threads");
    refused(&["render", "missing.toml"], "missing.toml: cannot read");
    refused(&["render", "."], "is a directory");
    refused(&["render", "-o", "picture.jpg"], ".png or .exr");
    refused(&["render", "--accel", "octree"], "unknown accelerator `octree`");
}

#[test]
fn a_failed_render_leaves_an_existing_image_untouched() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("keep.png"), b"a good image").unwrap();
    std::fs::write(dir.path().join("bad.toml"), "[image]\nwidth = 0\nheight = 1\n").unwrap();
    let out = englobe(dir.path(), &["render", "bad.toml", "-o", "keep.png"]);
    assert!(!out.status.success());
    assert_eq!(std::fs::read(dir.path().join("keep.png")).unwrap(), b"a good image");
}

#[test]
fn exr_output_is_linear_float() {
    let dir = tempfile::tempdir().unwrap();
    let out = englobe(dir.path(), &["render", "--width", "16", "--height", "12", "-o", "hdr.exr"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(dir.path().join("hdr.exr")).unwrap().to_rgb32f();
    assert_eq!(img.dimensions(), (16, 12));
}

#[cfg(unix)]
#[test]
fn ctrl_c_stops_with_code_130_and_writes_nothing() {
    use std::time::{Duration, Instant};
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("keep.png"), b"a good image").unwrap();
    // Thousands of samples per pixel: far more work than the test waits for.
    let mut child = Command::new(env!("CARGO_BIN_EXE_englobe"))
        .args(["render", "--spp", "20000", "--accel", "none", "-o", "keep.png"])
        .current_dir(dir.path())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let sent = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    assert!(sent.success());
    // A guard, not a measurement: a render that ignored Ctrl-C would run for many minutes.
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > Duration::from_secs(120) {
            child.kill().unwrap();
            panic!("the render did not stop after Ctrl-C");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let mut err = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
    assert_eq!(status.code(), Some(130), "{err}");
    // The tiles really done, not the bar's end: fewer than all of them (20000 samples per pixel
    // take minutes), and as many as the render finished.
    let counts = err.split("stopped after ").nth(1).unwrap_or_else(|| panic!("{err}"));
    let words: Vec<&str> = counts.split_whitespace().collect();
    let (done, total): (usize, usize) = (words[0].parse().unwrap(), words[2].parse().unwrap());
    assert_eq!((words[1], words[3], total), ("of", "tiles;", 300), "{err}");
    assert!(done < total, "{done} of {total} tiles after 1.5 s of a render of minutes: {err}");
    assert_eq!(std::fs::read(dir.path().join("keep.png")).unwrap(), b"a good image");
    let leftovers: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(leftovers.len(), 1, "no temporary file is left behind");
}

#[cfg(unix)]
#[test]
fn an_unreadable_scene_file_is_named_in_the_error() {
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink("loop.toml", dir.path().join("loop.toml")).unwrap();
    let out = englobe(dir.path(), &["render", "loop.toml"]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("loop.toml: cannot read") && err.contains("symbolic links"), "{err}");
}

#[cfg(unix)]
#[test]
fn killing_a_render_at_any_moment_never_leaves_a_broken_image() {
    use std::time::Instant;
    let dir = tempfile::tempdir().unwrap();
    // The good image already there: small, so that it can be told apart from the new one.
    let first = englobe(dir.path(), &["render", "--width", "30", "--height", "20", "--spp", "1", "-o", "out.png"]);
    assert!(first.status.success());
    let args = ["render", "--width", "900", "--height", "700", "--spp", "1", "--quiet", "-o", "out.png"];
    let start = Instant::now();
    assert!(englobe(dir.path(), &args).status.success());
    let full = start.elapsed();
    let mut outcomes = std::collections::BTreeSet::new();
    for k in 0..12u32 {
        // Restore the small image, then kill a new render at a point spread over its life.
        assert!(
            englobe(dir.path(), &["render", "--width", "30", "--height", "20", "--spp", "1", "-o", "out.png"])
                .status
                .success()
        );
        let mut child = Command::new(env!("CARGO_BIN_EXE_englobe")).args(args).current_dir(dir.path()).spawn().unwrap();
        std::thread::sleep(full * k / 10);
        let _ = child.kill(); // SIGKILL: no handler runs
        child.wait().unwrap();
        let img = image::open(dir.path().join("out.png")).expect("out.png is always a complete image");
        outcomes.insert((img.width(), img.height()));
        assert!(matches!((img.width(), img.height()), (30, 20) | (900, 700)), "{}x{}", img.width(), img.height());
    }
    eprintln!("images seen after the kills: {outcomes:?}");
    assert!(outcomes.contains(&(30, 20)), "some kills came before the new image was in place");
}

/// `englobe` with `args` in `dir`, its standard error a terminal (through script(1)); what the
/// terminal showed.
#[cfg(target_os = "linux")]
fn on_a_terminal(dir: &Path, args: &str) -> String {
    let o = Command::new("script")
        .args(["-qec", &format!("\"{}\" {args}", env!("CARGO_BIN_EXE_englobe")), "/dev/null"])
        .current_dir(dir)
        .output()
        .expect("script(1) runs");
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[cfg(target_os = "linux")]
#[test]
fn phases_are_shown_on_a_terminal_with_counts_and_times_and_never_in_a_pipe() {
    let dir = tempfile::tempdir().unwrap();
    let scene = repo_root().join("scenes/bunny.toml").display().to_string();
    let shown = on_a_terminal(dir.path(), &format!("render {scene} --scale 0.1 --spp 1 -o b.png"));
    assert!(shown.contains(&format!("loaded {scene} in ")), "{shown}");
    assert!(shown.contains("(69451 triangles in the picture from 1 mesh file(s)), 2 lights"), "{shown}");
    assert!(shown.contains("stanford-bunny.obj: 69451 triangles in "), "the mesh file's own phase: {shown}");
    assert!(shown.contains("built bvh-wide in ") && shown.contains(" s over 69451 triangles"), "{shown}");
    let quiet = on_a_terminal(dir.path(), &format!("render {scene} --scale 0.1 --spp 1 -q -o b.png"));
    assert!(!quiet.contains("loaded") && !quiet.contains("wrote"), "{quiet}");
    let piped = englobe(dir.path(), &["render", &scene, "--scale", "0.1", "--spp", "1", "-o", "b.png"]);
    assert!(stderr(&piped).is_empty(), "a pipe gets no phases: {}", stderr(&piped));
}

#[test]
fn the_summary_splits_the_wall_time_into_load_build_and_render() {
    let dir = tempfile::tempdir().unwrap();
    let out = englobe(dir.path(), &["render", "--width", "64", "--spp", "1"]);
    let line = stdout(&out);
    let seconds = |after: &str| -> f64 {
        let at = line.find(after).unwrap_or_else(|| panic!("no `{after}` in {line}")) + after.len();
        line[at..].split(' ').next().unwrap().parse().unwrap()
    };
    let (wall, load, build, render) =
        (seconds("accel bvh-wide, "), seconds("threads: load "), seconds("build "), seconds("render "));
    assert!(line.trim_end().ends_with(" s)"), "{line}");
    // Rounded to hundredths each, the parts cannot exceed the whole by more than the rounding.
    assert!(load + build + render <= wall + 0.015, "{line}");
}
