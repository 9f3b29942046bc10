//! Rendering an image: the film is cut into square tiles that rayon's workers take in any order;
//! every pixel draws its samples from a generator seeded by the scene's seed and the pixel's
//! position alone, and tiles are stitched back in a fixed order, so the image bytes and the
//! counts are the same on 1 thread or many.
//!
//! On request the renderer also records the work of every pixel (the cost AOV, see
//! [`crate::cost`]) and can render only a regular sample of the pixels (every `n`-th pixel of
//! every `n`-th row), which times slow structures on large scenes, or only a window of the image
//! (a tile of a render spread over several processes, see [`crate::tile`]); a pixel's value never
//! depends on which other pixels are rendered.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

use englobe::{Counters, NoCount, Ray, Vec3, WorkCounts, World};
use englobe_scene::{ImageSettings, IntegratorKind, Scene, TextureFilter};
use rand::RngExt;

use crate::sampler::PixelSampler;
pub use crate::sampler::pixel_rng;
use rayon::prelude::*;

use crate::camera::ImageCamera;
use crate::cost::CostImage;
use crate::film::Film;
use crate::filter::FilterSampler;
use crate::path::PathTracer;
use crate::ray_cone::RayCone;
use crate::stats::{RenderStats, Tally};
use crate::supersample::AdaptiveSupersampling;
use crate::tile::PixelWindow;
use crate::whitted::Whitted;

/// Side of the square tiles, in pixels.
pub const TILE_SIZE: u32 = 32;

/// Why a render could not start.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RenderError {
    /// Size, samples or depth out of range (checked before anything is allocated).
    #[error("{0}")]
    Limits(String),
}

/// What a render produced.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    /// The image: the window's pixels (the whole image unless [`Renderer::window`] asked for less).
    pub film: Film,
    /// Where the film lies in the image.
    pub window: PixelWindow,
    /// Rays and work per kind of ray (work is zero unless counting was asked for).
    pub stats: RenderStats,
    /// False if the render was cancelled before every tile was done (missing tiles are black).
    pub complete: bool,
    /// Tiles of [`TILE_SIZE`] pixels finished, out of all the window's (a render by passes counts
    /// the tiles of its passes' pixels: all of them, or none).
    pub tiles_done: usize,
    /// Samples per pixel the film holds: all those asked for, unless a render by passes stopped
    /// early (see [`Renderer::render_passes`]); with a noise threshold, the most any pixel took
    /// (each pixel's own are in [`RenderOutput::samples_map`]).
    pub samples_done: u32,
    /// Wall-clock seconds spent rendering.
    pub seconds: f64,
    /// Work per pixel (nodes visited plus exact tests) over the window, if [`Renderer::record_cost`]
    /// asked for it.
    pub cost: Option<CostImage>,
    /// Samples each pixel of the window took, when the scene's noise threshold made them vary
    /// (adaptive sampling, see `crate::adaptive`).
    pub samples_map: Option<CostImage>,
}

/// Renders a scene through its world: `Renderer::new(&scene, &world).size(640, 480).render()`.
pub struct Renderer<'a> {
    pub(crate) scene: &'a Scene,
    pub(crate) world: &'a World,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) samples: u32,
    pub(crate) count_work: bool,
    pub(crate) record_cost: bool,
    pub(crate) stride: u32,
    pub(crate) window: Option<PixelWindow>,
    pub(crate) progress: Option<&'a (dyn Fn(usize, usize) + Sync)>,
    pub(crate) cancel: Option<&'a AtomicBool>,
    pub(crate) integrator: IntegratorKind,
    pub(crate) supersampling: Option<AdaptiveSupersampling>,
    pub(crate) filter: FilterSampler,
}

impl<'a> Renderer<'a> {
    /// A renderer with the scene's own image settings. `world` must hold the scene's objects in
    /// order (see [`crate::build_world`]).
    pub fn new(scene: &'a Scene, world: &'a World) -> Self {
        let ImageSettings { width, height, samples, .. } = scene.image;
        Renderer {
            scene,
            world,
            width,
            height,
            samples,
            count_work: false,
            record_cost: false,
            stride: 1,
            window: None,
            progress: None,
            cancel: None,
            integrator: scene.image.integrator,
            supersampling: None,
            filter: FilterSampler::new(&scene.image.filter),
        }
    }

