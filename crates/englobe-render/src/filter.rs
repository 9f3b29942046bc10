//! Pixel filters by importance sampling (Ernst, Stamminger and Greiner 2006, "Filter Importance
//! Sampling"; pbrt-v4, section 8.8): instead of weighting each sample by the filter at its offset,
//! the offset itself is drawn with the filter's shape as its density, so that every sample of a
//! positive filter weighs the same and a pixel is the plain mean of its samples. A pixel's value
//! still depends on its own samples only, so tiles and threads give the same bytes.
//!
//! The filters are separable: each axis is drawn from its own one-dimensional shape.
//! - box of radius `r`: uniform; for `r = 1/2` the offset is the uniform number itself, so the
//!   default reproduces the renderer's earlier jitter over the pixel bit for bit;
//! - triangle (tent) `max(0, r - |x|)`: the exact inverse of its quadratic distribution function;
//! - Gaussian `max(0, g(x) - g(r))` (pbrt-v4's, lowered to reach zero at the radius): a table of
//!   the inverse distribution function (256 intervals), refined by Newton's method on the exact
//!   distribution function, written with the error function, so that offsets follow the shape
//!   to double precision rather than to the table's.

use englobe_scene::PixelFilter;

/// Intervals of the Gaussian's inverse distribution table.
const TABLE: usize = 256;

/// How a pixel filter draws sample offsets.
#[derive(Clone, Debug)]
pub struct FilterSampler {
    x: Axis,
    y: Axis,
}

#[derive(Clone, Debug)]
enum Axis {
    Box { radius: f32 },
    Tent { radius: f32 },
    Gaussian(Box<GaussianAxis>),
}

impl FilterSampler {
    /// The sampler of `filter` (checked by the scene loader: radii in `(0, 16]`, sigma positive).
    pub fn new(filter: &PixelFilter) -> Self {
        let r = filter.radius();
        let axis = |radius: f32| match *filter {
            PixelFilter::Box { .. } => Axis::Box { radius },
            PixelFilter::Triangle { .. } => Axis::Tent { radius },
            PixelFilter::Gaussian { sigma, .. } => Axis::Gaussian(Box::new(GaussianAxis::new(radius, sigma))),
        };
        FilterSampler { x: axis(r.x), y: axis(r.y) }
    }

    /// The point a sample goes through, in pixels from the pixel's top-left corner (its centre is
    /// `(0.5, 0.5)`), from two uniform numbers in `[0, 1)`.
    #[inline]
    pub fn sample(&self, u: f32, v: f32) -> (f32, f32) {
        (self.x.position(u), self.y.position(v))
    }
}

impl Axis {
    /// `0.5 + offset`, the offset drawn from the axis's shape.
    #[inline]
    fn position(&self, u: f32) -> f32 {
        match self {
            // Written so that r = 0.5 gives `0 + 1 * u`, exactly `u`.
            Axis::Box { radius } => (0.5 - radius) + (2.0 * radius) * u,
            Axis::Tent { radius } => 0.5 + tent_offset(u, *radius),
            Axis::Gaussian(g) => 0.5 + g.offset(u as f64) as f32,
        }
    }
}

/// An offset with density `max(0, r - |x|) / r²`: the inverse of its distribution function,
/// `(x + r)² / (2 r²)` below 0 and symmetric above.
fn tent_offset(u: f32, r: f32) -> f32 {
    if u < 0.5 { r * ((2.0 * u).sqrt() - 1.0) } else { r * (1.0 - (2.0 - 2.0 * u).max(0.0).sqrt()) }
}

/// One axis of the Gaussian filter: its shape `g(x) - g(r)` on `[-r, r]`, the distribution function
/// of that shape, and the table of its inverse.
#[derive(Clone, Debug)]
struct GaussianAxis {
    radius: f64,
    sigma: f64,
    /// `g(r)`, subtracted from the Gaussian.
    edge: f64,
    /// The shape's integral over `[-r, r]`.
    total: f64,
    /// `inverse[k]` is the offset below which a fraction `k / TABLE` of the shape lies.
    inverse: Vec<f64>,
}

impl GaussianAxis {
    fn new(radius: f32, sigma: f32) -> Self {
        let (radius, sigma) = (radius as f64, sigma as f64);
        let mut g = GaussianAxis { radius, sigma, edge: 0.0, total: 0.0, inverse: Vec::new() };
        g.edge = g.gaussian(radius);
        g.total = g.cdf(radius);
        g.inverse = (0..=TABLE)
            .map(|k| {
                let target = g.total * k as f64 / TABLE as f64;
                let (mut lo, mut hi) = (-radius, radius);
                for _ in 0..64 {
                    let mid = 0.5 * (lo + hi);
                    if g.cdf(mid) < target { lo = mid } else { hi = mid }
                }
                0.5 * (lo + hi)
            })
            .collect();
        g
    }

    fn gaussian(&self, x: f64) -> f64 {
        (-x * x / (2.0 * self.sigma * self.sigma)).exp()
    }

