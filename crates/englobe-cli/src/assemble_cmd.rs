//! `englobe assemble`: tiles rendered with `--tile` or `--pixel-bounds` (by any number of
//! processes or machines) into one image, byte-identical to a single `englobe render`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::Args;
use englobe_render::tile::assemble::{Tile, assemble, missing_tiles, output_settings};
use englobe_render::tile::file::read_tile;
use englobe_render::write_image_with;
use englobe_scene::OutputSettings;

use crate::image_options::OutputOptions;

#[derive(Args)]
pub struct AssembleArgs {
    /// Tiles (.exr files written by `englobe render --tile` or `--pixel-bounds`), or folders
    /// whose .exr files are all tiles.
    #[arg(required = true)]
    tiles: Vec<PathBuf>,
    /// The image to write (.png or .exr), atomically.
    #[arg(short, long, required_unless_present = "missing")]
    output: Option<PathBuf>,
    /// Write nothing; print the tiles of the cut that are still to render, one `K/N` per line.
    #[arg(long)]
    missing: bool,
    /// How many tiles the cut has (default: what the tiles say); with --missing, lets an empty
    /// folder list every tile.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    count: Option<u32>,
    #[command(flatten)]
    output_options: OutputOptions,
    /// No summary line.
    #[arg(short, long)]
    quiet: bool,
}

pub fn run(args: AssembleArgs) -> anyhow::Result<ExitCode> {
    let paths = tile_paths(&args.tiles)?;
    let mut tiles = Vec::with_capacity(paths.len());
    let mut unreadable = Vec::new();
    for path in paths {
        match read_tile(&path) {
            Ok((header, film)) => tiles.push(Tile { path, header, film }),
            Err(e) => unreadable.push(e.to_string()),
        }
    }
    anyhow::ensure!(unreadable.is_empty(), "cannot read {} of the tiles:\n{}", unreadable.len(), unreadable.join("\n"));
    if let Some(count) = args.count
        && let Some(t) = tiles.iter().find(|t| t.header.tile.is_some_and(|s| s.count != count))
    {
        anyhow::bail!("{}: tile {} is not of a cut into {count} tiles", t.path.display(), t.header.tile.unwrap());
    }
    if args.missing {
        for tile in missing_tiles(&tiles, args.count) {
            println!("{tile}");
        }
        return Ok(ExitCode::SUCCESS);
    }
    let output = args.output.expect("clap requires --output without --missing");
    englobe_render::OutputFormat::from_path(&output)?;
    let film = assemble(&tiles)?;
    // The tiles' own output settings unless the command line says otherwise.
    let settings = match output_settings(&tiles) {
        Ok(recorded) => args.output_options.apply(recorded),
        Err(_) if args.output_options.exposure.is_some() && args.output_options.tonemap.is_some() => {
            args.output_options.apply(OutputSettings::default())
        }
        Err(why) => anyhow::bail!("{why}; choose with --exposure and --tonemap"),
    };
    write_image_with(&film, &output, &settings)?;
    if !args.quiet {
        println!("wrote {} ({}x{} from {} tiles)", output.display(), film.width(), film.height(), tiles.len());
    }
    Ok(ExitCode::SUCCESS)
}

/// The files named, with folders replaced by their .exr files in name order.
fn tile_paths(args: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
    let mut paths = Vec::new();
    for arg in args {
        if arg.is_dir() {
            paths.extend(exr_files_in(arg)?);
        } else {
            paths.push(arg.clone());
        }
    }
    Ok(paths)
}

/// The .exr files of a folder, in name order.
pub fn exr_files_in(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(|| format!("{}: cannot list the folder", dir.display()))? {
        let path = entry.with_context(|| format!("{}: cannot list the folder", dir.display()))?.path();
        if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) && path.is_file() {
            files.push(path);
        }
    }
    files.sort();
    Ok(files)
}
