//! `englobe render --tile/--pixel-bounds`, `englobe assemble` and `englobe farm slurm` end to
//! end: tiles assemble to the bytes of one render (PNG and EXR), assembly refuses a missing, a
//! duplicate, a foreign or a changed tile and says which, and the farm command renders every tile
//! through `sbatch`, then only the missing ones. The farm runs here against stand-ins for `sbatch`
//! and `squeue` that run the array's tasks at once; scripts/slurm-e2e.sh runs it on real Slurm.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn englobe_env(dir: &Path, args: &[&str], path: Option<&Path>, env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_englobe"));
    cmd.args(args).current_dir(dir);
    if let Some(bin) = path {
        cmd.env("PATH", format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default()));
    }
    cmd.envs(env.iter().copied()).output().expect("englobe runs")
}

fn englobe(dir: &Path, args: &[&str]) -> Output {
    englobe_env(dir, args, None, &[])
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    o
}

fn failure(o: Output) -> String {
    assert!(!o.status.success(), "expected a failure: {}", String::from_utf8_lossy(&o.stdout));
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn scene() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box-path.toml").display().to_string()
}

const SIZE: [&str; 6] = ["--width", "48", "--height", "36", "--spp", "4"];

fn render(dir: &Path, extra: &[&str]) -> Output {
    let scene = scene();
    let mut args = vec!["render", scene.as_str(), "-q"];
    args.extend(SIZE);
    args.extend(extra);
    ok(englobe(dir, &args))
}

fn tiles(dir: &Path, count: u32) -> Vec<String> {
    (0..count)
        .map(|k| {
            let name = format!("t{k}-of-{count}.exr");
            render(dir, &["--tile", &format!("{k}/{count}"), "-o", &name]);
            name
        })
        .collect()
}

fn assemble(dir: &Path, tiles: &[String], out: &str) -> Output {
    let mut args = vec!["assemble", "-o", out];
    args.extend(tiles.iter().map(String::as_str));
    englobe(dir, &args)
}

#[test]
fn one_four_and_seven_tiles_assemble_to_the_bytes_of_one_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    render(d, &["-o", "one.png"]);
    render(d, &["-o", "one.exr"]);
    for count in [1, 4, 7] {
        let t = tiles(d, count);
        for ext in ["png", "exr"] {
            let out = format!("assembled-{count}.{ext}");
            let o = ok(assemble(d, &t, &out));
            assert!(String::from_utf8_lossy(&o.stdout).contains(&format!("48x36 from {count} tiles")));
            assert_eq!(std::fs::read(d.join(&out)).unwrap(), std::fs::read(d.join(format!("one.{ext}"))).unwrap());
        }
    }
    // Strips cut by predicted cost too.
    for count in [4, 7] {
        let t: Vec<String> = (0..count)
            .map(|k| {
                let name = format!("c{k}-of-{count}.exr");
                render(d, &["--tile", &format!("{k}/{count}"), "--balance", "cost", "-o", &name]);
                name
            })
            .collect();
        ok(assemble(d, &t, "balanced.png"));
        assert_eq!(std::fs::read(d.join("balanced.png")).unwrap(), std::fs::read(d.join("one.png")).unwrap());
        // Mixed with strips cut by area, they are another render's.
        let mixed = [t[0].clone(), format!("t1-of-{count}.exr")];
        render(d, &["--tile", &format!("1/{count}"), "-o", &mixed[1]]);
        assert!(failure(assemble(d, &mixed, "x.png")).contains("different renders"));
    }
    // Any windows that cover the image once do too.
    for w in ["0,20,0,36", "20,48,0,10", "20,48,10,36"] {
        render(d, &["--pixel-bounds", w, "-o", &format!("w{w}.exr")]);
    }
    let windows: Vec<String> = ["0,20,0,36", "20,48,0,10", "20,48,10,36"].iter().map(|w| format!("w{w}.exr")).collect();
    ok(assemble(d, &windows, "windows.png"));
    assert_eq!(std::fs::read(d.join("windows.png")).unwrap(), std::fs::read(d.join("one.png")).unwrap());
}

