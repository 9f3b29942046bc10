//! `englobe render`: one scene to one image, with optional statistics, or one piece of an image
//! (`--tile K/N`, `--pixel-bounds`) written as an OpenEXR tile for `englobe assemble`.

use std::io::Read;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::{Args, ValueEnum};
use englobe_lab::memory::peak_rss_bytes;
use englobe_lab::report::{StatsReport, stats_table, write_json};
use englobe_render::adaptive::AdaptiveSampling;
use englobe_render::tile::file::{TileHeader, VERSION, write_tile};
use englobe_render::{HeatmapScale, PixelWindow, Renderer, TileSpec, build_world, write_cost_image, write_image_with};
use englobe_scene::framing::{framing_scene, turntable_position};
use englobe_scene::mesh::MeshFormat;
use englobe_scene::{LoadObserver, Override, Scene, Unobserved, load_scene_observed, parse_scene_with};

use crate::image_options::{Balance, ImageOptions, render_digest};
use crate::interrupt;
use crate::progress::{MeshPhases, Phases, progress_bar, tile_bar};

#[derive(Args, Clone)]
pub struct RenderArgs {
    /// Scene file (TOML, see docs/scene-format.md, or pbrt-v4 .pbrt, see docs/pbrt.md), `-` for
    /// standard input, or a mesh file (.obj, .ply, .gltf, .glb) to see it framed (camera, ground, lights: the scene `englobe scene MESH`
    /// prints); the embedded default scene if omitted.
    scene: Option<PathBuf>,
    /// Output image (.png or .exr); defaults to the scene's name with .png, in the current folder
    /// (with --tile or --pixel-bounds: an .exr tile, named after the scene and the tile).
    #[arg(short, long)]
    output: Option<PathBuf>,
    #[command(flatten)]
    image: ImageOptions,
    /// Render only tile K of N (from 0): the K-th of N horizontal strips, written as an OpenEXR
    /// tile for `englobe assemble`.
    #[arg(long, value_name = "K/N", conflicts_with = "pixel_bounds")]
    tile: Option<TileSpec>,
    /// How --tile cuts the image: strips of equal height (area) or of equal predicted cost (cost).
    #[arg(long, value_enum, default_value_t = Balance::Area, requires = "tile")]
    balance: Balance,
    /// Render only columns X0..X1 and rows Y0..Y1 (half-open), written as an OpenEXR tile.
    #[arg(long, value_name = "X0,X1,Y0,Y1")]
    pixel_bounds: Option<PixelWindow>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    threads: Option<u32>,
    /// What the image shows: the shaded scene (color), or the structure's work per pixel (cost:
    /// nodes visited plus exact tests, in false colour with a colour bar; raw counts in .exr).
    #[arg(long, value_enum, default_value_t = Aov::Color)]
    aov: Aov,
    /// Cost drawn brightest with --aov cost (default: the image's largest), so that heatmaps of
    /// several structures can share one scale.
    #[arg(long, value_name = "N")]
    cost_max: Option<u64>,
    /// Scale of the cost heatmap.
    #[arg(long, value_enum, default_value_t = CostScale::Log)]
    cost_scale: CostScale,
    /// Print rays cast and exact intersection tests per kind of ray.
    #[arg(long)]
    stats: bool,
    /// Write the statistics as JSON to this file.
    #[arg(long, value_name = "FILE")]
    stats_json: Option<PathBuf>,
    /// With a noise threshold (--noise-threshold, image.noise_threshold), also write the samples
    /// each pixel took: a heatmap on a linear scale up to the most taken, with its colour bar
    /// (.png), or the raw counts (.exr).
    #[arg(long, value_name = "FILE")]
    samples_map: Option<PathBuf>,
    /// Stop at the last complete sample pass once this much time has passed since the command
    /// started (30s, 2m, 1.5h; a bare number is seconds) and write that image, saying so. Renders
    /// pass by pass (every pixel's first sample, then every pixel's second...), which gives the
    /// same image when it finishes.
    #[arg(long, value_name = "DURATION", value_parser = parse_duration,
          conflicts_with_all = ["tile", "pixel_bounds"])]
    time_limit: Option<Duration>,
    /// On Ctrl-C, write the image of the sample passes completed (instead of nothing), saying so;
    /// renders pass by pass as --time-limit does.
    #[arg(long, conflicts_with_all = ["tile", "pixel_bounds"])]
    keep_partial: bool,
    /// Render N frames with the camera turning once around the vertical axis through the point
    /// it looks at, written as OUT-000.png, OUT-001.png...
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=10000),
          conflicts_with_all = ["tile", "pixel_bounds"])]
    turntable: Option<u32>,
    /// No progress bar and no summary line.
    #[arg(short, long)]
    quiet: bool,
    /// For a pbrt scene: refuse it, at the first thing englobe would skip or approximate, instead
    /// of rendering it with warnings.
    #[arg(long)]
    strict: bool,
}