    /// The shape at `x` (unnormalised).
    fn shape(&self, x: f64) -> f64 {
        if x.abs() <= self.radius { (self.gaussian(x) - self.edge).max(0.0) } else { 0.0 }
    }

    /// The shape's integral from `-r` to `x`.
    fn cdf(&self, x: f64) -> f64 {
        let x = x.clamp(-self.radius, self.radius);
        let s = self.sigma * std::f64::consts::SQRT_2;
        let half = self.sigma * (std::f64::consts::PI / 2.0).sqrt();
        half * (erf(x / s) + erf(self.radius / s)) - self.edge * (x + self.radius)
    }

    /// The offset of uniform number `u`: the table's interval, then Newton's method kept inside it
    /// (the distribution function increases, so the root lies in the interval).
    fn offset(&self, u: f64) -> f64 {
        let s = (u.clamp(0.0, 1.0) * TABLE as f64).min(TABLE as f64 - 1e-9);
        let k = s as usize;
        let (lo, hi) = (self.inverse[k], self.inverse[k + 1]);
        let target = u * self.total;
        let mut x = lo + (hi - lo) * (s - k as f64);
        // Quadratic convergence where the shape is not near zero (two steps); near the radius,
        // where it vanishes, a few more.
        for _ in 0..12 {
            let density = self.shape(x);
            if !(density > 1e-300) {
                break;
            }
            let next = (x - (self.cdf(x) - target) / density).clamp(lo, hi);
            let done = (next - x).abs() < 1e-13;
            x = next;
            if done {
                break;
            }
        }
        x
    }
}

/// The error function, to about 1e-15: its Maclaurin series below 2.5, the continued fraction
/// of `erfc` (Abramowitz and Stegun 7.1.14) above.
pub(crate) fn erf(x: f64) -> f64 {
    let z = x.abs();
    let value = if z < 2.5 {
        let (mut term, mut sum) = (z, z);
        for n in 1..200 {
            term *= -z * z / n as f64;
            let add = term / (2 * n + 1) as f64;
            sum += add;
            if add.abs() < 1e-17 * sum.abs() {
                break;
            }
        }
        sum * 2.0 / std::f64::consts::PI.sqrt()
    } else {
        let mut t = z;
        for k in (1..=160).rev() {
            t = z + (k as f64 / 2.0) / t;
        }
        1.0 - (-z * z).exp() / (std::f64::consts::PI.sqrt() * t)
    };
    value.copysign(x)
}

#[cfg(test)]
mod tests {
    use englobe::Vec2;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;

    #[test]
    fn the_error_function_matches_its_tables() {
        // Abramowitz and Stegun, table 7.1, and erf(-x) = -erf(x).
        for (x, e) in [
            (0.0, 0.0),
            (0.5, 0.520_499_877_813_046_5),
            (1.0, 0.842_700_792_949_714_9),
            (2.0, 0.995_322_265_018_952_7),
            (2.5, 0.999_593_047_982_555),
            (3.0, 0.999_977_909_503_001_4),
            (4.0, 0.999_999_984_582_742_1),
        ] {
            assert!((erf(x) - e).abs() < 1e-14, "erf({x}) = {} not {e}", erf(x));
            assert!((erf(-x) + e).abs() < 1e-14);
        }
    }

    #[test]
    fn the_default_box_draws_the_uniform_numbers_themselves() {
        // The renderer jittered samples with (u, v) before filters existed: the default filter
        // must give those very numbers, so that images are unchanged to the bit.
        let f = FilterSampler::new(&PixelFilter::default());
        let mut rng = Pcg32::seed_from_u64(7);
        for _ in 0..100_000 {
            let (u, v): (f32, f32) = (rng.random(), rng.random());
            let (x, y) = f.sample(u, v);
            assert_eq!((x.to_bits(), y.to_bits()), (u.to_bits(), v.to_bits()), "u {u}, v {v}");
        }
        for u in [0.0, f32::EPSILON, 0.25, 0.5, 1.0 - f32::EPSILON / 2.0] {
            assert_eq!(f.sample(u, u).0.to_bits(), u.to_bits());
        }
    }

    /// The distribution function of filter `f`'s offset on the x axis, in closed form (the
    /// Gaussian's through the error function).
    fn distribution(f: &PixelFilter) -> impl Fn(f64) -> f64 {
        let r = f.radius().x as f64;
        let gaussian = match *f {
            PixelFilter::Gaussian { sigma, .. } => Some(GaussianAxis::new(r as f32, sigma)),
            _ => None,
        };
        let f = *f;
        move |x: f64| -> f64 {
            let x = x.clamp(-r, r);
            match (f, &gaussian) {
                (PixelFilter::Box { .. }, _) => (x + r) / (2.0 * r),
                (PixelFilter::Triangle { .. }, _) if x < 0.0 => (x + r).powi(2) / (2.0 * r * r),
                (PixelFilter::Triangle { .. }, _) => 1.0 - (r - x).powi(2) / (2.0 * r * r),
                (_, Some(g)) => g.cdf(x) / g.total,
                (_, None) => unreachable!("a Gaussian has its axis"),
            }
        }
    }

