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

/// The binary's allocator. A build of a large structure writes tens of megabytes of vectors it
/// frees at the end; with glibc's malloc much of that memory goes back to the system between
/// builds, and the next build takes a page fault on every fresh 4 KiB page it writes, where
/// Embree (which manages its own memory) takes few. mimalloc keeps the memory for the next build
/// (docs/performance.md, "The build's memory", has the counts). The library allocates through
/// whatever allocator the program sets.
#[cfg(feature = "mimalloc")]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

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
