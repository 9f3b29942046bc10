//! Rendering with adaptive sampling: the blocks that cover the window take the first pass, then
//! every block that has not converged takes the next pass, and so on (see [`super::estimator`]).
//!
//! Why the result does not depend on threads or on the window: a pixel draws its samples from its
//! own sampler ([`crate::sampler::PixelSampler`]), kept between passes, so sample `k` of a pixel is
//! the same whatever else is rendered; a pass's samples are added to a copy of each block's sums
//! and only committed once the whole pass is done; and a block's decision, taken between passes,
//! reads its own pixels alone. A pixel's value is the mean of its own samples, added in order, so
//! it is bit for bit the pixel of a uniform render with as many samples; a block that never
//! converges gives the uniform render's pixels. A window (a tile) is rendered with every block
//! that touches it, whole, and keeps its own pixels: the same values as the whole image's.
//!
//! Memory: a generator, three sums and the work per pixel (60 bytes), a little more than a render
//! by passes.

use std::sync::atomic::Ordering;
use std::time::Instant;

use englobe::{Counters, NoCount, Vec3, WorkCounts};
use rayon::prelude::*;

use super::estimator::{AdaptiveSampling, BLOCK_SIZE, HalfSums, block_error};
use crate::cost::CostImage;
use crate::film::Film;
use crate::render::{RenderError, RenderOutput, Renderer, TILE_SIZE};
use crate::sampler::PixelSampler;
use crate::stats::{RenderStats, Tally};
use crate::tile::PixelWindow;

/// One pixel's state between passes.
#[derive(Clone)]
struct PixelState {
    rng: PixelSampler,
    sums: HalfSums,
    /// Nodes visited plus exact tests over its samples (kept when the cost AOV is recorded).
    cost: u64,
}

/// A block of pixels that stop together.
struct Block {
    area: PixelWindow,
    /// Its pixels, row by row.
    pixels: Vec<PixelState>,
    /// Samples every pixel of it has taken.
    taken: u32,
    /// No more samples: converged, or at the maximum.
    done: bool,
}

/// The blocks of the image's grid (of [`BLOCK_SIZE`], from the image's corner) that `window`
/// touches, clipped to the `width` x `height` image, row by row.
pub fn covering_blocks(window: PixelWindow, width: u32, height: u32) -> Vec<PixelWindow> {
    let (bx0, by0) = (window.x0 / BLOCK_SIZE, window.y0 / BLOCK_SIZE);
    let (bx1, by1) = (window.x1.div_ceil(BLOCK_SIZE), window.y1.div_ceil(BLOCK_SIZE));
    let mut blocks = Vec::with_capacity(((bx1 - bx0) * (by1 - by0)) as usize);
    for by in by0..by1 {
        for bx in bx0..bx1 {
            blocks.push(PixelWindow {
                x0: bx * BLOCK_SIZE,
                x1: ((bx + 1) * BLOCK_SIZE).min(width),
                y0: by * BLOCK_SIZE,
                y1: ((by + 1) * BLOCK_SIZE).min(height),
            });
        }
    }
    blocks
}

