//! Rendering by sample passes: every pixel takes its first sample, then every pixel its second,
//! and so on, so that a render stopped by a time limit or by Ctrl-C still has an image, the one
//! of its last complete pass, with as many samples in every pixel.
//!
//! Each pixel keeps its own generator and sum between passes and adds its samples in the order
//! the tile renderer does ([`Renderer::render`]), so a render by passes that finishes writes the
//! same bytes, and one stopped after `k` passes holds the image of a `k`-sample render (for
//! `k >= 2`: one sample alone goes through the pixel centre). The price is memory: a generator, a
//! sum and the pass's sample per pixel, 40 bytes, which is why the tile renderer stays the default.

use std::sync::atomic::Ordering;
use std::time::Instant;

use englobe::{Counters, NoCount, Vec3, WorkCounts};
use englobe_scene::ImageSettings;
use rayon::prelude::*;

use crate::film::Film;
use crate::render::{RenderError, RenderOutput, Renderer, TILE_SIZE};
use crate::sampler::PixelSampler;
use crate::stats::{RenderStats, Tally};
use crate::tile::PixelWindow;

impl Renderer<'_> {
    /// Renders pass by pass until every sample is taken, the cancel flag is set, or `deadline`
    /// passes; the film holds the passes completed ([`RenderOutput::samples_done`]), and
    /// [`RenderOutput::complete`] says whether that is all of them. Progress is reported as
    /// `(passes_done, passes_total)`. Work is counted if asked; the cost AOV is not recorded.
    /// With the scene's `noise_threshold` the passes are adaptive sampling's (see
    /// `crate::adaptive`), progress is `(samples, max_samples)`, and the cost AOV is recorded.
    pub fn render_passes(&self, deadline: Option<Instant>) -> Result<RenderOutput, RenderError> {
        if self.supersampling.is_some() {
            return Err(RenderError::Limits(
                "adaptive supersampling has no passes: a pixel's samples depend on each other".into(),
            ));
        }
        ImageSettings::check_limits(self.width, self.height, self.samples, self.scene.image.max_depth)
            .map_err(RenderError::Limits)?;
        if let Some(w) = self.window {
            w.check_inside(self.width, self.height).map_err(RenderError::Limits)?;
        }
        if let Some(adaptive) = self.adaptive_sampling()? {
            return self.render_adaptive(adaptive, deadline);
        }
        if self.count_work {
            Ok(self.passes_with::<WorkCounts>(deadline))
        } else {
            Ok(self.passes_with::<NoCount>(deadline))
        }
    }

    fn passes_with<C: Counters + Copy + Send + Into<WorkCounts>>(&self, deadline: Option<Instant>) -> RenderOutput {
        let start = Instant::now();
        let (camera, integrator) = self.parts();
        let window = self.window.unwrap_or(PixelWindow::full(self.width, self.height));
        let (w, h) = (window.width() as usize, window.height() as usize);
        let at = |i: usize| (window.x0 + (i % w) as u32, window.y0 + (i / w) as u32);
        let mut rngs: Vec<PixelSampler> = (0..w * h).map(at).map(|(x, y)| self.pixel_sampler(x, y)).collect();
        let mut sums = vec![Vec3::ZERO; w * h];
        let mut values = vec![Vec3::ZERO; w * h];
        let stop =
            || self.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) || deadline.is_some_and(|d| Instant::now() >= d);
        let rendered = |x: u32, y: u32| x % self.stride == 0 && y % self.stride == 0;
        let mut stats = RenderStats::default();
        let mut samples_done = 0;
        // Rows in chunks, so that a worker checks the clock between a few hundred pixels.
        let rows = (4096 / w.max(1)).clamp(1, TILE_SIZE as usize);
        for pass in 0..self.samples {
            if stop() {
                break;
            }
            let chunks: Option<Vec<RenderStats>> = values
                .par_chunks_mut(rows * w)
                .zip(rngs.par_chunks_mut(rows * w))
                .enumerate()
                .map(|(chunk, (values, rngs))| {
                    let mut tally = Tally::<C>::default();
                    for (k, (value, rng)) in values.iter_mut().zip(rngs).enumerate() {
                        if k % w == 0 && stop() {
                            return None;
                        }
                        let (x, y) = at(chunk * rows * w + k);
                        *value = if rendered(x, y) {
                            self.sample(&camera, &integrator, x, y, rng, &mut tally)
                        } else {
                            Vec3::ZERO
                        };
                    }
                    Some(tally.stats())
                })
                .collect();
            // A pass cut short leaves the sums of the passes before it.
            let Some(chunks) = chunks else { break };
            if self.samples == 1 {
                // As the tile renderer: the one sample itself, not added to a zero (which would
                // turn a negative zero positive).
                sums.copy_from_slice(&values);
            } else {
                sums.par_iter_mut().zip(&values).for_each(|(sum, value)| *sum += *value);
            }
            for c in &chunks {
                stats.add(c);
            }
            samples_done = pass + 1;
            if let Some(progress) = self.progress {
                progress(samples_done as usize, self.samples as usize);
            }
        }

        let mut film = Film::new(window.width(), window.height());
        if samples_done > 0 {
            for (i, sum) in sums.iter().enumerate() {
                let value = if self.samples == 1 { *sum } else { *sum / samples_done as f32 };
                film.set((i % w) as u32, (i / w) as u32, value);
            }
        }
        let complete = samples_done == self.samples;
        let tiles = (window.width().div_ceil(TILE_SIZE) * window.height().div_ceil(TILE_SIZE)) as usize;
        RenderOutput {
            film,
            window,
            stats,
            complete,
            tiles_done: if complete { tiles } else { 0 },
            samples_done,
            seconds: start.elapsed().as_secs_f64(),
            cost: None,
            samples_map: None,
        }
    }
}
