//! Piecewise-constant distributions in one and two dimensions, sampled by inverting their
//! cumulative distribution (Pharr, Jakob and Humphreys, "Physically Based Rendering", 3rd ed.,
//! section 13.6.7, "Piecewise-Constant 1D Functions", and section 13.6.7's 2D extension:
//! "Sampling piecewise-constant 2D distributions"; 4th ed., sections A.4.2 and A.5).
//!
//! A 1D distribution of `n` values `f[i]` has the density `f[i] / integral` on `[i/n, (i+1)/n)`
//! of `[0, 1)`, with `integral = sum(f) / n`. The 2D one over `[0, 1)^2` samples a row `v` from the
//! marginal distribution of the rows' integrals, then `u` from that row's own distribution; its
//! density is `f[row][column] / integral`.

/// A piecewise-constant density over `[0, 1)`.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    func: Vec<f32>,
    /// `cdf[i]` is the probability of `[0, i/n)`; `cdf[n] = 1`.
    cdf: Vec<f32>,
    integral: f32,
}

impl Distribution1D {
    /// The distribution proportional to `func` (values at least 0 and finite; others count as 0).
    /// All zero, or empty: the integral is 0, [`Distribution1D::sample`] is uniform and every
    /// density 0, so that callers can tell there is nothing to sample.
    pub fn new(func: &[f32]) -> Self {
        let func: Vec<f32> = func.iter().map(|&f| if f.is_finite() && f > 0.0 { f } else { 0.0 }).collect();
        let n = func.len();
        let mut cdf = Vec::with_capacity(n + 1);
        // Sums in f64: a map's row has a thousand values of very different sizes.
        let mut sum = 0.0f64;
        cdf.push(0.0f64);
        for &f in &func {
            sum += f as f64 / n as f64;
            cdf.push(sum);
        }
        let cdf = if sum > 0.0 {
            cdf.iter().map(|&c| (c / sum) as f32).collect()
        } else {
            (0..=n).map(|i| i as f32 / n.max(1) as f32).collect()
        };
        Distribution1D { func, cdf, integral: sum as f32 }
    }

    /// Number of pieces.
    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// True if there are no pieces.
    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// The integral of the function over `[0, 1)` (the mean of its values).
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// The value of piece `i`.
    pub fn value(&self, i: usize) -> f32 {
        self.func[i]
    }

    /// A point of `[0, 1)` from a uniform number `u` in `[0, 1)`, its density, and its piece.
    pub fn sample(&self, u: f32) -> (f32, f32, usize) {
        let n = self.func.len();
        // The last piece whose start is at most u, among those of non-zero width.
        let i = self.cdf.partition_point(|&c| c <= u).saturating_sub(1).min(n.saturating_sub(1));
        let width = self.cdf[i + 1] - self.cdf[i];
        let du = if width > 0.0 { ((u - self.cdf[i]) / width).clamp(0.0, 1.0) } else { 0.0 };
        let x = ((i as f32 + du) / n as f32).min(1.0 - f32::EPSILON / 2.0);
        (x, self.pdf_of(i), i)
    }

    /// The density at `x` in `[0, 1)` (values outside are clamped to it).
    pub fn pdf(&self, x: f32) -> f32 {
        self.pdf_of(self.piece(x))
    }

    /// The piece that holds `x`.
    pub fn piece(&self, x: f32) -> usize {
        let n = self.func.len();
        ((x * n as f32) as isize).clamp(0, n as isize - 1) as usize
    }

    fn pdf_of(&self, i: usize) -> f32 {
        if self.integral > 0.0 { self.func[i] / self.integral } else { 0.0 }
    }
}

/// A piecewise-constant density over `[0, 1)^2`: `width` columns (u) by `height` rows (v).
#[derive(Clone, Debug)]
pub struct Distribution2D {
    /// One distribution over u per row.
    rows: Vec<Distribution1D>,
    /// The distribution of the rows, by their integrals.
    marginal: Distribution1D,
}

