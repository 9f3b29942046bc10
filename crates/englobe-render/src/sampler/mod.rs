//! The pixel sampler: where a pixel's random numbers come from.
//!
//! Every integrator draws its numbers through `rand`'s `Rng` trait from a [`PixelSampler`], one
//! per pixel, made from the scene's seed and the pixel alone, and told where each of the pixel's
//! samples starts ([`PixelSampler::start_sample`]); so a number depends on (pixel, sample index,
//! dimension, seed) only, as in pbrt-v4, and images are the same on any number of threads and
//! tiles, by passes or adaptively.
//!
//! - [`SamplerKind::Independent`]: a PCG32 stream per pixel (O'Neill 2014), every number
//!   independent and uniform.
//! - [`SamplerKind::Sobol`]: sample `i` of a pixel is point `i` of an Owen-scrambled Sobol
//!   sequence padded in groups of four dimensions ([`sobol`], Burley 2020), scrambled by a seed of
//!   the pixel: the `n`-th number a sample draws is dimension `n`. Its first `2^m` samples are
//!   stratified in every dimension, which lowers the error of smooth integrands (the pixel
//!   footprint, soft shadows, glossy and diffuse bounces) faster than `1 / spp`.

pub mod sobol;

use std::convert::Infallible;

use englobe_scene::SamplerKind;
use rand::{Rng, SeedableRng, TryRng};
use rand_pcg::Pcg32;

/// The independent sample generator of one pixel: depends on the seed and the pixel only, never
/// on threads.
pub fn pixel_rng(seed: u64, x: u32, y: u32) -> Pcg32 {
    Pcg32::seed_from_u64(pixel_seed(seed, x, y))
}

