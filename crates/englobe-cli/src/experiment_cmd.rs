//! `englobe experiment seed`: the seed report's four tests with every accelerator, beside the
//! report's figures (see `englobe_lab::seed_experiment`); `englobe experiment fewer-rays`: the
//! report's other family of speed-ups, measured (see `englobe_lab::fewer_rays`); `englobe
//! experiment samplers`: the pixel samplers' errors (see `englobe_lab::samplers`). This file parses
//! the arguments and prints what the experiments return.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::{Args, ValueEnum};
use englobe::AccelKind;
use englobe_lab::html_report::{render_seed_pictures, write_seed_report};
use englobe_lab::{FewerRaysOptions, SamplerOptions, SeedOptions, run_fewer_rays, run_samplers, run_seed};

use crate::image_options::parse_accel;

/// The experiments `englobe experiment` runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Experiment {
    /// The seed report's four tests.
    Seed,
    /// Fewer rays: adaptive depth at several thresholds against full depth, and adaptive
    /// supersampling against uniform supersampling, on the seed's scenes, the glass, mirrors and
    /// Sponza scenes; adaptive sampling against uniform sampling on the path-traced Cornell box
    /// (or the SCENEs given): rays per kind, exact tests, time, the image's difference (RMSE,
    /// SSIM), and the samples uniform sampling needs for adaptive sampling's error.
    FewerRays,
    /// The pixel samplers: the mean squared error of independent and Owen-scrambled Sobol
    /// samples at 4, 16, 64 and 256 spp against a 4096-spp reference, on the path-traced Cornell
    /// box (or the SCENE given), with each error's log-log slope against the samples.
    Samplers,
}

#[derive(Args)]
pub struct ExperimentArgs {
    /// Which experiment.
    #[arg(value_enum)]
    experiment: Experiment,
    /// fewer-rays: the scene files (default: the seed's four tests, glass, mirrors, Sponza, the
    /// path-traced Cornell box and the textured ground, from the repository's `scenes/`).
    scenes: Vec<PathBuf>,
    /// fewer-rays: the adaptive-depth thresholds, comma-separated (default 0.1,0.03,0.01,0.003).
    #[arg(long, value_delimiter = ',')]
    thresholds: Vec<f32>,
    /// fewer-rays: the noise thresholds of adaptive sampling on path-traced scenes,
    /// comma-separated (default 0.05,0.03,0.02,0.01).
    #[arg(long, value_delimiter = ',')]
    noise_thresholds: Vec<f32>,
    /// fewer-rays: the longer side of path-traced scenes' images (default 128).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=16384))]
    path_size: Option<u32>,
    /// fewer-rays: samples per pixel of path-traced scenes' reference, and adaptive sampling's
    /// maximum (default 4096; the uniform renders take 16, 32, ... up to a quarter of it).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(32..=65536))]
    reference_spp: Option<u32>,
    /// Image width and height in pixels (default: the scenes' own, 512, like the report's); for
    /// fewer-rays, the longer side (default 320).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    size: Option<u32>,
    /// Only these tests (1 to 4), comma-separated (default: all).
    #[arg(long, value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..=4))]
    tests: Vec<u32>,
    /// Only these accelerators, comma-separated (default: all); brute force (none) always runs,
    /// as the reference.
    #[arg(long, value_delimiter = ',', value_parser = parse_accel)]
    accel: Vec<AccelKind>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    threads: Option<u32>,
    /// Also write the table as JSON to this file.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Write every image rendered into this folder, as testN-ACCEL.png.
    #[arg(long, value_name = "DIR")]
    images: Option<PathBuf>,
    /// seed: also write the experiment as one self-contained HTML page, DIR/index.html: the
    /// report's claims checked, and for each test its table beside the report's figures, its plot,
    /// the image and one cost heatmap per structure (no server, no network needed to open it).
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
    /// No progress lines on standard error.
    #[arg(short, long)]
    quiet: bool,
}