/// What `englobe render` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Aov {
    /// The shaded image.
    Color,
    /// Work per pixel: nodes visited plus exact tests.
    Cost,
}

/// Scale of the cost heatmap.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CostScale {
    /// ln(1 + cost) / ln(1 + max).
    Log,
    /// cost / max.
    Linear,
}

/// The scene of the command line (`-` reads it from standard input, a mesh file is framed, see
/// `englobe_scene::framing`, a `.pbrt` file is read as a pbrt-v4 scene, `strict` or not), or the
/// embedded default, with `overrides` applied (refused for pbrt scenes), and its display name.
pub fn read_scene(path: Option<&PathBuf>, overrides: &[Override], strict: bool) -> anyhow::Result<(Scene, String)> {
    read_scene_observed(path, overrides, strict, &Unobserved)
}

/// [`read_scene`], telling `observer` when each mesh file of a scene file starts and ends loading.
pub fn read_scene_observed(
    path: Option<&PathBuf>,
    overrides: &[Override],
    strict: bool,
    observer: &dyn LoadObserver,
) -> anyhow::Result<(Scene, String)> {
    match path {
        Some(p) if englobe_scene::pbrt::is_pbrt_path(p) => {
            englobe_scene::pbrt::refuse_overrides(overrides)?;
            Ok((englobe_scene::pbrt::load(p, strict)?, p.display().to_string()))
        }
        Some(p) if MeshFormat::from_path(p).is_some() => {
            let text = framing_scene(p)?;
            // Named without a folder, so that the mesh path in the text, as given, is read from
            // the current folder, as it will be from a scene printed by `englobe scene` there.
            let name = format!("{} (framed)", p.file_name().unwrap_or(p.as_os_str()).to_string_lossy());
            Ok((parse_scene_with(&text, name.as_ref(), overrides)?, p.display().to_string()))
        }
        Some(p) if p.as_os_str() == "-" => {
            let text = read_stdin()?;
            Ok((parse_scene_with(&text, STDIN_NAME.as_ref(), overrides)?, STDIN_NAME.to_owned()))
        }
        Some(p) => Ok((load_scene_observed(p, overrides, observer)?, p.display().to_string())),
        None => Ok((
            parse_scene_with(englobe_render::DEFAULT_SCENE, "default.toml".as_ref(), overrides)?,
            "default".to_owned(),
        )),
    }
}

/// How a scene read from standard input is named in messages; its mesh paths are relative to the
/// current folder.
const STDIN_NAME: &str = "<stdin>";

fn read_stdin() -> anyhow::Result<String> {
    let limit = englobe_scene::parse::MAX_SCENE_BYTES;
    let mut bytes = Vec::new();
    std::io::stdin()
        .lock()
        .take(limit + 1)
        .read_to_end(&mut bytes)
        .with_context(|| format!("{STDIN_NAME}: cannot read the scene"))?;
    anyhow::ensure!(bytes.len() as u64 <= limit, "{STDIN_NAME}: the scene is larger than the {limit}-byte limit");
    String::from_utf8(bytes).map_err(|e| {
        anyhow::anyhow!("{STDIN_NAME}: byte {}: the scene is not valid UTF-8", e.utf8_error().valid_up_to())
    })
}