impl Distribution2D {
    /// The distribution proportional to `func`, `width` values per row, row by row (`func.len()`
    /// must be `width * height`, both at least 1).
    pub fn new(func: &[f32], width: usize, height: usize) -> Self {
        assert!(width >= 1 && height >= 1 && func.len() == width * height, "a {width}x{height} grid");
        let rows: Vec<Distribution1D> = func.chunks_exact(width).map(Distribution1D::new).collect();
        let marginal = Distribution1D::new(&rows.iter().map(Distribution1D::integral).collect::<Vec<f32>>());
        Distribution2D { rows, marginal }
    }

    /// The integral of the function over `[0, 1)^2`; 0 when there is nothing to sample.
    pub fn integral(&self) -> f32 {
        self.marginal.integral()
    }

    /// A point `(u, v)` of `[0, 1)^2` from two uniform numbers, and its density.
    pub fn sample(&self, u0: f32, u1: f32) -> ([f32; 2], f32) {
        let (v, pdf_v, row) = self.marginal.sample(u1);
        let (u, pdf_u, _) = self.rows[row].sample(u0);
        ([u, v], pdf_u * pdf_v)
    }

    /// The density at `(u, v)`.
    pub fn pdf(&self, u: f32, v: f32) -> f32 {
        let integral = self.marginal.integral();
        if !(integral > 0.0) {
            return 0.0;
        }
        let row = &self.rows[self.marginal.piece(v)];
        row.value(row.piece(u)) / integral
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_dimension_inverts_the_cumulative_distribution() {
        let d = Distribution1D::new(&[1.0, 3.0, 0.0, 4.0]);
        assert_eq!(d.integral(), 2.0);
        // The cdf is 0, 1/8, 1/2, 1/2, 1: u = 0.3 falls in piece 1, (0.3 - 1/8) / (3/8) of the way.
        let (x, pdf, i) = d.sample(0.3);
        assert_eq!(i, 1);
        assert!((x - (1.0 + (0.3 - 0.125) / 0.375) / 4.0).abs() < 1e-6, "{x}");
        assert_eq!(pdf, 1.5);
        // A piece of zero weight is never chosen, even at its own cdf value.
        assert_eq!(d.sample(0.5).2, 3);
        assert_eq!(d.pdf(0.6), 0.0);
        assert_eq!(d.pdf(0.9), 2.0);
        assert!(d.sample(0.999_999_9).0 < 1.0);
    }

    #[test]
    fn nothing_to_sample_gives_density_zero() {
        let d = Distribution1D::new(&[0.0, f32::NAN, -1.0]);
        assert_eq!(d.integral(), 0.0);
        assert_eq!(d.sample(0.5).1, 0.0);
        let d2 = Distribution2D::new(&[0.0; 6], 3, 2);
        assert_eq!(d2.integral(), 0.0);
        assert_eq!(d2.pdf(0.5, 0.5), 0.0);
    }

    #[test]
    fn two_dimensions_sample_rows_then_columns_and_the_density_integrates_to_one() {
        // 3 columns by 2 rows.
        let f = [1.0, 2.0, 3.0, 0.0, 0.0, 6.0];
        let d = Distribution2D::new(&f, 3, 2);
        assert!((d.integral() - 2.0).abs() < 1e-6);
        // Exact integral of the density over the grid: sum of pdf times cell area.
        let total: f32 = (0..2)
            .flat_map(|r| (0..3).map(move |c| (c, r)))
            .map(|(c, r)| d.pdf((c as f32 + 0.5) / 3.0, (r as f32 + 0.5) / 2.0) / 6.0)
            .sum();
        assert!((total - 1.0).abs() < 1e-6, "{total}");
        // Counts from a stratified grid of numbers match each cell's probability f / sum(f).
        let k = 600;
        let mut counts = [0u32; 6];
        for i in 0..k {
            for j in 0..k {
                let ([u, v], pdf) = d.sample((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
                let cell = (v * 2.0) as usize * 3 + (u * 3.0) as usize;
                assert_eq!(pdf, d.pdf(u, v));
                counts[cell] += 1;
            }
        }
        for (cell, &c) in counts.iter().enumerate() {
            let expected = f[cell] / 12.0 * (k * k) as f32;
            assert!((c as f32 - expected).abs() <= 2.0 * k as f32 + 2.0, "cell {cell}: {c} against {expected}");
        }
    }
}
