//! The noise estimate of adaptive sampling and its schedule: how much error a block of pixels
//! still holds, when it stops, and how many samples each pass brings.
//!
//! **The estimator** is the one of Dammertz, Hanika, Keller and Lensch (2010, "A Hierarchical
//! Automatic Stopping Condition for Monte Carlo Global Illumination", WSCG, section 2.1), as
//! Blender's Cycles computes it (`kernel/film/adaptive_sampling.h`): every pixel keeps the sum of
//! all its samples and the sum of its even-numbered ones (0, 2, 4, ...), two independent
//! half-buffers `A` and `B` of the same pixel. Their means differ by noise alone, so
//!
//! ```text
//! error(p) = (|A_r - B_r| + |A_g - B_g| + |A_b - B_b|) / 2  /  (0.0001 + n(I_r + I_g + I_b))
//! n(i) = sqrt(i) for i < 1, i above
//! ```
//!
//! (`I` the mean of all samples) estimates the pixel's remaining standard error relative to the
//! square root of its brightness: dark pixels need less absolute precision than bright ones, as
//! the eye and the sRGB curve do, and over-exposed ones (`i >= 1`) less again. The half-buffer
//! difference is the idea of Rousselle, Knaus and Zwicker (2012, "Adaptive Rendering with
//! Non-Local Means Filtering") as well: it needs no sample variance and holds for any integrator.
//!
//! One change to Cycles: the half-buffers hold the samples as the film shows them, each channel
//! clamped to `0..=1` (see [`crate::film::Film::to_srgb8`]), while the image keeps the samples
//! themselves. Where the film saturates, the noise of the linear values does not show: the outline
//! of a lamp (samples of the emitter, dozens of times the display's white, beside samples of a
//! dim ceiling) has a relative variance near one in linear values and would take every sample up
//! to the maximum for a difference no one sees. If the film gains an exposure or a tone curve, the
//! clamp should follow it.
//!
//! **Blocks, not pixels.** One pixel's `|A - B|` is a single draw of a noisy quantity: a pixel
//! whose halves agree by chance would stop long before it is smooth (Cycles answers with a
//! minimum of samples and by waking a stopped pixel's neighbours). englobe decides per block of
//! [`BLOCK_SIZE`] x [`BLOCK_SIZE`] pixels, aligned to the image, on the mean of its pixels'
//! errors, as Dammertz et al. measure the error over blocks of the image: the mean of 64 draws
//! fluctuates about eight times less than one, a stopped block leaves no pepper of under-sampled
//! pixels inside smooth areas, and 8 x 8 blocks still follow the image's structure (a 256-pixel
//! image has 1 024 of them). A block's decision reads its own pixels only, so any window of the
//! image rendered with the blocks that cover it gets the pixels of the whole render.
//!
//! **The schedule**: a first pass of `min_samples` everywhere (the estimate is meaningless on a
//! handful of samples, and rare bright paths need a chance to show), then passes that add a
//! quarter of the samples taken so far (16, 20, 25, 32, 40, 50, ...), up to `samples`. Geometric
//! steps keep the number of looks at the estimate small (each look is a chance to stop on an
//! unlucky low estimate: 20 passes from 16 to 1 024 samples) while a block stops within 1.25 times
//! the samples it needed (1.12 times on average), which is most of what adaptive sampling saves
//! where noise is even.

use englobe::Vec3;
use englobe_scene::{ImageSettings, NoiseAllocation};

/// Side of the blocks that stop together, in pixels (the image's blocks start at its corner).
pub const BLOCK_SIZE: u32 = 8;

/// Samples of the first pass when the scene does not set `min_samples`, as Cycles chooses them
/// (`Integrator::get_adaptive_sampling`): `16 / threshold^0.3`, at least 4 (32 at 0.1, 64 at
/// 0.01, 128 at 0.001), since a finer threshold needs a steadier first estimate; at most
/// `samples`.
pub fn default_min_samples(threshold: f32, samples: u32) -> u32 {
    let cycles = (16.0 / threshold.powf(0.3)).ceil();
    (if cycles.is_finite() { cycles.min(u32::MAX as f32) as u32 } else { u32::MAX }).max(4).min(samples)
}

