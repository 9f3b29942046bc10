//! `englobe compare SCENE`: every structure built for one scene and compared (build time, memory,
//! speed, work per ray, quality; see `englobe_lab::compare`). This file parses the arguments,
//! reads the scene and prints what the comparison returns.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use englobe::AccelKind;
use englobe_lab::html_report::{render_pictures, write_report};
use englobe_lab::{CompareOptions, run_compare};

use englobe_scene::Override;

use crate::image_options::{image_size, parse_accel, parse_scale};
use crate::render_cmd::read_scene;

#[derive(Args)]
pub struct CompareArgs {
    /// Scene file (TOML, see docs/scene-format.md); the embedded default scene if omitted.
    scene: Option<PathBuf>,
    /// Set any value of the scene by its dotted path, as a TOML value (repeatable), as in
    /// `englobe render`: `-D camera.fov=40`.
    #[arg(short = 'D', long = "set", value_name = "KEY=VALUE")]
    set: Vec<Override>,
    /// Image width in pixels (overrides the scene; alone, the height follows the scene's aspect
    /// ratio).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene; alone, the width follows the scene's aspect
    /// ratio).
    #[arg(long)]
    height: Option<u32>,
    /// Scale the image size by this factor, after --width and --height.
    #[arg(long, value_parser = parse_scale)]
    scale: Option<f64>,
    /// Samples per pixel (overrides the scene).
    #[arg(long)]
    spp: Option<u32>,
    /// Only these accelerators, comma-separated (default: all); brute force (none) always runs, as
    /// the reference.
    #[arg(long, value_delimiter = ',', value_parser = parse_accel)]
    accel: Vec<AccelKind>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    threads: Option<u32>,
    /// Seconds one render may take before the structure is measured on a sample of the pixels.
    #[arg(long, default_value_t = 10.0, value_name = "SECONDS")]
    budget: f64,
    /// Render every pixel with every structure, however long it takes.
    #[arg(long)]
    full: bool,
    /// Also write the table as JSON to this file.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Also draw rays per second and exact tests per ray of every structure into this SVG file.
    #[arg(long, value_name = "FILE.svg")]
    plot: Option<PathBuf>,
    /// Also write the comparison as one self-contained HTML page, DIR/index.html: the tables, the
    /// plot, the image and one cost heatmap per structure on one shared scale (no server, no
    /// network needed to open it).
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
    /// No progress lines on standard error.
    #[arg(short, long)]
    quiet: bool,
}

pub fn run(args: CompareArgs) -> anyhow::Result<ExitCode> {
    let (scene, scene_name) = read_scene(args.scene.as_ref(), &args.set, false)?;
    let (width, height) = image_size(&scene.image, args.width, args.height, args.scale);
    let options = CompareOptions {
        width: Some(width),
        height: Some(height),
        spp: args.spp,
        accel: args.accel,
        threads: args.threads,
        budget: args.budget,
        full: args.full,
    };
    let quiet = args.quiet;
    let comparison = run_compare(&scene, &scene_name, &options, &mut |line| {
        if !quiet {
            eprintln!("{line}");
        }
    })?;
    print!("{}", comparison.table());
    print!("{}", comparison.quality_table());
    if let Some(path) = &args.json {
        comparison.write_json(path)?;
    }
    if let Some(path) = &args.plot {
        comparison.write_plot(path)?;
    }
    if let Some(dir) = &args.report {
        if !quiet {
            eprintln!("rendering the pictures of the report...");
        }
        let pictures = render_pictures(&scene, &comparison)?;
        let page = write_report(dir, &comparison, &pictures)?;
        println!("wrote {}", page.display());
    }
    if !comparison.images_equal() {
        eprintln!("error: some structures drew a different image than brute force");
        return Ok(ExitCode::from(2));
    }
    Ok(ExitCode::SUCCESS)
}
