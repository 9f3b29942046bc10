//! `englobe render` and `englobe info` on pbrt scenes: the reference Cornell box rendered from its
//! own file, what is reported and what `--strict` refuses, and the overrides that do not apply.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use englobe_scene::shared_data::locate_shared;

fn englobe(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_englobe")).args(args).output().expect("the englobe binary runs")
}

fn scenes() -> PathBuf {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    locate_shared(&repo).expect("the shared scene data").join("scenes")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn info_shows_a_pbrt_scene_and_strict_refuses_what_it_would_approximate() {
    let cornell = scenes().join("cornell-bitterli/scene-v4.pbrt");
    let out = englobe(&["info", "--strict", cornell.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let shown = text(&out.stdout);
    for line in [
        "image:      1024x1024, 64 spp, depth 65",
        "integrator: path, filter triangle of radius [1, 1]",
        "camera:     at [0, 1, 6.8] looking at [0, 1, 0], up [0, 1, 0], vertical fov 19.5",
        "meshes 8",
        "Light + area light [17, 12, 4]",
    ] {
        assert!(shown.contains(line), "{line:?} missing from:\n{shown}");
    }
    let killeroo = scenes().join("meshes/pbrt-killeroo/killeroo-simple.pbrt");
    let out = englobe(&["info", killeroo.to_str().unwrap()]);
    assert!(out.status.success() && text(&out.stdout).contains("loopsubdiv"), "{}", text(&out.stdout));
    let out = englobe(&["info", "--strict", killeroo.to_str().unwrap()]);
    let err = text(&out.stderr);
    assert!(!out.status.success() && err.contains("killeroo-simple.pbrt:24:1: ") && err.contains("--strict"), "{err}");
}

#[test]
fn render_draws_the_cornell_box_from_its_file_and_refuses_overrides() {
    let cornell = scenes().join("cornell-bitterli/scene-v4.pbrt");
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("cornell.png");
    let out =
        englobe(&["render", cornell.to_str().unwrap(), "--width", "24", "--spp", "4", "-o", png.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("24x24, 4 spp, path"), "{}", text(&out.stdout));
    assert!(text(&out.stderr).contains("warning: ") && text(&out.stderr).contains("cornell-box.png"));
    assert!(png.is_file());
    for extra in [["-D", "camera.fov=30"], ["--fov", "30"]] {
        let mut args = vec!["render", cornell.to_str().unwrap(), "-o", png.to_str().unwrap()];
        args.extend(extra);
        let out = englobe(&args);
        let err = text(&out.stderr);
        assert!(!out.status.success() && err.contains("camera.fov=30") && err.contains("not to pbrt scenes"), "{err}");
    }
}
