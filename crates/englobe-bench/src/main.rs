//! The `englobe-bench` command: englobe against Intel Embree, obvhs and bvh on the same rays (the
//! same as `englobe bench`).

use std::process::ExitCode;

use clap::Parser;
use englobe_bench::BenchArgs;

/// Measure englobe against Intel Embree, obvhs and bvh on the same rays.
#[derive(Parser)]
#[command(name = "englobe-bench", version, about, long_about = None)]
struct Cli {
    #[command(flatten)]
    args: BenchArgs,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match englobe_bench::run(&cli.args) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
