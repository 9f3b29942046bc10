//! `englobe experiment seed`: the seed report's four tests with every accelerator, beside the
//! report's figures (see `englobe_lab::seed_experiment`). This file parses the arguments and
//! prints what the experiment returns.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, ValueEnum};
use englobe::AccelKind;
use englobe_lab::{SeedOptions, run_seed};

use crate::image_options::parse_accel;

/// The experiments `englobe experiment` runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Experiment {
    /// The seed report's four tests.
    Seed,
}

#[derive(Args)]
pub struct ExperimentArgs {
    /// Which experiment.
    #[arg(value_enum)]
    experiment: Experiment,
    /// Image width and height in pixels (default: the scenes' own, 512, like the report's).
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
    /// No progress lines on standard error.
    #[arg(short, long)]
    quiet: bool,
}

pub fn run(args: ExperimentArgs) -> anyhow::Result<ExitCode> {
    let Experiment::Seed = args.experiment;
    let options = SeedOptions {
        size: args.size,
        tests: args.tests,
        accel: args.accel,
        threads: args.threads,
        images: args.images,
    };
    let quiet = args.quiet;
    let experiment = run_seed(&options, &mut |line| {
        if !quiet {
            eprintln!("{line}");
        }
    })?;
    print!("{}", experiment.table());
    print!("{}", experiment.claims());
    if let Some(path) = &args.json {
        experiment.write_json(path)?;
    }
    if !experiment.images_identical() {
        eprintln!("error: some accelerators drew a different image than brute force (see the image column)");
        return Ok(ExitCode::from(2));
    }
    Ok(ExitCode::SUCCESS)
}