    /// Overrides the image size.
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.width = width;
        self.height = height;
        self
    }

    /// Overrides the samples per pixel.
    pub fn samples(mut self, samples: u32) -> Self {
        self.samples = samples;
        self
    }

    /// Counts the structure's work (nodes, box tests, exact tests) per kind of ray. Off by
    /// default: the uncounted render compiles the counters away.
    pub fn count_work(mut self, on: bool) -> Self {
        self.count_work = on;
        self
    }

    /// Records the work of every pixel (nodes visited plus exact tests, over all its rays) into
    /// [`RenderOutput::cost`]. Implies counting; off by default, so a normal render pays nothing.
    pub fn record_cost(mut self, on: bool) -> Self {
        self.record_cost = on;
        self
    }

    /// Renders only the pixels `(x, y)` with `x` and `y` multiples of `stride` (1, the default,
    /// renders all); the others stay black and cost nothing. Statistics count the rendered pixels
    /// only. Pixels rendered have the values a full render gives them.
    pub fn pixel_stride(mut self, stride: u32) -> Self {
        self.stride = stride.max(1);
        self
    }

    /// Renders only the pixels of `window` (checked to lie inside the image when the render
    /// starts), into a film of the window's size; each has the value a full render gives it.
    pub fn window(mut self, window: PixelWindow) -> Self {
        self.window = Some(window);
        self
    }

    /// Samples each pixel adaptively (see [`crate::supersample`]) instead of with the scene's
    /// samples: corners first, squares whose corners differ cut in four. The sample positions
    /// are fixed, so a pixel still depends on itself alone; the path tracer's random numbers
    /// come from the pixel's generator as usual. Not for renders by passes.
    pub fn supersampling(mut self, adaptive: AdaptiveSupersampling) -> Self {
        self.supersampling = Some(adaptive);
        self
    }

    /// Overrides the scene's integrator.
    pub fn integrator(mut self, kind: IntegratorKind) -> Self {
        self.integrator = kind;
        self
    }

    /// Calls `f(tiles_done, tiles_total)` after every tile, from any worker thread.
    pub fn on_progress(mut self, f: &'a (dyn Fn(usize, usize) + Sync)) -> Self {
        self.progress = Some(f);
        self
    }

    /// Stops the render once `flag` is set: every worker gives up at its next pixel, so the render
    /// returns within about one pixel's time, and the output says it is incomplete.
    pub fn cancel_flag(mut self, flag: &'a AtomicBool) -> Self {
        self.cancel = Some(flag);
        self
    }

    /// Renders on the current rayon thread pool; with the scene's `noise_threshold`, by adaptive
    /// sampling (see `crate::adaptive`).
    pub fn render(&self) -> Result<RenderOutput, RenderError> {
        ImageSettings::check_limits(self.width, self.height, self.samples, self.scene.image.max_depth)
            .map_err(RenderError::Limits)?;
        if let Some(w) = self.window {
            w.check_inside(self.width, self.height).map_err(RenderError::Limits)?;
        }
        if let Some(adaptive) = self.adaptive_sampling()? {
            return self.render_adaptive(adaptive, None);
        }
        if self.count_work || self.record_cost {
            Ok(self.render_with::<WorkCounts>())
        } else {
            Ok(self.render_with::<NoCount>())
        }
    }

    fn render_with<C: Counters + Copy + Send + Into<WorkCounts>>(&self) -> RenderOutput {
        let start = Instant::now();
        let (camera, integrator) = self.parts();
        let window = self.window.unwrap_or(PixelWindow::full(self.width, self.height));
        let tiles_x = window.width().div_ceil(TILE_SIZE);
        let tiles_y = window.height().div_ceil(TILE_SIZE);
        // Tile `index`'s pixels: the grid starts at the window's corner.
        let tile_at = |index: usize| {
            let (x0, y0) =
                (window.x0 + (index as u32 % tiles_x) * TILE_SIZE, window.y0 + (index as u32 / tiles_x) * TILE_SIZE);
            (x0, y0, (x0 + TILE_SIZE).min(window.x1), (y0 + TILE_SIZE).min(window.y1))
        };
        let total = (tiles_x * tiles_y) as usize;
        let done = AtomicUsize::new(0);
        let cancelled = || self.cancel.is_some_and(|c| c.load(Ordering::Relaxed));
        let tile_done = || {
            let n = done.fetch_add(1, Ordering::Relaxed) + 1;
            if let Some(progress) = self.progress {
                progress(n, total);
            }
        };

        let tiles: Vec<Option<TileOutput>> = (0..total)
            .into_par_iter()
            .map(|index| {
                let (x0, y0, x1, y1) = tile_at(index);
                let mut tally = Tally::<C>::default();
                if self.primary_packets() {
                    let pixels =
                        self.tile_in_packets(&camera, &integrator, (x0, y0, x1, y1), &mut tally, &cancelled)?;
                    tile_done();
                    return Some(TileOutput { pixels, stats: tally.stats(), cost: Vec::new() });
                }
                let area = ((x1 - x0) * (y1 - y0)) as usize;
                let mut pixels = Vec::with_capacity(area);
                let mut cost = Vec::with_capacity(if self.record_cost { area } else { 0 });
                for y in y0..y1 {
                    for x in x0..x1 {
                        if cancelled() {
                            return None;
                        }
                        if x % self.stride != 0 || y % self.stride != 0 {
                            pixels.push(Vec3::ZERO);
                            if self.record_cost {
                                cost.push(0);
                            }
                        } else if self.record_cost {
                            let before = tally.work_total();
                            pixels.push(self.pixel(&camera, &integrator, x, y, &mut tally));
                            let after = tally.work_total();
                            cost.push(
                                (after.nodes_visited + after.exact_tests) - (before.nodes_visited + before.exact_tests),
                            );
                        } else {
                            pixels.push(self.pixel(&camera, &integrator, x, y, &mut tally));
                        }
                    }
                }
                tile_done();
                Some(TileOutput { pixels, stats: tally.stats(), cost })
            })
            .collect();

        let mut film = Film::new(window.width(), window.height());
        let mut cost = self.record_cost.then(|| CostImage::new(window.width(), window.height()));
        let mut stats = RenderStats::default();
        let mut complete = true;
        let mut tiles_done = 0;
        for (index, tile) in tiles.into_iter().enumerate() {
            let Some(tile) = tile else {
                complete = false;
                continue;
            };
            tiles_done += 1;
            stats.add(&tile.stats);
            let (x0, y0, x1, y1) = tile_at(index);
            let mut it = tile.pixels.into_iter();
            let mut work = tile.cost.into_iter();
            for y in y0 - window.y0..y1 - window.y0 {
                for x in x0 - window.x0..x1 - window.x0 {
                    film.set(x, y, it.next().expect("a tile holds all its pixels"));
                    if let Some(cost) = cost.as_mut() {
                        cost.set(x, y, work.next().expect("a tile holds the cost of all its pixels"));
                    }
                }
            }
        }
        let samples_done = if complete { self.samples } else { 0 };
        RenderOutput {
            film,
            window,
            stats,
            complete,
            tiles_done,
            samples_done,
            seconds: start.elapsed().as_secs_f64(),
            cost,
            samples_map: None,
        }
    }

    fn pixel<C: Counters>(
        &self,
        camera: &ImageCamera,
        integrator: &Integrator,
        x: u32,
        y: u32,
        tally: &mut Tally<C>,
    ) -> Vec3 {
        let mut rng = self.pixel_sampler(x, y);
        if let Some(adaptive) = self.supersampling {
            let mut at = |dx: f32, dy: f32| {
                rng.start_sample();
                self.sample_at(camera, integrator, x, y, dx, dy, &mut rng, tally)
            };
            return adaptive.pixel(&mut at).0;
        }
        if self.samples == 1 {
            return self.sample(camera, integrator, x, y, &mut rng, tally);
        }
        let mut sum = Vec3::ZERO;
        for _ in 0..self.samples {
            sum += self.sample(camera, integrator, x, y, &mut rng, tally);
        }
        sum / self.samples as f32
    }

    /// The next sample of pixel `(x, y)`, whose generator is `rng`: through the pixel's centre
    /// when the render takes one sample per pixel (as the seed's renderer did, whatever the
    /// filter), otherwise at an offset drawn from the scene's pixel filter (see
    /// [`crate::filter`]; the default box jitters over the pixel). A render by passes calls it in
    /// the same order per pixel, so the sums are the same.
    #[inline]
    pub(crate) fn sample<C: Counters>(
        &self,
        camera: &ImageCamera,
        integrator: &Integrator,
        x: u32,
        y: u32,
        rng: &mut PixelSampler,
        tally: &mut Tally<C>,
    ) -> Vec3 {
        rng.start_sample();
        let (dx, dy) = self.sample_offset(rng);
        self.sample_at(camera, integrator, x, y, dx, dy, rng, tally)
    }

    /// Where a sample passes through its pixel (see [`Renderer::sample`]), drawn from `rng` just
    /// after [`PixelSampler::start_sample`].
    #[inline]
    pub(crate) fn sample_offset(&self, rng: &mut PixelSampler) -> (f32, f32) {
        if self.samples == 1 { (0.5, 0.5) } else { self.filter.sample(rng.random(), rng.random()) }
    }

    /// The camera ray through the point `(dx, dy)` of pixel `(x, y)` (see
    /// [`Renderer::sample_at`]).
    #[inline(always)]
    pub(crate) fn camera_ray(
        &self,
        camera: &ImageCamera,
        x: u32,
        y: u32,
        dx: f32,
        dy: f32,
        rng: &mut PixelSampler,
    ) -> Ray {
        if camera.has_lens() {
            // Drawn only with a lens, so that pinhole images keep their random numbers.
            let (u, v): (f32, f32) = (rng.random(), rng.random());
            camera.ray_through_lens(x as f32 + dx, y as f32 + dy, u, v)
        } else {
            camera.ray(x as f32 + dx, y as f32 + dy)
        }
    }

    /// The sample of pixel `(x, y)` through its point `(dx, dy)`, in pixels from its top-left
    /// corner (`0..=1` inside the pixel; a filter wider than the pixel reaches beyond).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn sample_at<C: Counters>(
        &self,
        camera: &ImageCamera,
        integrator: &Integrator,
        x: u32,
        y: u32,
        dx: f32,
        dy: f32,
        rng: &mut PixelSampler,
        tally: &mut Tally<C>,
    ) -> Vec3 {
        let ray = self.camera_ray(camera, x, y, dx, dy, rng);
        let radiance = match integrator {
            Integrator::Whitted(w) => w.radiance(&ray, tally),
            Integrator::Path(p) => p.radiance(&ray, rng, tally),
        };
        self.clamped(radiance)
    }

    /// A sample's radiance clamped as the scene asks (see [`clamp_sample`]).
    #[inline]
    pub(crate) fn clamped(&self, radiance: Vec3) -> Vec3 {
        match self.scene.image.clamp {
            Some(most) => clamp_sample(radiance, most),
            None => radiance,
        }
    }

    /// The camera and the integrator of a render.
    pub(crate) fn parts(&self) -> (ImageCamera, Integrator<'a>) {
        let camera = ImageCamera::new(&self.scene.camera, self.width, self.height);
        // Untextured scenes skip the cones: they would change nothing but the time.
        let cone = (self.scene.image.texture_filter == TextureFilter::Cone && !self.scene.textures.is_empty())
            .then(|| RayCone::primary(&self.scene.camera, self.height, self.samples));
        let integrator = match self.integrator {
            IntegratorKind::Whitted => Integrator::Whitted(Whitted::new(self.scene, self.world).with_cone(cone)),
            IntegratorKind::Path => Integrator::Path(PathTracer::new(self.scene, self.world).with_cone(cone)),
        };
        (camera, integrator)
    }
}

/// The integrator a render uses.
pub(crate) enum Integrator<'a> {
    Whitted(Whitted<'a>),
    Path(PathTracer<'a>),
}

/// What one tile produced: its pixels row by row, its counts, and its pixels' work if recorded.
struct TileOutput {
    pixels: Vec<Vec3>,
    stats: RenderStats,
    cost: Vec<u64>,
}

/// A sample's radiance with its largest component at most `most`, scaled down as a whole so that
/// its hue stays (pbrt-v4's `maxComponentValue`): the clamp against fireflies, a bias traded for
/// less noise. NaN components are left for the film to show.
pub fn clamp_sample(radiance: Vec3, most: f32) -> Vec3 {
    let largest = radiance.max_element();
    if !(largest > most) {
        radiance
    } else if largest.is_finite() {
        radiance * (most / largest)
    } else {
        radiance.min(Vec3::splat(most))
    }
}

impl Renderer<'_> {
    /// The random numbers of pixel `(x, y)` (see [`crate::sampler`]).
    pub(crate) fn pixel_sampler(&self, x: u32, y: u32) -> PixelSampler {
        PixelSampler::new(self.scene.image.sampler, self.scene.image.seed, x, y)
    }
}
