//! `englobe scene MESH`: prints the scene that frames a mesh file (see `englobe_scene::framing`),
//! the one `englobe render MESH` draws, as a starting point to edit: `englobe scene bunny.obj >
//! bunny.toml`, saved in the current folder, renders the same image.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use englobe_scene::framing::framing_scene;

#[derive(Args)]
pub struct SceneArgs {
    /// Mesh file (.obj, .ply, .gltf, .glb), named in the scene as given here.
    mesh: PathBuf,
}

pub fn run(args: SceneArgs) -> anyhow::Result<ExitCode> {
    print!("{}", framing_scene(&args.mesh)?);
    Ok(ExitCode::SUCCESS)
}