impl Renderer<'_> {
    /// The adaptive sampling this render uses, if any: the scene's `noise_threshold` with the
    /// render's samples as the maximum; refused with what it cannot be combined with.
    pub(crate) fn adaptive_sampling(&self) -> Result<Option<AdaptiveSampling>, RenderError> {
        let Some(adaptive) = AdaptiveSampling::of(&self.scene.image, self.samples) else { return Ok(None) };
        if self.supersampling.is_some() {
            return Err(RenderError::Limits(
                "adaptive supersampling and a noise threshold cannot be combined: both decide a pixel's samples".into(),
            ));
        }
        if self.stride > 1 {
            return Err(RenderError::Limits(format!(
                "a noise threshold decides per {BLOCK_SIZE}x{BLOCK_SIZE} block of pixels, so it cannot render a \
                 sample of the pixels (1 in {0}x{0}); set image.noise_threshold = 0",
                self.stride
            )));
        }
        Ok(Some(adaptive))
    }

    /// Renders with adaptive sampling until every block has converged or taken the maximum, the
    /// cancel flag is set, or `deadline` passes; a pass cut short is dropped, so the film holds
    /// the passes completed. [`RenderOutput::samples_map`] holds each pixel's samples;
    /// [`RenderOutput::samples_done`] is the most any pixel took. Progress is reported as
    /// `(samples, max_samples)` after each pass.
    pub(crate) fn render_adaptive(
        &self,
        adaptive: AdaptiveSampling,
        deadline: Option<Instant>,
    ) -> Result<RenderOutput, RenderError> {
        if self.count_work || self.record_cost {
            Ok(self.adaptive_with::<WorkCounts>(adaptive, deadline))
        } else {
            Ok(self.adaptive_with::<NoCount>(adaptive, deadline))
        }
    }

    fn adaptive_with<C: Counters + Copy + Send + Into<WorkCounts>>(
        &self,
        adaptive: AdaptiveSampling,
        deadline: Option<Instant>,
    ) -> RenderOutput {
        let start = Instant::now();
        let (camera, integrator) = self.parts();
        let window = self.window.unwrap_or(PixelWindow::full(self.width, self.height));
        let mut blocks: Vec<Block> = covering_blocks(window, self.width, self.height)
            .into_iter()
            .map(|area| {
                let pixels = (area.y0..area.y1)
                    .flat_map(|y| (area.x0..area.x1).map(move |x| (x, y)))
                    .map(|(x, y)| PixelState { rng: self.pixel_sampler(x, y), sums: HalfSums::default(), cost: 0 })
                    .collect();
                Block { area, pixels, taken: 0, done: false }
            })
            .collect();
        let stop =
            || self.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) || deadline.is_some_and(|d| Instant::now() >= d);
        let mut stats = RenderStats::default();
        let mut taken = 0;
        loop {
            let active: Vec<usize> = (0..blocks.len()).filter(|&i| !blocks[i].done).collect();
            if active.is_empty() || stop() {
                break;
            }
            let target = adaptive.next_total(taken);
            let pass: Option<Vec<(Vec<PixelState>, RenderStats)>> = active
                .par_iter()
                .map(|&i| {
                    let block = &blocks[i];
                    let mut pixels = block.pixels.clone();
                    let mut tally = Tally::<C>::default();
                    let width = block.area.width();
                    for (k, p) in pixels.iter_mut().enumerate() {
                        if stop() {
                            return None;
                        }
                        let (x, y) = (block.area.x0 + k as u32 % width, block.area.y0 + k as u32 / width);
                        let before = self.record_cost.then(|| tally.work_total());
                        for index in block.taken..target {
                            let value = self.sample(&camera, &integrator, x, y, &mut p.rng, &mut tally);
                            p.sums.add(index, value);
                        }
                        if let Some(before) = before {
                            let after = tally.work_total();
                            p.cost +=
                                (after.nodes_visited + after.exact_tests) - (before.nodes_visited + before.exact_tests);
                        }
                    }
                    Some((pixels, tally.stats()))
                })
                .collect();
            // A pass cut short leaves the passes before it.
            let Some(pass) = pass else { break };
            for (&i, (pixels, pass_stats)) in active.iter().zip(pass) {
                let block = &mut blocks[i];
                block.pixels = pixels;
                block.taken = target;
                block.done = target >= adaptive.max_samples
                    || adaptive.converged(block_error(block.pixels.iter().map(|p| &p.sums), target), target);
                stats.add(&pass_stats);
            }
            taken = target;
            if let Some(progress) = self.progress {
                progress(taken as usize, adaptive.max_samples as usize);
            }
        }

        let (w, h) = (window.width(), window.height());
        let mut film = Film::new(w, h);
        let mut samples_map = CostImage::new(w, h);
        let mut cost = self.record_cost.then(|| CostImage::new(w, h));
        for block in &blocks {
            let Some(inside) = block.area.intersection(&window) else { continue };
            let bw = block.area.width();
            for y in inside.y0..inside.y1 {
                for x in inside.x0..inside.x1 {
                    let p = &block.pixels[((y - block.area.y0) * bw + x - block.area.x0) as usize];
                    let (fx, fy) = (x - window.x0, y - window.y0);
                    if block.taken > 0 {
                        film.set(fx, fy, p.sums.mean(block.taken));
                    } else {
                        film.set(fx, fy, Vec3::ZERO);
                    }
                    samples_map.set(fx, fy, block.taken as u64);
                    if let Some(cost) = cost.as_mut() {
                        cost.set(fx, fy, p.cost);
                    }
                }
            }
        }
        let complete = blocks.iter().all(|b| b.done);
        let tiles = (w.div_ceil(TILE_SIZE) * h.div_ceil(TILE_SIZE)) as usize;
        RenderOutput {
            film,
            window,
            stats,
            complete,
            tiles_done: if complete { tiles } else { 0 },
            samples_done: taken,
            seconds: start.elapsed().as_secs_f64(),
            cost,
            samples_map: Some(samples_map),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_cover_a_window_on_the_image_s_grid() {
        // Rows 5..13 of a 20 x 18 image: block rows 0..8 and 8..16, three blocks a row, the last
        // 4 pixels wide.
        let blocks = covering_blocks(PixelWindow { x0: 0, x1: 20, y0: 5, y1: 13 }, 20, 18);
        assert_eq!(blocks.len(), 6);
        assert_eq!(blocks[0], PixelWindow { x0: 0, x1: 8, y0: 0, y1: 8 });
        assert_eq!(blocks[2], PixelWindow { x0: 16, x1: 20, y0: 0, y1: 8 });
        assert_eq!(blocks[5], PixelWindow { x0: 16, x1: 20, y0: 8, y1: 16 });
        // The bottom edge is clipped to the image.
        let last = covering_blocks(PixelWindow { x0: 9, x1: 10, y0: 17, y1: 18 }, 20, 18);
        assert_eq!(last, [PixelWindow { x0: 8, x1: 16, y0: 16, y1: 18 }]);
        // The whole image: every pixel in exactly one block.
        let all = covering_blocks(PixelWindow::full(20, 18), 20, 18);
        assert_eq!(all.iter().map(|b| b.area()).sum::<u64>(), 20 * 18);
    }
}
