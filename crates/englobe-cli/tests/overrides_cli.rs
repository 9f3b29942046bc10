//! End-to-end runs of the options for iterating on a render: `-D key=value` overrides of any scene
//! value, the aspect ratio kept by `--width` alone, `--scale` previews, and a scene read from
//! standard input.

use std::io::Write;
use std::path::Path;
use std::process::{Command, Output, Stdio};

fn englobe(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_englobe")).args(args).current_dir(dir).output().expect("englobe runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn size(path: &Path) -> (u32, u32) {
    let img = image::open(path).unwrap();
    (img.width(), img.height())
}

#[test]
fn overrides_of_nested_keys_and_arrays_change_the_image() {
    let dir = tempfile::tempdir().unwrap();
    let base = ["render", "--width", "48", "--spp", "1", "--quiet"];
    let run = |extra: &[&str], out: &str| {
        let o = englobe(dir.path(), &[&base[..], extra, &["-o", out]].concat());
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read(dir.path().join(out)).unwrap()
    };
    let plain = run(&[], "plain.png");
    let fov = run(&["-D", "camera.fov=30"], "fov.png");
    let light = run(&["--set", "point_light.0.intensity=90"], "light.png");
    let material = run(&["-D", "materials.red.diffuse=[0.1, 0.8, 0.1]"], "material.png");
    let same = run(&["-D", "camera.fov=45"], "same.png");
    assert_ne!(plain, fov, "a narrower field of view changes the image");
    assert_ne!(plain, light, "a brighter first point light changes the image");
    assert_ne!(plain, material, "a green `red` material changes the image");
    assert_eq!(plain, same, "overriding a value with the one the scene has changes nothing");
}

#[test]
fn an_override_of_the_image_size_is_the_scene_s() {
    let dir = tempfile::tempdir().unwrap();
    let o = englobe(dir.path(), &["render", "-D", "image.width=32", "-D", "image.height=20", "-D", "image.samples=1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).starts_with("wrote englobe.png (32x20, 1 spp"), "{}", stdout(&o));
    assert_eq!(size(&dir.path().join("englobe.png")), (32, 20));
}

#[test]
fn a_bad_override_is_named_with_its_column_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let o = englobe(dir.path(), &["render", "-D", "image.samples=2", "-D", "camera.fov=400"]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("error: -D camera.fov=400:1:15: a field of view of 400 degrees"), "{e}");
    assert!(e.contains("1 | -D camera.fov=400"), "the override is shown under the message: {e}");
    let o = englobe(dir.path(), &["render", "-D", "camera.zoom=2"]);
    assert!(stderr(&o).contains("-D camera.zoom=2:1:11: unknown field `zoom`, expected one of"), "{}", stderr(&o));
    let o = englobe(dir.path(), &["render", "-D", "point_light.7.intensity=1"]);
    assert!(stderr(&o).contains("`point_light` has 1 entries"), "{}", stderr(&o));
    let o = englobe(dir.path(), &["render", "-D", "camera.fov"]);
    assert!(stderr(&o).contains("expected KEY=VALUE"), "{}", stderr(&o));
    assert!(!dir.path().join("englobe.png").exists());
}

#[test]
fn a_width_alone_keeps_the_aspect_ratio_and_scale_shrinks_both() {
    let dir = tempfile::tempdir().unwrap();
    let o = englobe(dir.path(), &["render", "--width", "160", "--spp", "1", "-o", "w.png"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(size(&dir.path().join("w.png")), (160, 120), "640x480 at width 160");
    let o = englobe(dir.path(), &["render", "--height", "60", "--spp", "1", "-o", "h.png"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(size(&dir.path().join("h.png")), (80, 60));
    let o = englobe(dir.path(), &["render", "--scale", "0.125", "--spp", "1", "-o", "s.png"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(size(&dir.path().join("s.png")), (80, 60));
    let o = englobe(dir.path(), &["render", "--scale", "0", "-o", "z.png"]);
    assert!(!o.status.success() && stderr(&o).contains("expected a factor greater than 0"), "{}", stderr(&o));
}

#[test]
fn a_scene_is_read_from_standard_input() {
    let dir = tempfile::tempdir().unwrap();
    let scene = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/default.toml"))
        .unwrap()
        .replace("width = 640", "width = 40")
        .replace("height = 480", "height = 30");
    let run = |text: &str| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_englobe"))
            .args(["render", "-", "-o", "in.png"])
            .current_dir(dir.path())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        child.stdin.take().unwrap().write_all(text.as_bytes()).unwrap();
        child.wait_with_output().unwrap()
    };
    let o = run(&scene);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(size(&dir.path().join("in.png")), (40, 30));
    let o = run(&scene.replace("fov = 45", "fov = -1"));
    assert!(!o.status.success());
    assert!(stderr(&o).contains("error: <stdin>:17:7: a field of view of -1 degrees"), "{}", stderr(&o));
}

#[test]
fn the_camera_is_set_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let run = |extra: &[&str], out: &str| {
        let o = englobe(dir.path(), &[&["render", "--width", "48", "--spp", "2", "-q", "-o", out][..], extra].concat());
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read(dir.path().join(out)).unwrap()
    };
    let flags = run(&["--look-from", "2,3,-6", "--look-at", "0,0.5,0", "--fov", "35"], "flags.png");
    let set = run(
        &["-D", "camera.position=[2, 3, -6]", "-D", "camera.look_at=[0, 0.5, 0]", "-D", "camera.fov=35"],
        "set.png",
    );
    assert_eq!(flags, set, "the flags are the overrides");
    assert_ne!(flags, run(&[], "plain.png"));
    let ortho = run(&["-D", "camera.projection=orthographic", "-D", "camera.view_height=4"], "ortho.png");
    let lens = run(&["-D", "camera.aperture=0.3", "-D", "camera.focus_distance=7"], "lens.png");
    assert_ne!(ortho, run(&[], "plain2.png"));
    assert_ne!(lens, ortho);
    let o = englobe(dir.path(), &["render", "--fov", "190"]);
    assert!(stderr(&o).contains("`190`: expected degrees, more than 0 and less than 180"), "{}", stderr(&o));
    let o = englobe(dir.path(), &["render", "--look-from", "1,2"]);
    assert!(stderr(&o).contains("`1,2`: expected three numbers X,Y,Z"), "{}", stderr(&o));
    let o = englobe(dir.path(), &["render", "--look-from", "0,0.8,0"]);
    assert!(stderr(&o).contains("the camera's look_at must differ from its position"), "{}", stderr(&o));
}