    /// Pearson's chi-square of `n` offsets of `f` against its shape, in `bins` equal bins over
    /// `[-r, r]`, with the largest distance between the empirical and the exact distribution
    /// functions (Kolmogorov's statistic times sqrt(n)).
    fn fit(f: &PixelFilter, n: usize, bins: usize) -> (f64, f64) {
        let sampler = FilterSampler::new(f);
        let cdf = distribution(f);
        let r = f.radius().x as f64;
        let mut rng = Pcg32::seed_from_u64(2024);
        let mut counts = vec![0usize; bins];
        let mut offsets = Vec::with_capacity(n);
        for _ in 0..n {
            let (x, y) = sampler.sample(rng.random(), rng.random());
            let (ox, oy) = (x as f64 - 0.5, y as f64 - 0.5);
            assert!(ox.abs() <= r + 1e-6 && oy.abs() <= f.radius().y as f64 + 1e-6, "offset ({ox}, {oy})");
            let bin = (((ox + r) / (2.0 * r)) * bins as f64).floor().clamp(0.0, bins as f64 - 1.0) as usize;
            counts[bin] += 1;
            offsets.push(ox);
        }
        let width = 2.0 * r / bins as f64;
        let chi2 = counts
            .iter()
            .enumerate()
            .map(|(i, &c)| {
                let a = -r + i as f64 * width;
                let e = n as f64 * (cdf(a + width) - cdf(a));
                (c as f64 - e).powi(2) / e
            })
            .sum();
        offsets.sort_by(f64::total_cmp);
        let ks = offsets
            .iter()
            .enumerate()
            .map(|(i, &x)| {
                let exact = cdf(x);
                (exact - i as f64 / n as f64).abs().max((exact - (i + 1) as f64 / n as f64).abs())
            })
            .fold(0.0, f64::max);
        (chi2, ks * (n as f64).sqrt())
    }

    #[test]
    fn offsets_follow_each_filters_shape() {
        // 30 bins: 29 degrees of freedom, whose chi-square exceeds 58.3 with probability 1e-3;
        // Kolmogorov's sqrt(n) D exceeds 1.95 with probability 1e-3.
        for f in [
            PixelFilter::Box { radius: Vec2::new(0.5, 0.5) },
            PixelFilter::Box { radius: Vec2::new(1.5, 0.7) },
            PixelFilter::Triangle { radius: Vec2::new(1.0, 1.0) },
            PixelFilter::Triangle { radius: Vec2::new(2.0, 0.5) },
            PixelFilter::Gaussian { radius: Vec2::new(1.5, 1.5), sigma: 0.5 },
            PixelFilter::Gaussian { radius: Vec2::new(3.0, 2.0), sigma: 0.4 },
            PixelFilter::Gaussian { radius: Vec2::new(1.0, 1.0), sigma: 2.0 },
        ] {
            let (chi2, ks) = fit(&f, 200_000, 30);
            assert!(chi2 < 58.3, "{f:?}: chi-square {chi2}");
            assert!(ks < 1.95, "{f:?}: Kolmogorov {ks}");
        }
    }

    #[test]
    fn a_wrong_shape_fails_the_same_test() {
        // The test has the power to see a mistake: tent offsets judged as a box's, or a Gaussian
        // of sigma 0.5 judged as one of sigma 0.6.
        let tent = PixelFilter::Triangle { radius: Vec2::splat(1.0) };
        let sampler = FilterSampler::new(&tent);
        let mut rng = Pcg32::seed_from_u64(1);
        let mut counts = [0usize; 10];
        for _ in 0..20_000 {
            let x = sampler.sample(rng.random(), 0.5).0 as f64 - 0.5;
            counts[(((x + 1.0) / 2.0) * 10.0).floor().clamp(0.0, 9.0) as usize] += 1;
        }
        let chi2: f64 = counts.iter().map(|&c| (c as f64 - 2000.0).powi(2) / 2000.0).sum();
        assert!(chi2 > 1000.0, "{chi2}");
        let a = GaussianAxis::new(1.5, 0.5);
        let b = GaussianAxis::new(1.5, 0.6);
        let worst = (0..=100).map(|i| -1.5 + 0.03 * i as f64).map(|x| (a.cdf(x) / a.total - b.cdf(x) / b.total).abs());
        assert!(worst.fold(0.0, f64::max) > 0.02);
    }

    #[test]
    fn gaussian_offsets_invert_the_distribution_function() {
        let g = GaussianAxis::new(1.5, 0.5);
        for i in 0..=1000 {
            let u = i as f64 / 1000.0;
            let x = g.offset(u);
            assert!((g.cdf(x) / g.total - u).abs() < 1e-9, "u {u}: x {x}");
        }
        assert!((g.offset(0.5)).abs() < 1e-9);
    }
}
