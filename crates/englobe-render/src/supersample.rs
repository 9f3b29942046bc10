//! Adaptive supersampling (Whitted 1980, "An Improved Illumination Model for Shaded Display",
//! section 4): a pixel is sampled at its four corners first, and a square whose corners differ is
//! cut into four, down to a maximum level, so that samples go where the image changes (edges,
//! reflections of edges) and flat areas cost four rays. "Differ" is Mitchell's contrast (1987,
//! "Generating Antialiased Images at Low Sampling Densities"): for some channel,
//! `(max - min) / (max + min)` above the threshold, which follows how the eye sees differences
//! rather than their absolute size.
//!
//! The positions are fixed (corners, midpoints, centres: no random numbers), and a sample shared by
//! two squares of one pixel is taken once. A pixel's value depends on the pixel alone, as every
//! pixel's in englobe.

use std::collections::HashMap;

use englobe::Vec3;

/// When to cut a square, and how deep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveSupersampling {
    /// Mitchell's contrast above which a square is cut.
    pub contrast: f32,
    /// Most cuts: level `L` squares are `1 / 2^L` of the pixel's side, at most `(2^L + 1)^2`
    /// samples per pixel.
    pub max_level: u32,
}

/// Mitchell's contrast of a set of colours: the largest over the channels of
/// `(max - min) / (max + min)` (0 where a channel is black throughout).
pub fn contrast(colours: &[Vec3]) -> f32 {
    let lo = colours.iter().copied().fold(Vec3::INFINITY, Vec3::min);
    let hi = colours.iter().copied().fold(Vec3::NEG_INFINITY, Vec3::max);
    (0..3)
        .map(|c| {
            let sum = hi[c] + lo[c];
            if sum > 0.0 { (hi[c] - lo[c]) / sum } else { 0.0 }
        })
        .fold(0.0, f32::max)
}

impl AdaptiveSupersampling {
    /// The pixel's value: the mean over its finest squares of their corners' mean, each square
    /// weighted by its area. `sample(dx, dy)` is the colour seen through the point `(dx, dy)` of
    /// the pixel, both in `0..=1`. Returns the value and the number of samples taken.
    pub fn pixel(&self, sample: &mut dyn FnMut(f32, f32) -> Vec3) -> (Vec3, u32) {
        let level = self.max_level.min(12);
        let side = 1u32 << level;
        let mut taken: HashMap<(u32, u32), Vec3> = HashMap::new();
        let mut at = |i: u32, j: u32| {
            *taken.entry((i, j)).or_insert_with(|| sample(i as f32 / side as f32, j as f32 / side as f32))
        };
        let value = self.square(&mut at, 0, 0, side, level);
        (value, taken.len() as u32)
    }

    /// The value of the square of `size` grid steps at `(i, j)`, with `levels` cuts left.
    fn square(&self, at: &mut dyn FnMut(u32, u32) -> Vec3, i: u32, j: u32, size: u32, levels: u32) -> Vec3 {
        let corners = [at(i, j), at(i + size, j), at(i, j + size), at(i + size, j + size)];
        if levels == 0 || contrast(&corners) <= self.contrast {
            return (corners[0] + corners[1] + corners[2] + corners[3]) * 0.25;
        }
        let half = size / 2;
        let quarters = [(i, j), (i + half, j), (i, j + half), (i + half, j + half)];
        quarters.iter().map(|&(a, b)| self.square(at, a, b, half, levels - 1)).sum::<Vec3>() * 0.25
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mitchell_contrast() {
        assert_eq!(contrast(&[Vec3::ONE, Vec3::ONE]), 0.0);
        assert_eq!(contrast(&[Vec3::ZERO, Vec3::ZERO]), 0.0);
        assert_eq!(contrast(&[Vec3::new(1.0, 0.5, 0.0), Vec3::new(3.0, 0.5, 0.0)]), 0.5);
        assert_eq!(contrast(&[Vec3::ZERO, Vec3::new(0.0, 0.0, 0.01)]), 1.0);
    }

    #[test]
    fn a_flat_pixel_costs_four_samples() {
        let s = AdaptiveSupersampling { contrast: 0.1, max_level: 3 };
        let (v, n) = s.pixel(&mut |_, _| Vec3::splat(0.7));
        assert_eq!((v, n), (Vec3::splat(0.7), 4));
    }

    #[test]
    fn an_edge_is_refined_toward_its_exact_coverage() {
        // White left of x = 0.3, black right of it: the pixel's exact value is 0.3.
        let edge = |x: f32, _: f32| if x < 0.3 { Vec3::ONE } else { Vec3::ZERO };
        let mut previous_samples = 0;
        let mut error = f32::INFINITY;
        for level in 1..=6 {
            let s = AdaptiveSupersampling { contrast: 0.1, max_level: level };
            let (v, n) = s.pixel(&mut |x, y| edge(x, y));
            error = (v.x - 0.3).abs();
            // Only the column of squares that straddles the edge, of width 1 / 2^level, is wrong.
            assert!(error <= 1.0 / (1u32 << level) as f32, "level {level}: error {error}");
            assert!(n > previous_samples, "level {level}: {n} samples");
            // Only the column of squares along the edge is cut: far fewer than the full grid.
            let full = ((1u32 << level) + 1).pow(2);
            assert!(level == 1 || n < full, "level {level}: {n} of {full}");
            previous_samples = n;
        }
        assert!(error < 1.0 / 64.0, "{error}");
    }

    #[test]
    fn shared_corners_are_sampled_once_in_fixed_places() {
        let s = AdaptiveSupersampling { contrast: 0.0, max_level: 2 };
        let mut points = Vec::new();
        let (_, n) = s.pixel(&mut |x, y| {
            points.push((x, y));
            Vec3::new(x, y, 0.5 + x * y)
        });
        // Every square is cut: the full 5 x 5 grid, each point once.
        assert_eq!(n, 25);
        assert_eq!(points.len(), 25);
        assert!(points.iter().all(|&(x, y)| (x * 4.0).fract() == 0.0 && (y * 4.0).fract() == 0.0));
    }
}
