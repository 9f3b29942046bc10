//! The `englobe` command: render scenes and measure how acceleration structures cut the work of
//! ray tracing.

mod progress;
mod render_cmd;
mod report;

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
    /// Render a scene file (or the embedded default scene) to PNG or EXR.
    Render(render_cmd::RenderArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render_cmd::run(args),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