#[test]
fn assembly_names_a_missing_a_duplicate_a_foreign_and_a_changed_tile() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let t = tiles(d, 4);

    let e = failure(assemble(d, &[t[0].clone(), t[1].clone(), t[3].clone()], "x.png"));
    assert!(e.contains("pixels are in no tile: 0,48,18,27") && e.contains("missing tiles: 2/4"), "{e}");
    let listed = ok(englobe(d, &["assemble", "--missing", &t[0], &t[3]]));
    assert_eq!(String::from_utf8_lossy(&listed.stdout), "1/4\n2/4\n");
    let listed = ok(englobe(d, &["assemble", "--missing", "--count", "4", &t[0], &t[1], &t[2], &t[3]]));
    assert_eq!(String::from_utf8_lossy(&listed.stdout), "");

    std::fs::copy(d.join(&t[2]), d.join("copy.exr")).unwrap();
    let mut with_copy = t.clone();
    with_copy.push("copy.exr".into());
    let e = failure(assemble(d, &with_copy, "x.png"));
    assert!(e.contains("tile 2/4 is given 2 times: t2-of-4.exr, copy.exr"), "{e}");

    render(d, &["--tile", "2/4", "-o", "foreign.exr", "--integrator", "whitted"]);
    let e = failure(assemble(d, &[t[0].clone(), t[1].clone(), "foreign.exr".into(), t[3].clone()], "x.png"));
    assert!(e.contains("come from 2 different renders") && e.contains("foreign.exr (scene"), "{e}");

    // One byte changed anywhere in the pixel data: the last byte of the file is compressed pixels.
    let mut bytes = std::fs::read(d.join(&t[1])).unwrap();
    *bytes.last_mut().unwrap() ^= 1;
    std::fs::write(d.join("changed.exr"), bytes).unwrap();
    let e = failure(assemble(d, &[t[0].clone(), "changed.exr".into(), t[2].clone(), t[3].clone()], "x.png"));
    assert!(e.contains("changed.exr:"), "{e}");
    assert!(!d.join("x.png").exists(), "no image is written when assembly fails");
}

#[test]
fn tile_options_are_checked_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = scene();
    let e = failure(englobe(d, &["render", &s, "--tile", "1/4", "-o", "t.png"]));
    assert!(e.contains("t.png: a tile is written as OpenEXR"), "{e}");
    let e = failure(englobe(d, &["render", &s, "--height", "3", "--tile", "1/4"]));
    assert!(e.contains("4 tiles for an image of 3 rows"), "{e}");
    let e = failure(englobe(d, &["render", &s, "--pixel-bounds", "0,10,0,401"]));
    assert!(e.contains("outside the 400x400 image"), "{e}");
    let e = failure(englobe(d, &["render", &s, "--tile", "4/4"]));
    assert!(e.contains("expected K/N"), "{e}");
    let o = ok(englobe(d, &["render", &s, "--width", "8", "--height", "8", "--spp", "1", "--tile", "1/2"]));
    assert!(
        String::from_utf8_lossy(&o.stdout)
            .starts_with("wrote cornell-box-path.tile-1-of-2.exr (tile 1/2, pixels 0,8,4,8 of 8x8")
    );
}