pub fn run(args: RenderArgs) -> anyhow::Result<ExitCode> {
    let interrupted = interrupt::install()?;
    let Some(frames) = args.turntable else { return render(&args, interrupted) };
    anyhow::ensure!(
        !args.scene.as_ref().is_some_and(|p| englobe_scene::pbrt::is_pbrt_path(p)),
        "--turntable moves the camera through a scene override (-D camera.position), which pbrt scenes do not take"
    );
    // The camera of the scene as it will be rendered, then one render per frame with its position.
    let (scene, _) = read_scene(args.scene.as_ref(), &args.image.overrides(), args.strict)?;
    let (position, look_at) = (scene.camera.position, scene.camera.look_at);
    let output = args.output.clone().unwrap_or_else(|| PathBuf::from(format!("{}.png", scene_stem(&args))));
    let stem = output.with_extension("");
    let ext = output.extension().map_or("png".into(), |e| e.to_string_lossy().into_owned());
    for k in 0..frames {
        let p = turntable_position(position, look_at, k, frames);
        let mut frame = args.clone();
        frame.turntable = None;
        frame.output = Some(PathBuf::from(format!("{}-{k:03}.{ext}", stem.display())));
        frame.image.set.push(Override { key: "camera.position".into(), value: format!("[{}, {}, {}]", p.x, p.y, p.z) });
        let code = render(&frame, interrupted)?;
        if code != ExitCode::SUCCESS {
            return Ok(code);
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The scene's file name without its extension, or `englobe` for the default scene and standard
/// input: what output files are named after.
fn scene_stem(args: &RenderArgs) -> String {
    args.scene
        .as_ref()
        .filter(|p| p.as_os_str() != "-")
        .and_then(|p| p.file_stem())
        .map_or("englobe".into(), |s| s.to_string_lossy().into_owned())
}

fn render(args: &RenderArgs, interrupted: &'static std::sync::atomic::AtomicBool) -> anyhow::Result<ExitCode> {
    let wall = Instant::now();
    // The destination is checked first, before the scene and its meshes are read: a long render
    // must not end in "cannot write".
    let stem = scene_stem(args);
    let output = args.output.clone().unwrap_or_else(|| match (args.tile, args.pixel_bounds) {
        (Some(tile), _) => PathBuf::from(format!("{stem}.tile-{}-of-{}.exr", tile.index, tile.count)),
        (None, Some(w)) => PathBuf::from(format!("{stem}.window-{}-{}-{}-{}.exr", w.x0, w.x1, w.y0, w.y1)),
        (None, None) => PathBuf::from(stem).with_extension("png"),
    });
    let format = englobe_render::output::check_writable(&output)?;
    if let Some(path) = &args.stats_json {
        englobe_render::output::check_file_writable(path)?;
    }
    if let Some(path) = &args.samples_map {
        englobe_render::output::check_writable(path)?;
    }
    if args.tile.is_some() || args.pixel_bounds.is_some() {
        anyhow::ensure!(
            format == englobe_render::OutputFormat::Exr,
            "{}: a tile is written as OpenEXR (.exr), so that `englobe assemble` gets the exact values",
            output.display()
        );
        anyhow::ensure!(
            args.aov == Aov::Color,
            "--aov cost cannot be tiled: its colour scale depends on the whole image"
        );
    }

    anyhow::ensure!(
        args.aov == Aov::Color || (args.time_limit.is_none() && !args.keep_partial),
        "--aov cost is not rendered by passes, so it cannot take --time-limit or --keep-partial"
    );
    let phases = Phases::new(args.quiet);
    let shown_name = args.scene.as_ref().map_or("the default scene".into(), |p| p.display().to_string());
    let phase = phases.begin(&format!("loading {shown_name}"));
    let meshes = MeshPhases::new(&phases, &phase);
    let (mut scene, scene_name) =
        read_scene_observed(args.scene.as_ref(), &args.image.overrides(), args.strict, &meshes)?;
    let mesh_files = meshes.count();
    let load_seconds = phases.end(phase, |s| {
        let triangles: usize = scene.objects.iter().map(|o| o.object.triangle_count()).sum();
        let files = if mesh_files > 0 { format!(" from {mesh_files} mesh file(s)") } else { String::new() };
        format!(
            "loaded {shown_name} in {s:.2} s: {} objects ({triangles} triangles in the picture{files}), {} lights",
            scene.objects.len(),
            scene.lights.len()
        )
    });
    if !args.quiet {
        for w in &scene.warnings {
            eprintln!("warning: {w}");
        }
    }
    args.image.apply(&mut scene)?;
    let accel = args.image.accel;
    let (width, height, samples, integrator) =
        (scene.image.width, scene.image.height, scene.image.samples, scene.image.integrator);
    let adaptive = AdaptiveSampling::of(&scene.image, samples);
    if let (Some(path), None) = (&args.samples_map, adaptive) {
        anyhow::bail!(
            "{}: every pixel takes {samples} sample(s) without a noise threshold; set --noise-threshold (and more \
             than one sample) for a map of samples",
            path.display()
        );
    }
    let piece = match (args.tile, args.pixel_bounds) {
        (Some(tile), _) => Some((tile.window(width, height).map_err(anyhow::Error::msg)?, Some(tile))),
        (None, Some(window)) => {
            window.check_inside(width, height).map_err(anyhow::Error::msg)?;
            Some((window, None))
        }
        (None, None) => None,
    };

    let phase = phases.begin(&format!("building {accel}"));
    let world = build_world(&scene, accel).context("cannot build the acceleration structure")?;
    let build_seconds =
        phases.end(phase, |s| format!("built {accel} in {s:.2} s over {} triangles", world.triangle_count()));

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.map_or(0, |t| t as usize))
        .build()
        .context("cannot start the worker threads")?;
    let count_work = args.stats || args.stats_json.is_some();
    let piece = match piece {
        Some((_, Some(tile))) if args.balance == Balance::Cost => {
            let costs = pool.install(|| englobe_render::tile::balance::predict_row_costs(&scene, &world))?;
            Some((tile.balanced_window(width, &costs).map_err(anyhow::Error::msg)?, Some(tile)))
        }
        other => other,
    };
    let window = piece.map_or(PixelWindow::full(width, height), |(w, _)| w);
    let tiles = window.width().div_ceil(englobe_render::render::TILE_SIZE) as usize
        * window.height().div_ceil(englobe_render::render::TILE_SIZE) as usize;
    let by_passes = args.time_limit.is_some() || args.keep_partial;
    let bar = match (adaptive, by_passes) {
        (Some(_), _) => progress_bar(samples as usize, "samples", args.quiet),
        (None, true) => progress_bar(samples as usize, "passes", args.quiet),
        (None, false) => tile_bar(tiles, args.quiet),
    };
    let progress = |done: usize, _total: usize| bar.set_position(done as u64);
    let out = pool.install(|| {
        let renderer = Renderer::new(&scene, &world)
            .window(window)
            .count_work(count_work)
            .record_cost(args.aov == Aov::Cost)
            .on_progress(&progress)
            .cancel_flag(interrupted);
        if by_passes { renderer.render_passes(args.time_limit.map(|t| wall + t)) } else { renderer.render() }
    })?;
    bar.finish_and_clear();
    let ctrl_c = interrupted.load(std::sync::atomic::Ordering::Relaxed);
    let mut exit = ExitCode::SUCCESS;
    if !out.complete && !by_passes && adaptive.is_some() {
        eprintln!(
            "interrupted: stopped at {} of at most {samples} samples per pixel; no image written ({} left as it was)",
            out.samples_done,
            output.display()
        );
        return Ok(ExitCode::from(interrupt::INTERRUPTED_EXIT_CODE));
    }
    if !out.complete && !by_passes {
        eprintln!(
            "interrupted: stopped after {} of {tiles} tiles; no image written ({} left as it was)",
            out.tiles_done,
            output.display()
        );
        return Ok(ExitCode::from(interrupt::INTERRUPTED_EXIT_CODE));
    }
    if !out.complete {
        let done = out.samples_done;
        let why = if ctrl_c {
            "interrupted".to_owned()
        } else {
            format!("time limit of {} reached", show_duration(args.time_limit.unwrap_or_default()))
        };
        let stopped = if adaptive.is_some() {
            format!("stopped at {done} of at most {samples} samples per pixel")
        } else {
            format!("stopped after {done} of {samples} sample passes")
        };
        if done == 0 || (ctrl_c && !args.keep_partial) {
            eprintln!("{why}: {stopped}; no image written ({} left as it was)", output.display());
            let code = if ctrl_c { interrupt::INTERRUPTED_EXIT_CODE } else { 1 };
            return Ok(ExitCode::from(code));
        }
        if adaptive.is_some() {
            eprintln!(
                "{why}: {stopped}; writing the image of the passes complete (each pixel the mean of its samples)"
            );
        } else {
            eprintln!("{why}: {stopped}; writing the image of the {done} complete");
        }
        if ctrl_c {
            exit = ExitCode::from(interrupt::INTERRUPTED_EXIT_CODE);
        }
    }
    let samples = out.samples_done;
    let rendered_pixels = out.window.area().max(1);
    let samples_total = out.samples_map.as_ref().map_or(samples as u64 * rendered_pixels, |m| m.total());
    let samples_mean = samples_total as f64 / rendered_pixels as f64;
    if let (Some(path), Some(map)) = (&args.samples_map, &out.samples_map) {
        write_cost_image(map, path, HeatmapScale::linear(map.max()))?;
    }
    let spp = match adaptive {
        Some(a) => format!("adaptive {samples_mean:.1} spp of at most {}, threshold {}", a.max_samples, a.threshold),
        None => format!("{samples} spp"),
    };

    if let Some((window, tile)) = piece {
        let header = TileHeader {
            full_width: width,
            full_height: height,
            window,
            scene_digest: render_digest(&scene, accel, args.balance),
            version: VERSION.to_owned(),
            tile,
            output: scene.image.output,
        };
        write_tile(&output, &header, &out.film)?;
    }
    let scale = match &out.cost {
        _ if piece.is_some() => None,
        Some(cost) => {
            let max = args.cost_max.unwrap_or_else(|| cost.max());
            let scale = match args.cost_scale {
                CostScale::Log => HeatmapScale::log(max),
                CostScale::Linear => HeatmapScale::linear(max),
            };
            Some(write_cost_image(cost, &output, scale)?)
        }
        None => {
            write_image_with(&out.film, &output, &scene.image.output)?;
            None
        }
    };
    if !args.quiet {
        if let Some(scale) = scale {
            println!("{}", scale.describe());
        }
        let what = match piece {
            Some((w, Some(tile))) => format!("tile {tile}, pixels {w} of {width}x{height}"),
            Some((w, None)) => format!("pixels {w} of {width}x{height}"),
            None => format!("{width}x{height}"),
        };
        println!(
            "wrote {} ({what}, {spp}, {}, accel {}, {:.2} s on {} threads: load {load_seconds:.2} s, \
             build {build_seconds:.2} s, render {:.2} s)",
            output.display(),
            integrator.name(),
            accel,
            wall.elapsed().as_secs_f64(),
            pool.current_num_threads(),
            out.seconds,
        );
    }
    let peak_memory_bytes = peak_rss_bytes();
    if args.stats {
        print!("{}", stats_table(&out.stats));
        match (&out.samples_map, adaptive) {
            (Some(map), Some(a)) => println!(
                "samples: {samples_total} in all, {samples_mean:.2} per pixel on average ({} to {} per pixel; \
                 threshold {}, first pass {}, at most {})",
                map.values().iter().min().unwrap_or(&0),
                map.max(),
                a.threshold,
                a.min_samples,
                a.max_samples
            ),
            _ => println!("samples: {samples_total} in all, {samples} per pixel"),
        }
        println!("triangles: {} in the picture; build {build_seconds:.3} s", world.triangle_count());
        if let Some(bytes) = peak_memory_bytes {
            println!("peak memory: {:.1} MiB", bytes as f64 / (1 << 20) as f64);
        }
    }
    if let Some(path) = &args.stats_json {
        let report = StatsReport {
            scene: &scene_name,
            accel: accel.name(),
            width,
            height,
            samples,
            samples_total,
            samples_mean,
            noise_threshold: adaptive.map(|a| a.threshold),
            build_seconds,
            render_seconds: out.seconds,
            triangles: world.triangle_count(),
            peak_memory_bytes,
            kinds: StatsReport::rows(&out.stats),
            total: out.stats.total(),
        };
        write_json(path, &report)?;
    }
    Ok(exit)
}

/// A duration such as `30s`, `2m`, `1.5h` or `90` (seconds).
fn parse_duration(s: &str) -> Result<Duration, String> {
    let t = s.trim();
    let (number, unit) = match t.find(|c: char| c.is_ascii_alphabetic()) {
        Some(at) => t.split_at(at),
        None => (t, "s"),
    };
    let scale = match unit {
        "ms" => 0.001,
        "s" => 1.0,
        "m" | "min" => 60.0,
        "h" => 3600.0,
        _ => return Err(format!("`{s}`: unknown unit `{unit}`; expected a duration such as 30s, 2m or 1.5h")),
    };
    match number.trim().parse::<f64>() {
        Ok(x) if x > 0.0 && (x * scale) < 1e9 => Ok(Duration::from_secs_f64(x * scale)),
        _ => Err(format!("`{s}`: expected a positive duration such as 30s, 2m or 1.5h")),
    }
}

fn show_duration(d: Duration) -> String {
    format!("{} s", d.as_secs_f64())
}
