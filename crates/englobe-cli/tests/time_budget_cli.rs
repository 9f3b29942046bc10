//! Time budgets: `--time-limit` stops at the last complete sample pass and writes that image
//! (the image of a render with that many samples), saying so; `--keep-partial` keeps what is done
//! on Ctrl-C; a render by passes that finishes writes the bytes of a normal render.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn englobe(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_englobe")).args(args).current_dir(dir).output().expect("englobe runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The `K` of "stopped after K of N sample passes".
fn passes_done(message: &str) -> u32 {
    let after = message.split("stopped after ").nth(1).unwrap_or_else(|| panic!("{message}"));
    after.split(' ').next().unwrap().parse().unwrap()
}

#[test]
fn a_time_limit_writes_the_image_of_the_last_complete_pass() {
    let dir = tempfile::tempdir().unwrap();
    let start = Instant::now();
    let o = englobe(dir.path(), &["render", "--width", "64", "--spp", "65536", "--time-limit", "1.5s", "-o", "t.png"]);
    assert!(start.elapsed() < Duration::from_secs(30), "the limit stopped the render");
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.starts_with("time limit of 1.5 s reached: stopped after "), "{e}");
    let k = passes_done(&e);
    assert!((1..65536).contains(&k), "{e}");
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(said.starts_with(&format!("wrote t.png (64x48, {k} spp")), "{said}");
    if k >= 2 {
        // The first k passes of any render are the k-sample render (one sample alone is centred).
        let o = englobe(dir.path(), &["render", "--width", "64", "--spp", &k.to_string(), "-o", "k.png"]);
        assert!(o.status.success());
        assert_eq!(std::fs::read(dir.path().join("t.png")).unwrap(), std::fs::read(dir.path().join("k.png")).unwrap());
    }
}

#[test]
fn a_time_limit_not_reached_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    for integrator in ["whitted", "path"] {
        let common = ["render", "--width", "48", "--spp", "3", "-q", "--integrator", integrator];
        let plain = englobe(dir.path(), &[&common[..], &["-o", "plain.png"]].concat());
        let limited = englobe(dir.path(), &[&common[..], &["--time-limit", "1h", "-o", "limited.png"]].concat());
        assert!(plain.status.success() && limited.status.success(), "{}", stderr(&limited));
        assert!(stderr(&limited).is_empty(), "{}", stderr(&limited));
        assert_eq!(
            std::fs::read(dir.path().join("plain.png")).unwrap(),
            std::fs::read(dir.path().join("limited.png")).unwrap(),
            "{integrator}"
        );
    }
}

#[test]
fn a_time_limit_before_the_first_pass_writes_nothing_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    // Loading the 69 451-triangle bunny alone takes longer than 5 ms.
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/bunny.toml").display().to_string();
    let o = englobe(dir.path(), &["render", &scene, "--time-limit", "5ms", "-o", "b.png"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("stopped after 0 of 1 sample passes; no image written"), "{}", stderr(&o));
    assert!(!dir.path().join("b.png").exists());
    let o = englobe(dir.path(), &["render", "--time-limit", "soon"]);
    assert!(stderr(&o).contains("`soon`: unknown unit"), "{}", stderr(&o));
    let o = englobe(dir.path(), &["render", "--time-limit", "3s", "--tile", "0/2"]);
    assert!(stderr(&o).contains("cannot be used with"), "{}", stderr(&o));
}

#[cfg(unix)]
#[test]
fn keep_partial_writes_what_is_done_on_ctrl_c() {
    let dir = tempfile::tempdir().unwrap();
    let out: PathBuf = dir.path().join("partial.png");
    let child = Command::new(env!("CARGO_BIN_EXE_englobe"))
        .args(["render", "--width", "160", "--spp", "20000", "--keep-partial", "-o", "partial.png"])
        .current_dir(dir.path())
        .stderr(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(2000));
    assert!(Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap().success());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.starts_with("interrupted: stopped after "), "{e}");
    let k = passes_done(&e);
    assert!(e.contains(&format!("writing the image of the {k} complete")), "{e}");
    assert!(String::from_utf8_lossy(&o.stdout).starts_with(&format!("wrote partial.png (160x120, {k} spp")));
    let img = image::open(&out).unwrap();
    assert_eq!((img.width(), img.height()), (160, 120));
}