/// Stand-ins for `sbatch` (runs the array's tasks one after another, skipping the index in
/// `FAKE_SKIP`, and records each submission) and `squeue` (nothing is ever left queued).
fn fake_slurm(dir: &Path) -> PathBuf {
    let bin = dir.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let sbatch = r#"#!/bin/bash
echo "$@" >> "$FAKE_SLURM_LOG"
array=; out=; script="${@: -1}"
for a in "$@"; do
    case $a in --array=*) array=${a#--array=} ;; --output=*) out=${a#--output=} ;; esac
done
id=$(( $(wc -l < "$FAKE_SLURM_LOG") + 100 ))
IFS=, read -ra parts <<< "$array"
for p in "${parts[@]}"; do
    if [[ $p == *-* ]]; then ks=$(seq "${p%-*}" "${p#*-}"); else ks=$p; fi
    for k in $ks; do
        [ "$k" = "${FAKE_SKIP:-}" ] && continue
        log=${out//%A/$id}; log=${log//%a/$k}
        SLURM_ARRAY_TASK_ID=$k SLURM_CPUS_PER_TASK=1 bash "$script" > "$log" 2>&1 || true
    done
done
echo "$id"
"#;
    for (name, text) in [("sbatch", sbatch), ("squeue", "#!/bin/sh\nexit 0\n")] {
        let path = bin.join(name);
        std::fs::write(&path, text).unwrap();
        #[cfg(unix)]
        std::fs::set_permissions(&path, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    }
    bin
}

#[test]
fn farm_renders_every_tile_then_only_the_missing_ones() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bin = fake_slurm(d);
    let log = d.join("submissions");
    let log_s = log.display().to_string();
    let s = scene();
    render(d, &["-o", "one.png"]);
    let mut farm: Vec<&str> = vec!["farm", "slurm", &s, "--tiles", "5", "-o", "out.png", "--poll", "0.05"];
    farm.extend(SIZE);

    let e =
        failure(englobe_env(d, &[farm.as_slice(), &["--resume"]].concat(), Some(&bin), &[("FAKE_SLURM_LOG", &log_s)]));
    assert!(e.contains("no earlier run to resume"), "{e}");

    let e = failure(englobe_env(d, &farm, Some(&bin), &[("FAKE_SLURM_LOG", &log_s), ("FAKE_SKIP", "3")]));
    assert!(e.contains("1 of 5 tiles missing") && e.contains("tile 3/5"), "{e}");
    assert!(e.contains("run the same command again"), "{e}");
    assert!(!d.join("out.png").exists());

    let o = ok(englobe_env(d, &[farm.as_slice(), &["--resume"]].concat(), Some(&bin), &[("FAKE_SLURM_LOG", &log_s)]));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("submitted job 102: 1 of 5 tiles (3)"), "{text}");
    assert!(text.contains("wrote out.png (48x36 from 5 tiles"), "{text}");
    assert_eq!(std::fs::read(d.join("out.png")).unwrap(), std::fs::read(d.join("one.png")).unwrap());
    let submissions = std::fs::read_to_string(&log).unwrap();
    let arrays: Vec<&str> =
        submissions.lines().map(|l| l.split_whitespace().find(|a| a.starts_with("--array=")).unwrap()).collect();
    assert_eq!(arrays, ["--array=0-4", "--array=3"]);
    assert!(submissions.contains("--requeue") && submissions.contains("--cpus-per-task=1"));

    // Run again, nothing is submitted; with other options, the folder's tiles are another render's.
    ok(englobe_env(d, &farm, Some(&bin), &[("FAKE_SLURM_LOG", &log_s)]));
    assert_eq!(std::fs::read_to_string(&log).unwrap().lines().count(), 2);
    let e = failure(englobe_env(
        d,
        &[farm.as_slice(), &["--integrator", "whitted"]].concat(),
        Some(&bin),
        &[("FAKE_SLURM_LOG", &log_s)],
    ));
    assert!(e.contains("tile-0000.exr: a tile of another render"), "{e}");

    // Cut by cost, in a folder of its own: the tasks are told to cut the same way.
    let o = ok(englobe_env(
        d,
        &[&farm[..6], &["balanced.png", "--balance", "cost", "--tiles-dir", "balanced"], &farm[7..]].concat(),
        Some(&bin),
        &[("FAKE_SLURM_LOG", &log_s)],
    ));
    assert!(String::from_utf8_lossy(&o.stdout).contains("wrote balanced.png"));
    assert!(std::fs::read_to_string(d.join("balanced/job.sbatch")).unwrap().contains("--balance cost"));
    assert_eq!(std::fs::read(d.join("balanced.png")).unwrap(), std::fs::read(d.join("one.png")).unwrap());
}

#[test]
fn farm_waits_for_an_earlier_job_still_queued_before_submitting() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bin = fake_slurm(d);
    // An earlier run's job 77 still shows a running task for the first three looks at the queue:
    // its tile appears meanwhile, so only the others are submitted once it is gone.
    let squeue = r#"#!/bin/bash
n=$(cat "$FAKE_SQUEUE_COUNT" 2>/dev/null || echo 0)
echo $((n + 1)) > "$FAKE_SQUEUE_COUNT"
case "$*" in *77*) ;; *) exit 0 ;; esac
if [ "$n" -lt 3 ]; then echo "77_1 RUNNING"; else exit 0; fi
"#;
    std::fs::write(bin.join("squeue"), squeue).unwrap();
    let log = d.join("submissions");
    let count = d.join("looks");
    let s = scene();
    let mut farm: Vec<&str> = vec!["farm", "slurm", &s, "--tiles", "3", "-o", "out.png", "--poll", "0.05"];
    farm.extend(SIZE);
    std::fs::create_dir_all(d.join("out.png.tiles")).unwrap();
    std::fs::write(d.join("out.png.tiles/jobs"), "77\n").unwrap();
    render(d, &["--tile", "1/3", "-o", "out.png.tiles/tile-0001.exr"]);
    let env = [("FAKE_SLURM_LOG", log.to_str().unwrap()), ("FAKE_SQUEUE_COUNT", count.to_str().unwrap())];
    let o = ok(englobe_env(d, &[farm.as_slice(), &["--resume"]].concat(), Some(&bin), &env));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("waiting for the tasks still queued from job 77"), "{text}");
    assert!(text.contains("submitted job 101: 2 of 3 tiles (0,2)"), "{text}");
    let looks: u32 = std::fs::read_to_string(&count).unwrap().trim().parse().unwrap();
    assert!(looks >= 4, "the queue was looked at until job 77 was gone ({looks} looks)");
    render(d, &["-o", "one.png"]);
    assert_eq!(std::fs::read(d.join("out.png")).unwrap(), std::fs::read(d.join("one.png")).unwrap());
}

