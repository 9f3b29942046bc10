//! The `englobe` command: render scenes, measure how acceleration structures cut the work of ray
//! tracing (the experiments and comparisons of englobe-lab), and benchmark englobe against other
//! libraries (`bench`, forwarded to englobe-bench when built with the `bench` feature). Each
//! command's file parses its arguments and calls the library crates.

mod assemble_cmd;
mod bench_cmd;
mod compare_cmd;
mod experiment_cmd;
mod farm_cmd;
mod image_options;
mod image_stats;
mod info_cmd;
mod interrupt;
mod progress;
mod render_cmd;
mod scene_cmd;
mod slurm;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// englobe: a ray tracer built around acceleration structures.
#[derive(Parser)]
#[command(name = "englobe", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file (or the embedded default scene, or a mesh file framed) to PNG or EXR,
    /// or one tile of it.
    Render(render_cmd::RenderArgs),
    /// Print the scene that frames a mesh file, the one `render MESH` draws, to start a scene from.
    Scene(scene_cmd::SceneArgs),
    /// Put tiles rendered with `render --tile` or `--pixel-bounds` together into one image,
    /// byte-identical to a single render; refuses missing, overlapping or foreign tiles.
    Assemble(assemble_cmd::AssembleArgs),
    /// Render one image on a cluster: `farm slurm` submits one Slurm job array of tiles, waits,
    /// and assembles; run again, it renders only the tiles still missing.
    Farm(farm_cmd::FarmArgs),
    /// Run an experiment: `seed` renders the seed report's four tests with every accelerator and
    /// prints its table beside the report's figures.
    Experiment(experiment_cmd::ExperimentArgs),
    /// Build every accelerator for one scene and compare build time, memory, speed and work.
    Compare(compare_cmd::CompareArgs),
    /// Measure englobe against Intel Embree, obvhs and bvh on the same rays (needs the `bench`
    /// cargo feature, Embree the `embree` one; otherwise run the englobe-bench binary); prints a
    /// table per scene and thread count, writes a CSV and prints its path last.
    Bench(bench_cmd::BenchArgs),
    /// Say what a mesh file (.obj, .ply, .gltf, .glb) or a scene file (.toml, .pbrt) holds, or why
    /// it is refused.
    Info(info_cmd::InfoArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render_cmd::run(args),
        Command::Scene(args) => scene_cmd::run(args),
        Command::Assemble(args) => assemble_cmd::run(args),
        Command::Farm(args) => farm_cmd::run(args),
        Command::Experiment(args) => experiment_cmd::run(args),
        Command::Compare(args) => compare_cmd::run(args),
        Command::Info(args) => info_cmd::run(args),
        Command::Bench(args) => bench_cmd::run(args),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
