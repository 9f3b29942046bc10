//! `englobe render`: one scene to one image, with optional statistics.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use clap::{Args, ValueEnum};
use englobe::AccelKind;
use englobe_lab::memory::peak_rss_bytes;
use englobe_lab::report::{StatsReport, stats_table, write_json};
use englobe_render::{HeatmapScale, Renderer, build_world, write_cost_image, write_image};
use englobe_scene::{IntegratorKind, Scene, load_scene, parse_scene};

use crate::interrupt;
use crate::progress::tile_bar;

#[derive(Args)]
pub struct RenderArgs {
    /// Scene file (TOML, see docs/scene-format.md); the embedded default scene if omitted.
    scene: Option<PathBuf>,
    /// Output image (.png or .exr); defaults to the scene's name with .png, in the current folder.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Image width in pixels (overrides the scene).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene).
    #[arg(long)]
    height: Option<u32>,
    /// Samples per pixel (overrides the scene).
    #[arg(long)]
    spp: Option<u32>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    threads: Option<u32>,
    /// Acceleration structure: bvh-wide (the fast path, eight-wide at both levels), none (brute
    /// force), bvh-seed, bvh-seed-ordered, bvh-sah, bvh-ploc, bvh-sweep, kdtree, grid
    #[arg(long, default_value = "bvh-wide", value_parser = parse_accel)]
    accel: AccelKind,
    /// Light transport: whitted (the seed's recursion) or path (Monte Carlo path tracing);
    /// overrides the scene's `integrator`.
    #[arg(long, value_parser = parse_integrator)]
    integrator: Option<IntegratorKind>,
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
    /// No progress bar and no summary line.
    #[arg(short, long)]
    quiet: bool,
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

fn parse_integrator(s: &str) -> Result<IntegratorKind, String> {
    match s {
        "whitted" => Ok(IntegratorKind::Whitted),
        "path" => Ok(IntegratorKind::Path),
        _ => Err(format!("unknown integrator `{s}`; expected whitted or path")),
    }
}

pub fn parse_accel(s: &str) -> Result<AccelKind, String> {
    s.parse().map_err(|e: englobe::accel::UnknownAccel| e.to_string())
}

/// The scene of the command line, or the embedded default, with its display name.
pub fn read_scene(path: Option<&PathBuf>) -> anyhow::Result<(Scene, String)> {
    match path {
        Some(p) => Ok((load_scene(p)?, p.display().to_string())),
        None => Ok((parse_scene(englobe_render::DEFAULT_SCENE, "default.toml".as_ref())?, "default".to_owned())),
    }
}

pub fn run(args: RenderArgs) -> anyhow::Result<ExitCode> {
    let interrupted = interrupt::install()?;
    let (scene, scene_name) = read_scene(args.scene.as_ref())?;
    if !args.quiet {
        for w in &scene.warnings {
            eprintln!("warning: {w}");
        }
    }
    let width = args.width.unwrap_or(scene.image.width);
    let height = args.height.unwrap_or(scene.image.height);
    let samples = args.spp.unwrap_or(scene.image.samples);
    let integrator = args.integrator.unwrap_or(scene.image.integrator);
    let output = args.output.clone().unwrap_or_else(|| {
        let stem = args.scene.as_ref().and_then(|p| p.file_stem()).map_or("englobe".into(), |s| s.to_os_string());
        PathBuf::from(stem).with_extension("png")
    });
    englobe_render::OutputFormat::from_path(&output)?;

    let build_start = Instant::now();
    let world = build_world(&scene, args.accel).context("cannot build the acceleration structure")?;
    let build_seconds = build_start.elapsed().as_secs_f64();

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.map_or(0, |t| t as usize))
        .build()
        .context("cannot start the worker threads")?;
    let count_work = args.stats || args.stats_json.is_some();
    let tiles = width.div_ceil(englobe_render::render::TILE_SIZE) as usize
        * height.div_ceil(englobe_render::render::TILE_SIZE) as usize;
    let bar = tile_bar(tiles, args.quiet);
    let progress = |done: usize, _total: usize| bar.set_position(done as u64);
    let out = pool.install(|| {
        Renderer::new(&scene, &world)
            .size(width, height)
            .samples(samples)
            .integrator(integrator)
            .count_work(count_work)
            .record_cost(args.aov == Aov::Cost)
            .on_progress(&progress)
            .cancel_flag(interrupted)
            .render()
    })?;
    bar.finish_and_clear();
    if !out.complete {
        eprintln!(
            "interrupted: stopped after {} of {tiles} tiles; no image written ({} left as it was)",
            bar.position(),
            output.display()
        );
        return Ok(ExitCode::from(interrupt::INTERRUPTED_EXIT_CODE));
    }

    let scale = match &out.cost {
        Some(cost) => {
            let max = args.cost_max.unwrap_or_else(|| cost.max());
            let scale = match args.cost_scale {
                CostScale::Log => HeatmapScale::log(max),
                CostScale::Linear => HeatmapScale::linear(max),
            };
            Some(write_cost_image(cost, &output, scale)?)
        }
        None => {
            write_image(&out.film, &output)?;
            None
        }
    };
    if !args.quiet {
        if let Some(scale) = scale {
            println!("{}", scale.describe());
        }
        println!(
            "wrote {} ({width}x{height}, {samples} spp, {}, accel {}, {:.2} s on {} threads)",
            output.display(),
            integrator.name(),
            args.accel,
            out.seconds,
            pool.current_num_threads()
        );
    }
    let peak_memory_bytes = peak_rss_bytes();
    if args.stats {
        print!("{}", stats_table(&out.stats));
        println!("triangles: {} in the picture; build {build_seconds:.3} s", world.triangle_count());
        if let Some(bytes) = peak_memory_bytes {
            println!("peak memory: {:.1} MiB", bytes as f64 / (1 << 20) as f64);
        }
    }
    if let Some(path) = &args.stats_json {
        let report = StatsReport {
            scene: &scene_name,
            accel: args.accel.name(),
            width,
            height,
            samples,
            build_seconds,
            render_seconds: out.seconds,
            triangles: world.triangle_count(),
            peak_memory_bytes,
            kinds: StatsReport::rows(&out.stats),
            total: out.stats.total(),
        };
        write_json(path, &report)?;
    }
    Ok(ExitCode::SUCCESS)
}