#[test]
fn farm_passes_scene_overrides_and_the_scale_to_its_tasks() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bin = fake_slurm(d);
    let log_s = d.join("submissions").display().to_string();
    let s = scene();
    let set = ["-D", "camera.fov=30", "--set", "image.max_depth=2", "--scale", "0.5"];
    render(d, &[&["-o", "one.png"][..], &set].concat());
    render(d, &["-o", "plain.png", "--scale", "0.5"]);
    let mut farm: Vec<&str> = vec!["farm", "slurm", &s, "--tiles", "3", "-o", "out.png", "--poll", "0.05"];
    farm.extend(SIZE);
    farm.extend(set);
    let o = ok(englobe_env(d, &farm, Some(&bin), &[("FAKE_SLURM_LOG", &log_s)]));
    assert!(String::from_utf8_lossy(&o.stdout).contains("wrote out.png (24x18 from 3 tiles"));
    let out = std::fs::read(d.join("out.png")).unwrap();
    assert_eq!(out, std::fs::read(d.join("one.png")).unwrap(), "the tasks rendered with the overrides");
    assert_ne!(out, std::fs::read(d.join("plain.png")).unwrap());
}

#[test]
fn exposure_and_tone_map_apply_at_assembly_and_the_clamp_enters_the_digest() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let look = ["--exposure", "1.5", "--tonemap", "filmic"];
    render(d, &[&look[..], &["-o", "one.png"]].concat());
    render(d, &["-o", "plain.png"]);
    assert_ne!(std::fs::read(d.join("one.png")).unwrap(), std::fs::read(d.join("plain.png")).unwrap());
    // Tiles rendered with the look record it, and assembly applies it.
    let t: Vec<String> = (0..3)
        .map(|k| {
            let name = format!("look{k}.exr");
            render(d, &[&look[..], &["--tile", &format!("{k}/3"), "-o", &name]].concat());
            name
        })
        .collect();
    ok(assemble(d, &t, "assembled.png"));
    assert_eq!(std::fs::read(d.join("assembled.png")).unwrap(), std::fs::read(d.join("one.png")).unwrap());
    // The look changes no linear pixel: tiles rendered without it are of the same render, and the
    // command line chooses how to write them.
    let plain = tiles(d, 3);
    let mut mixed = vec![t[0].clone(), plain[1].clone(), plain[2].clone()];
    assert!(failure(assemble(d, &mixed, "x.png")).contains("different output settings"));
    let mut args = vec!["assemble", "-o", "chosen.png", "--exposure", "1.5", "--tonemap", "filmic"];
    args.extend(mixed.iter().map(String::as_str));
    ok(englobe(d, &args));
    assert_eq!(std::fs::read(d.join("chosen.png")).unwrap(), std::fs::read(d.join("one.png")).unwrap());
    // A clamp changes pixels: its tiles are another render's.
    render(d, &["-D", "image.clamp=0.5", "--tile", "0/3", "-o", "clamped.exr"]);
    mixed[0] = "clamped.exr".into();
    assert!(failure(assemble(d, &mixed, "x.png")).contains("different renders"));
    // Half floats: a smaller EXR of the same image, within half precision.
    render(d, &["--half", "-o", "half.exr"]);
    render(d, &["-o", "full.exr"]);
    let (half, full) =
        (image::open(d.join("half.exr")).unwrap().to_rgb32f(), image::open(d.join("full.exr")).unwrap().to_rgb32f());
    for (h, f) in half.pixels().zip(full.pixels()) {
        for (a, b) in h.0.into_iter().zip(f.0) {
            assert!((a - b).abs() <= b.abs() * 2f32.powi(-11) + 1e-7, "{a} against {b}");
        }
    }
}
