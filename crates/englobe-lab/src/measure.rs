//! What the seed's experiments and the comparison share: building one structure for a scene and
//! rendering with it, timed, comparing the images of two structures bit for bit, and the worker
//! pool they render on.

use std::time::Instant;

use englobe::{AccelKind, World};
use englobe_render::{Film, RenderOutput, Renderer, build_world};
use englobe_scene::Scene;

use crate::error::LabError;

/// Renders are repeated until they have taken this long in all (or [`MAX_TIMED_RUNS`] times), and
/// the best time is kept.
pub const MIN_TIMED_SECONDS: f64 = 2.0;
/// Most renders timed per structure (and test).
pub const MAX_TIMED_RUNS: u32 = 10;

/// How to render.
#[derive(Clone, Copy, Debug)]
pub struct RenderSettings {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel.
    pub samples: u32,
    /// Count the structure's work (slightly slower).
    pub count_work: bool,
    /// Render every `stride`-th pixel of every `stride`-th row only.
    pub stride: u32,
}

/// Builds the world of the scene's objects under `kind`; returns it with the seconds it took
/// (the primitives' boxes and the structure over them).
pub fn build(scene: &Scene, kind: AccelKind) -> Result<(World, f64), LabError> {
    let start = Instant::now();
    let world = build_world(scene, kind).map_err(|source| LabError::Build { kind, source })?;
    Ok((world, start.elapsed().as_secs_f64()))
}

/// Renders the scene through `world` on the current pool.
pub fn render(scene: &Scene, world: &World, settings: RenderSettings) -> Result<RenderOutput, LabError> {
    Ok(Renderer::new(scene, world)
        .size(settings.width, settings.height)
        .samples(settings.samples)
        .count_work(settings.count_work)
        .pixel_stride(settings.stride)
        .render()?)
}

/// Pixels rendered in both images (those at multiples of the larger of two power-of-two strides)
/// and how many of them differ, bit for bit.
pub fn compare_films(a: &Film, stride_a: u32, b: &Film, stride_b: u32) -> (usize, usize) {
    let step = stride_a.max(stride_b).max(1);
    let (mut compared, mut differing) = (0, 0);
    for y in (0..a.height().min(b.height())).step_by(step as usize) {
        for x in (0..a.width().min(b.width())).step_by(step as usize) {
            compared += 1;
            let (p, q) = (a.get(x, y), b.get(x, y));
            if p.to_array().map(f32::to_bits) != q.to_array().map(f32::to_bits) {
                differing += 1;
            }
        }
    }
    (compared, differing)
}

/// A worker pool of `threads` threads (all cores if `None`).
pub fn thread_pool(threads: Option<u32>) -> Result<rayon::ThreadPool, LabError> {
    rayon::ThreadPoolBuilder::new().num_threads(threads.map_or(0, |t| t as usize)).build().map_err(LabError::Threads)
}