pub fn run(args: ExperimentArgs) -> anyhow::Result<ExitCode> {
    if args.experiment == Experiment::FewerRays {
        return fewer_rays(args);
    }
    if args.experiment == Experiment::Samplers {
        return samplers(args);
    }
    if let Some(dir) = &args.report {
        // Checked before the experiment runs, so that it never ends in "cannot write".
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    anyhow::ensure!(
        args.scenes.is_empty()
            && args.thresholds.is_empty()
            && args.noise_thresholds.is_empty()
            && args.path_size.is_none()
            && args.reference_spp.is_none(),
        "scenes, --thresholds, --noise-thresholds, --path-size and --reference-spp are for fewer-rays"
    );
    let options = SeedOptions {
        size: args.size,
        tests: args.tests,
        accel: args.accel,
        threads: args.threads,
        images: args.images,
    };
    let quiet = args.quiet;
    let experiment = run_seed(&options, &mut |line: &str| {
        if !quiet {
            eprintln!("{line}");
        }
    })?;
    print!("{}", experiment.table());
    print!("{}", experiment.claims());
    if let Some(path) = &args.json {
        experiment.write_json(path)?;
    }
    if let Some(dir) = &args.report {
        if !quiet {
            eprintln!("rendering the pictures of the report...");
        }
        let pictures = render_seed_pictures(&experiment)?;
        let page = write_seed_report(dir, &experiment, &pictures)?;
        println!("wrote {}", page.display());
    }
    if !experiment.images_identical() {
        eprintln!("error: some accelerators drew a different image than brute force (see the image column)");
        return Ok(ExitCode::from(2));
    }
    Ok(ExitCode::SUCCESS)
}

fn samplers(args: ExperimentArgs) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(
        args.scenes.len() <= 1
            && args.report.is_none()
            && args.thresholds.is_empty()
            && args.noise_thresholds.is_empty()
            && args.tests.is_empty()
            && args.accel.is_empty()
            && args.images.is_none(),
        "samplers takes one SCENE, --path-size, --reference-spp, --threads and --json"
    );
    let mut options = SamplerOptions { threads: args.threads, ..SamplerOptions::default() };
    if let Some(scene) = args.scenes.first() {
        options.scene = scene.clone();
    }
    if let Some(size) = args.path_size {
        options.size = size;
    }
    if let Some(spp) = args.reference_spp {
        options.reference_spp = spp;
    }
    let quiet = args.quiet;
    let experiment = run_samplers(&options, &mut progress(quiet))?;
    print!("{}", experiment.table());
    if let Some(path) = &args.json {
        englobe_lab::report::write_json(path, &experiment)?;
    }
    Ok(ExitCode::SUCCESS)
}

fn fewer_rays(args: ExperimentArgs) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(args.report.is_none(), "--report is for the seed experiment");
    let mut options = FewerRaysOptions { threads: args.threads, ..FewerRaysOptions::default() };
    if !args.scenes.is_empty() {
        options.scenes = args.scenes;
    }
    if let Some(size) = args.size {
        options.size = size;
    }
    if !args.thresholds.is_empty() {
        anyhow::ensure!(args.thresholds.iter().all(|t| (0.0..=1.0).contains(t)), "--thresholds: each between 0 and 1");
        options.thresholds = args.thresholds;
    }
    if !args.noise_thresholds.is_empty() {
        anyhow::ensure!(
            args.noise_thresholds.iter().all(|t| t.is_finite() && *t > 0.0),
            "--noise-thresholds: each greater than 0"
        );
        options.noise_thresholds = args.noise_thresholds;
    }
    options.path_size = args.path_size.unwrap_or(options.path_size);
    options.reference_samples = args.reference_spp.unwrap_or(options.reference_samples);
    let quiet = args.quiet;
    let experiment = run_fewer_rays(&options, &mut progress(quiet))?;
    print!("{}", experiment.table());
    if let Some(path) = &args.json {
        englobe_lab::report::write_json(path, &experiment)?;
    }
    Ok(ExitCode::SUCCESS)
}

/// The experiments' progress lines, on standard error unless `quiet`.
fn progress(quiet: bool) -> impl FnMut(String) {
    move |line| {
        if !quiet {
            eprintln!("{line}");
        }
    }
}
