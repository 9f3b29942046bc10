//! `englobe bench`: the benchmark against Intel Embree, obvhs and bvh. Those libraries are
//! compiled into `englobe` only with the `bench` cargo feature (`embree` adds Embree); with it,
//! this forwards to `englobe_bench`. Without it, the command is still listed and says how to run
//! the benchmark: the `englobe-bench` binary, or `englobe` rebuilt with the feature.

#[cfg(feature = "bench")]
pub use englobe_bench::BenchArgs;

#[cfg(not(feature = "bench"))]
pub use without_bench::BenchArgs;

/// Runs the benchmark.
#[cfg(feature = "bench")]
pub fn run(args: BenchArgs) -> anyhow::Result<std::process::ExitCode> {
    englobe_bench::run(&args)
}

/// Says how to run the benchmark, which this build of `englobe` does not hold.
#[cfg(not(feature = "bench"))]
pub fn run(_args: BenchArgs) -> anyhow::Result<std::process::ExitCode> {
    eprintln!("{}", without_bench::HOW_TO_BENCH);
    Ok(std::process::ExitCode::from(2))
}

#[cfg(not(feature = "bench"))]
mod without_bench {
    use std::ffi::OsString;

    /// What `englobe bench` says when this build has no benchmark.
    pub const HOW_TO_BENCH: &str = "\
error: this englobe was built without the benchmark (the `bench` cargo feature), so that it does not \
compile Embree, obvhs and bvh. Run the benchmark's own binary instead:
    cargo run --release -p englobe-bench -- MESH...
(add `--features embree` to also measure Intel Embree), or rebuild englobe with it:
    cargo build --release -p englobe-cli --features bench";

    /// The benchmark's arguments, taken as they come: this build cannot run it.
    #[derive(clap::Args)]
    #[command(disable_help_flag = true)]
    pub struct BenchArgs {
        /// The benchmark's arguments (see `englobe-bench --help`).
        #[arg(trailing_var_arg = true, allow_hyphen_values = true, value_name = "ARGS")]
        _args: Vec<OsString>,
    }
}