/// Added to the error's divisor, as in Cycles, so that black pixels divide by no zero.
const EPSILON: f32 = 1e-4;

/// When to stop sampling a block, and the bounds of its samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveSampling {
    /// A block stops once its error (see the module's documentation) falls under this, or under
    /// this times `sqrt(n / min_samples)` with the `mse` allocation.
    pub threshold: f32,
    /// How the samples are shared (see [`AdaptiveSampling::converged`]).
    pub allocation: NoiseAllocation,
    /// Samples every pixel takes before any block may stop (2 at least).
    pub min_samples: u32,
    /// Samples no pixel goes beyond.
    pub max_samples: u32,
}

impl AdaptiveSampling {
    /// The adaptive sampling `image` asks for when a render takes up to `samples` per pixel:
    /// `None` when its `noise_threshold` is 0 or a pixel takes one sample only.
    pub fn of(image: &ImageSettings, samples: u32) -> Option<Self> {
        if !(image.noise_threshold > 0.0) || samples < 2 {
            return None;
        }
        let min = image.min_samples.unwrap_or_else(|| default_min_samples(image.noise_threshold, samples));
        Some(AdaptiveSampling {
            threshold: image.noise_threshold,
            allocation: image.noise_allocation,
            min_samples: min.clamp(2, samples),
            max_samples: samples,
        })
    }

    /// Samples per pixel after the pass that follows `taken` (0 before the first pass): the
    /// minimum, then a quarter more each pass, at most the maximum.
    pub fn next_total(&self, taken: u32) -> u32 {
        if taken == 0 { self.min_samples } else { taken.saturating_add(taken.div_ceil(4)).min(self.max_samples) }
    }

    /// Whether a block with this error (the mean of its pixels' errors) after `n` samples per
    /// pixel has converged. NaN (a sample that was not a number) never converges, so such a
    /// block takes every sample.
    ///
    /// `even`: the error is under the threshold `T`. `mse`: a block's error is `s / sqrt(n)` for
    /// a noise `s` of its own, so one more sample lowers its squared error by about
    /// `s^2 / n^2 = error^2 / n`; the block stops once that falls under what a block at the
    /// threshold after the first pass would gain, `T^2 / min_samples`, that is once
    /// `error < T sqrt(n / min_samples)`. Blocks then end with `n` proportional to `s`, which is
    /// the split of a number of samples that minimises the sum of squared errors (Lagrange: the
    /// gain of the last sample is the same everywhere), where `even`'s `n` grows as `s^2` and
    /// gives the same squared error as uniform sampling wherever no block stops at the first
    /// pass or at the maximum.
    pub fn converged(&self, block_error: f32, n: u32) -> bool {
        match self.allocation {
            NoiseAllocation::Even => block_error < self.threshold,
            NoiseAllocation::Mse => block_error < self.threshold * (n as f32 / self.min_samples.max(1) as f32).sqrt(),
        }
    }
}

/// What a pixel keeps of its samples: the sum of all of them, in the order they were taken (so
/// that their mean is bit for bit a uniform render's), and the two half-buffers of the estimate,
/// as the film shows the samples (each channel clamped to `0..=1`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HalfSums {
    /// Every sample added, as it is.
    pub all: Vec3,
    /// The samples of even number (the first, the third, ...), as shown: half-buffer `A`.
    pub even: Vec3,
    /// The samples of odd number, as shown: half-buffer `B`.
    pub odd: Vec3,
}

impl HalfSums {
    /// Adds sample number `index` (from 0).
    #[inline]
    pub fn add(&mut self, index: u32, value: Vec3) {
        self.all += value;
        let shown = value.clamp(Vec3::ZERO, Vec3::ONE);
        if index % 2 == 0 {
            self.even += shown;
        } else {
            self.odd += shown;
        }
    }

    /// The pixel's value after `n` samples: their mean.
    pub fn mean(&self, n: u32) -> Vec3 {
        self.all / n as f32
    }