/// The seed of pixel `(x, y)`'s stream.
fn pixel_seed(seed: u64, x: u32, y: u32) -> u64 {
    seed ^ ((y as u64) << 32 | x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

/// The random numbers of one pixel.
#[derive(Clone, Debug)]
pub enum PixelSampler {
    /// Independent uniform numbers from the pixel's PCG32 stream ([`pixel_rng`]).
    Independent(Pcg32),
    /// The same stream before its first number, seeded when one is drawn: Whitted's integrator
    /// at one sample per pixel draws none, and seeding costs as much as a ray's setup.
    Unseeded(u64),
    /// Owen-scrambled padded Sobol points.
    Sobol(SobolPixel),
}

/// The state of a pixel's Sobol sampler: its scramble seed, the sample being drawn and the next
/// dimension.
#[derive(Clone, Debug)]
pub struct SobolPixel {
    seed: u64,
    next_sample: u32,
    sample: u32,
    dimension: u32,
}

impl PixelSampler {
    /// The sampler of pixel `(x, y)` for the scene's `seed`.
    pub fn new(kind: SamplerKind, seed: u64, x: u32, y: u32) -> PixelSampler {
        match kind {
            SamplerKind::Independent => PixelSampler::Unseeded(pixel_seed(seed, x, y)),
            SamplerKind::Sobol => PixelSampler::Sobol(SobolPixel {
                seed: sobol::mix(sobol::mix(seed) ^ (u64::from(y) << 32 | u64::from(x))),
                next_sample: 0,
                sample: 0,
                dimension: 0,
            }),
        }
    }

    /// The independent stream, seeded now if it was not yet (only for independent samplers).
    #[inline]
    fn seeded(&mut self) -> &mut Pcg32 {
        if let PixelSampler::Unseeded(seed) = *self {
            *self = PixelSampler::Independent(Pcg32::seed_from_u64(seed));
        }
        match self {
            PixelSampler::Independent(rng) => rng,
            _ => unreachable!("only independent samplers have a stream"),
        }
    }

    /// The pixel's next sample begins: its numbers restart at the first dimension. Independent
    /// numbers just go on.
    #[inline]
    pub fn start_sample(&mut self) {
        if let PixelSampler::Sobol(s) = self {
            s.sample = s.next_sample;
            s.next_sample = s.next_sample.wrapping_add(1);
            s.dimension = 0;
        }
    }
}

impl TryRng for PixelSampler {
    type Error = Infallible;

    #[inline]
    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        Ok(match self {
            PixelSampler::Independent(rng) => rng.next_u32(),
            PixelSampler::Unseeded(_) => self.seeded().next_u32(),
            PixelSampler::Sobol(s) => {
                let x = sobol::scrambled_sobol(s.sample, s.dimension, s.seed);
                s.dimension = s.dimension.wrapping_add(1);
                x
            }
        })
    }

    /// Independent: the stream's own. Sobol: one dimension as the high 32 bits (which a float
    /// draws from), hashed low bits below.
    #[inline]
    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        Ok(match self {
            PixelSampler::Independent(rng) => rng.next_u64(),
            PixelSampler::Unseeded(_) => self.seeded().next_u64(),
            PixelSampler::Sobol(s) => {
                let high = u64::from(sobol::scrambled_sobol(s.sample, s.dimension, s.seed));
                let low = sobol::mix(s.seed ^ (u64::from(s.sample) << 32 | u64::from(s.dimension))) >> 32;
                s.dimension = s.dimension.wrapping_add(1);
                high << 32 | low
            }
        })
    }

    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        if let PixelSampler::Independent(_) | PixelSampler::Unseeded(_) = self {
            self.seeded().fill_bytes(dst);
            return Ok(());
        }
        for chunk in dst.chunks_mut(4) {
            let word = self.try_next_u32()?.to_le_bytes();
            chunk.copy_from_slice(&word[..chunk.len()]);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use rand::RngExt;

    use super::*;

    #[test]
    fn independent_numbers_are_the_pixel_stream() {
        let mut a = PixelSampler::new(SamplerKind::Independent, 3, 10, 20);
        let mut b = pixel_rng(3, 10, 20);
        for _ in 0..10 {
            a.start_sample();
            assert_eq!(a.random::<f32>(), b.random::<f32>());
            assert_eq!(a.random::<f64>(), b.random::<f64>());
        }
    }

    #[test]
    fn sobol_numbers_depend_on_pixel_sample_and_dimension_only() {
        let draw = |x: u32, y: u32, samples: u32| {
            let mut s = PixelSampler::new(SamplerKind::Sobol, 5, x, y);
            let mut last = Vec::new();
            for k in 0..samples {
                s.start_sample();
                // Samples draw different numbers of dimensions, as paths do.
                last = (0..3 + k % 5).map(|_| s.random::<f32>()).collect();
            }
            last
        };
        assert_eq!(draw(1, 2, 9), draw(1, 2, 9));
        assert_ne!(draw(1, 2, 9), draw(2, 1, 9));
        assert_ne!(draw(1, 2, 9), draw(1, 2, 8));
        // Sample 8, dimension 2, is the sequence's point whatever came before.
        let mut s = PixelSampler::new(SamplerKind::Sobol, 5, 1, 2);
        for _ in 0..9 {
            s.start_sample();
        }
        let PixelSampler::Sobol(state) = &s else { unreachable!() };
        let expected = sobol::scrambled_sobol(8, 2, state.seed) >> 8;
        assert_eq!(draw(1, 2, 9)[2], expected as f32 / (1 << 24) as f32);
    }

    #[test]
    fn a_pixels_first_samples_are_stratified() {
        // 16 samples of one dimension: one in each sixteenth of [0, 1).
        let mut s = PixelSampler::new(SamplerKind::Sobol, 0, 4, 4);
        let mut cells: Vec<u32> = (0..16)
            .map(|_| {
                s.start_sample();
                let _ = s.random::<f32>();
                (s.random::<f32>() * 16.0) as u32
            })
            .collect();
        cells.sort_unstable();
        assert!(cells.iter().copied().eq(0..16), "{cells:?}");
    }
}
