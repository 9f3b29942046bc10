//! # englobe-render
//!
//! englobe's renderer: a pinhole camera, point and directional lights, Phong-style materials with
//! mirrors and glass, the Whitted integrator of the seed report and a Monte Carlo path tracer,
//! tiled parallel rendering that
//! gives the same bytes on any number of threads, atomic PNG/EXR output, and the cost AOV: a
//! false-colour picture of the work an acceleration structure does per pixel.
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let scene = englobe_scene::parse_scene(englobe_render::DEFAULT_SCENE, "default.toml".as_ref())?;
//! let world = englobe_render::build_world(&scene, englobe::AccelKind::None)?;
//! let out = englobe_render::Renderer::new(&scene, &world).size(16, 12).render()?;
//! assert_eq!(out.film.width(), 16);
//! # Ok(()) }
//! ```

pub mod adaptive;
pub mod bsdf;
pub mod camera;
pub mod cost;
pub mod digest;
pub mod distribution;
pub mod emitters;
pub mod environment;
pub mod film;
pub mod filter;
pub mod heatmap;
pub mod light_sampling;
pub mod optics;
pub mod output;
mod passes;
pub mod path;
mod primary_packets;
pub mod ray_cone;
pub mod render;
pub mod sampler;
pub mod sampling;
pub mod shading;
pub mod sphere_lights;
pub mod stats;
pub mod supersample;
pub mod tile;
pub mod tonemap;
pub mod visibility;
pub mod whitted;

pub use camera::ImageCamera;
pub use cost::{CostImage, write_cost_image};
pub use film::Film;
pub use filter::FilterSampler;
pub use heatmap::{Heatmap, HeatmapScale};
pub use output::{OutputError, OutputFormat, write_image, write_image_with};
pub use path::PathTracer;
pub use render::{RenderError, RenderOutput, Renderer};
pub use stats::{KindStats, RayKind, RenderStats};
pub use tile::{PixelWindow, TileSpec};

use englobe::{AccelKind, World, WorldError};
use englobe_scene::Scene;

/// The default scene: a few spheres on a plane, mirror and glass, two lights.
pub const DEFAULT_SCENE: &str = include_str!("../../../scenes/default.toml");

/// The world of a scene's objects, in the scene's order, under the structure `kind`.
pub fn build_world(scene: &Scene, kind: AccelKind) -> Result<World, WorldError> {
    World::build(scene.objects.iter().map(|o| o.object.clone()).collect(), kind)
}
