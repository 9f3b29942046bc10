//! Failing early and once: the destination is checked before anything is read or rendered, an
//! I/O error names the destination and its cause once, and size limits hold for files that have
//! no size beforehand (devices, pipes).

use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn englobe(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_englobe")).args(args).current_dir(dir).output().expect("englobe runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn the_destination_is_checked_before_the_render_starts() {
    let dir = tempfile::tempdir().unwrap();
    // Hours of work at this size, and a scene that does not exist: only a check made first can
    // answer at once, and about the destination.
    let huge = ["--width", "16000", "--height", "16000", "--spp", "4096"];
    let cases: [(&str, &str); 4] = [
        ("no-such-folder/out.png", "no-such-folder/out.png: cannot write: the folder no-such-folder does not exist"),
        ("out.jpg", "out.jpg: unsupported image format; expected a file name ending in .png or .exr"),
        (".", ".: cannot write: it is a folder"),
        ("file.txt/out.png", "file.txt/out.png: cannot write: file.txt is not a folder"),
    ];
    std::fs::write(dir.path().join("file.txt"), "").unwrap();
    for (out, message) in cases {
        let start = Instant::now();
        let o = englobe(dir.path(), &[&["render", "missing.toml", "-o", out][..], &huge].concat());
        assert!(start.elapsed() < Duration::from_secs(20), "{out}: the render started");
        assert!(!o.status.success());
        let e = stderr(&o);
        assert_eq!(e.trim_end(), format!("error: {message}"), "{out}: the message is the destination's, and only it");
    }
    let o = englobe(dir.path(), &["render", "missing.toml", "-o", "fine.png"]);
    assert!(stderr(&o).contains("missing.toml: cannot read"), "a good destination passes: {}", stderr(&o));
    assert!(
        std::fs::read_dir(dir.path()).unwrap().all(|e| !e.unwrap().file_name().to_string_lossy().ends_with(".tmp"))
    );
}

#[test]
fn the_statistics_file_is_checked_before_the_render_starts() {
    let dir = tempfile::tempdir().unwrap();
    let huge = ["--width", "16000", "--height", "16000", "--spp", "4096"];
    let start = Instant::now();
    let o = englobe(
        dir.path(),
        &[&["render", "missing.toml", "-o", "out.png", "--stats-json", "gone/s.json"][..], &huge].concat(),
    );
    assert!(start.elapsed() < Duration::from_secs(20), "the render started");
    assert_eq!(stderr(&o).trim_end(), "error: gone/s.json: cannot write: the folder gone does not exist");
    assert!(!dir.path().join("out.png").exists());
}

#[test]
fn an_io_error_names_the_destination_and_its_cause_once() {
    let dir = tempfile::tempdir().unwrap();
    let o = englobe(dir.path(), &["render", "--width", "8", "-o", "gone/x.png"]);
    let e = stderr(&o);
    assert_eq!(e.matches("does not exist").count(), 1, "{e}");
    assert!(!e.contains(".englobe-") && !e.contains(".tmp"), "no temporary file is named: {e}");
}

#[cfg(unix)]
#[test]
fn an_endless_device_stops_at_the_size_limit_with_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["zero.obj", "zero.toml"] {
        std::os::unix::fs::symlink("/dev/zero", dir.path().join(name)).unwrap();
    }
    // 4 GiB of address space: reading /dev/zero to its end would exhaust it and abort, not refuse.
    let run = |args: &str| {
        Command::new("sh")
            .arg("-c")
            .arg(format!("ulimit -v 4194304 && exec \"$0\" {args}"))
            .arg(env!("CARGO_BIN_EXE_englobe"))
            .current_dir(dir.path())
            .output()
            .unwrap()
    };
    let o = run("info zero.obj");
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("zero.obj: more than the limit of 2147483648 bytes (not a regular file"),
        "{}",
        stderr(&o)
    );
    let o = run("render zero.toml -o z.png");
    assert!(
        stderr(&o).contains("zero.toml: cannot read: the file is larger than the 67108864-byte limit"),
        "{}",
        stderr(&o)
    );
}
