//! What decides an image's pixels besides the scene file, shared by `render` and `farm`: the
//! size, samples, integrator and structure overrides, applied to the scene, and the digest that
//! tiles record of the result (see englobe-render's `tile` module).

use clap::{Args, ValueEnum};
use englobe::AccelKind;
use englobe_scene::{IntegratorKind, Scene};

/// Overrides of the scene's image settings, and the structure to trace with.
#[derive(Args, Clone, Debug)]
pub struct ImageOptions {
    /// Image width in pixels (overrides the scene).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels (overrides the scene).
    #[arg(long)]
    pub height: Option<u32>,
    /// Samples per pixel (overrides the scene).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Acceleration structure: bvh-wide (the fast path, eight-wide at both levels), none (brute
    /// force), bvh-seed, bvh-seed-ordered, bvh-sah, bvh-ploc, bvh-sweep, kdtree, grid
    #[arg(long, default_value = "bvh-wide", value_parser = parse_accel)]
    pub accel: AccelKind,
    /// Light transport: whitted (the seed's recursion) or path (Monte Carlo path tracing);
    /// overrides the scene's `integrator`.
    #[arg(long, value_parser = parse_integrator)]
    pub integrator: Option<IntegratorKind>,
}

impl ImageOptions {
    /// Writes the overrides into the scene's image settings.
    pub fn apply(&self, scene: &mut Scene) {
        let image = &mut scene.image;
        image.width = self.width.unwrap_or(image.width);
        image.height = self.height.unwrap_or(image.height);
        image.samples = self.spp.unwrap_or(image.samples);
        image.integrator = self.integrator.unwrap_or(image.integrator);
    }

    /// The same options as command-line arguments, to pass them on to another `englobe render`.
    pub fn to_args(&self) -> Vec<String> {
        let mut args = vec!["--accel".to_owned(), self.accel.name().to_owned()];
        let mut push = |flag: &str, value: Option<String>| {
            if let Some(v) = value {
                args.extend([flag.to_owned(), v]);
            }
        };
        push("--width", self.width.map(|v| v.to_string()));
        push("--height", self.height.map(|v| v.to_string()));
        push("--spp", self.spp.map(|v| v.to_string()));
        push("--integrator", self.integrator.map(|i| i.name().to_owned()));
        args
    }
}

/// How `--tile K/N` cuts the image into strips.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Balance {
    /// Strips of equal height.
    #[default]
    Area,
    /// Strips of equal predicted cost, from a first pass of the cost AOV on every 4th pixel of
    /// every 4th row (each task makes the same pass, so all agree on the cut).
    Cost,
}

/// The digest of the pixels `scene` (with the overrides applied) gives under `accel`, cut as
/// `balance` says (tiles of different cuts must not be mixed).
pub fn render_digest(scene: &Scene, accel: AccelKind, balance: Balance) -> String {
    let balance = balance.to_possible_value().expect("no variant is skipped");
    englobe_render::digest::scene_digest(
        scene,
        &format!("accel={} aov=color balance={}", accel.name(), balance.get_name()),
    )
}

fn parse_integrator(s: &str) -> Result<IntegratorKind, String> {
    match s {
        "whitted" => Ok(IntegratorKind::Whitted),
        "path" => Ok(IntegratorKind::Path),
        _ => Err(format!("unknown integrator `{s}`; expected whitted or path")),
    }
}

/// Reads a structure's name.
pub fn parse_accel(s: &str) -> Result<AccelKind, String> {
    s.parse().map_err(|e: englobe::accel::UnknownAccel| e.to_string())
}