    /// The pixel's relative error after `n >= 2` samples (see the module's documentation).
    pub fn error(&self, n: u32) -> f32 {
        debug_assert!(n >= 2, "two halves need two samples");
        let (n_a, n_b) = (n.div_ceil(2) as f32, (n / 2) as f32);
        let (a, b) = (self.even / n_a, self.odd / n_b);
        let d = (a - b).abs();
        let difference = (d.x + d.y + d.z) * 0.5;
        let mean = (self.even + self.odd) / n as f32;
        let intensity = mean.x + mean.y + mean.z;
        let normalise = if intensity < 1.0 { intensity.max(0.0).sqrt() } else { intensity };
        difference / (EPSILON + normalise)
    }
}

/// The mean of the errors of a block's pixels, each after `n` samples.
pub fn block_error<'a>(pixels: impl IntoIterator<Item = &'a HalfSums>, n: u32) -> f32 {
    let (mut sum, mut count) = (0.0f64, 0u32);
    for p in pixels {
        sum += p.error(n) as f64;
        count += 1;
    }
    if count == 0 { 0.0 } else { (sum / count as f64) as f32 }
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;

    fn settings(threshold: f32, min_samples: Option<u32>) -> ImageSettings {
        let scene = englobe_scene::parse_scene(crate::DEFAULT_SCENE, "default.toml".as_ref()).unwrap();
        ImageSettings { noise_threshold: threshold, min_samples, ..scene.image }
    }

    #[test]
    fn off_without_a_threshold_or_with_one_sample() {
        assert_eq!(AdaptiveSampling::of(&settings(0.0, None), 64), None);
        assert_eq!(AdaptiveSampling::of(&settings(0.01, None), 1), None);
        let a = AdaptiveSampling::of(&settings(0.01, None), 1024).unwrap();
        assert_eq!((a.min_samples, a.max_samples), (64, 1024), "16 / 0.01^0.3 = 63.7");
        // Cycles' comment: 0.1 gives 32, 0.001 gives 128; 0.05 gives 16 / 0.407 = 39.3.
        let min = |t: f32, samples: u32| AdaptiveSampling::of(&settings(t, None), samples).unwrap().min_samples;
        assert_eq!((min(0.1, 4096), min(0.001, 4096), min(0.05, 4096)), (32, 128, 40));
        assert_eq!((min(1000.0, 4096), min(1e-30, 65536)), (4, 65536), "at least 4, at most the maximum");
        assert_eq!(min(0.01, 8), 8, "at most the maximum");
        assert_eq!(AdaptiveSampling::of(&settings(0.01, Some(4)), 64).unwrap().min_samples, 4);
    }

    #[test]
    fn passes_grow_by_a_quarter_up_to_the_maximum() {
        let a =
            AdaptiveSampling { threshold: 0.01, allocation: NoiseAllocation::Even, min_samples: 16, max_samples: 100 };
        let mut totals = vec![];
        let mut taken = 0;
        while taken < a.max_samples {
            taken = a.next_total(taken);
            totals.push(taken);
        }
        assert_eq!(totals, [16, 20, 25, 32, 40, 50, 63, 79, 99, 100]);
        let two =
            AdaptiveSampling { threshold: 0.01, allocation: NoiseAllocation::Even, min_samples: 2, max_samples: 5 };
        assert_eq!((two.next_total(0), two.next_total(2), two.next_total(4), two.next_total(5)), (2, 3, 5, 5));
    }

    #[test]
    fn the_mse_allocation_relaxes_the_threshold_as_the_root_of_the_samples() {
        let even =
            AdaptiveSampling { threshold: 0.02, allocation: NoiseAllocation::Even, min_samples: 16, max_samples: 4096 };
        let mse = AdaptiveSampling { allocation: NoiseAllocation::Mse, ..even };
        // At the first pass both ask for the threshold.
        assert_eq!((even.converged(0.0199, 16), mse.converged(0.0199, 16)), (true, true));
        assert_eq!((even.converged(0.0201, 16), mse.converged(0.0201, 16)), (false, false));
        // At 64 samples (four times the first pass) mse accepts twice the threshold.
        assert_eq!((even.converged(0.039, 64), mse.converged(0.039, 64)), (false, true));
        assert!(!mse.converged(0.041, 64));
        // A block of noise s stops where s / sqrt(n) < T sqrt(n / 16): n > 4 s / T. Twice the
        // noise, twice the samples (even: four times).
        let stop = |a: &AdaptiveSampling, s: f32| (16..4096).find(|&n| a.converged(s / (n as f32).sqrt(), n)).unwrap();
        let (n1, n2) = (stop(&mse, 0.2), stop(&mse, 0.4));
        assert!((n2 as f32 / n1 as f32 - 2.0).abs() < 0.05, "{n1} {n2}");
        let (e1, e2) = (stop(&even, 0.2), stop(&even, 0.4));
        assert!((e2 as f32 / e1 as f32 - 4.0).abs() < 0.05, "{e1} {e2}");
    }

    #[test]
    fn the_error_by_hand() {
        // Samples 0.1, 0.3 (grey): A = 0.1, B = 0.3, mean 0.2 per channel, so the error is
        // 3 * 0.2 / 2 / sqrt(0.6).
        let mut p = HalfSums::default();
        p.add(0, Vec3::splat(0.1));
        p.add(1, Vec3::splat(0.3));
        let expected = 0.3 / (1e-4 + 0.6f32.sqrt());
        assert!((p.error(2) - expected).abs() < 1e-6, "{}", p.error(2));
        // Above 1 the division is by the intensity itself: samples 0.6 and 1.0 grey have a mean
        // intensity of 2.4 and a difference of 3 * 0.4 / 2.
        let mut bright = HalfSums::default();
        bright.add(0, Vec3::splat(0.6));
        bright.add(1, Vec3::splat(1.0));
        assert!((bright.error(2) - 0.6 / (1e-4 + 2.4)).abs() < 1e-6, "{}", bright.error(2));
        // The halves hold what the film shows: beyond white, no difference, whatever the image's
        // values (which the mean keeps).
        let mut lamp = HalfSums::default();
        lamp.add(0, Vec3::splat(3.0));
        lamp.add(1, Vec3::splat(40.0));
        assert_eq!((lamp.error(2), lamp.mean(2)), (0.0, Vec3::splat(21.5)));
        // Identical halves, and black: no error.
        let mut flat = HalfSums::default();
        (0..6).for_each(|i| flat.add(i, Vec3::splat(0.3)));
        assert_eq!(flat.error(6), 0.0);
        assert_eq!(HalfSums::default().error(4), 0.0);
        let even =
            AdaptiveSampling { threshold: 1.0, allocation: NoiseAllocation::Even, min_samples: 2, max_samples: 2 };
        assert!(!even.converged(f32::NAN, 2));
        assert!(!AdaptiveSampling { allocation: NoiseAllocation::Mse, ..even }.converged(f32::NAN, 2));
    }

    #[test]
    fn the_error_falls_as_one_over_the_root_of_the_samples() {
        // Uniform noise on [0, 0.2] over many pixels: the mean error at 4n samples is half the
        // error at n, and it is the standard error of the mean, sigma / sqrt(n), times the mean
        // of |Z| (sqrt(2 / pi)), times 3 (three channels), over sqrt(3 * 0.1) (the normalisation).
        let mut rng = Pcg32::seed_from_u64(7);
        let mut error_at = |n: u32| {
            let pixels: Vec<HalfSums> = (0..4000)
                .map(|_| {
                    let mut p = HalfSums::default();
                    (0..n).for_each(|i| p.add(i, Vec3::splat(0.2 * rng.random::<f32>())));
                    p
                })
                .collect();
            block_error(&pixels, n)
        };
        let (e16, e64) = (error_at(16), error_at(64));
        assert!((e16 / e64 - 2.0).abs() < 0.1, "{e16} / {e64}");
        let sigma = 0.2 / 12f32.sqrt();
        let predicted = 3.0 * (2.0 / std::f32::consts::PI).sqrt() * sigma / 16f32.sqrt() / 0.3f32.sqrt();
        assert!((e16 / predicted - 1.0).abs() < 0.05, "{e16} against {predicted}");
    }
}
