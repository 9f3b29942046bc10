//! The statistics and quadrature behind the tests: adaptive Simpson integration over the sphere
//! in `(cos θ, φ)`, the chi-square distribution, and Pearson's test with pooled low-count cells
//! and the Šidák correction (as pbrt-v4's `Chi2Test` and Mitsuba 3's `ChiSquareTest`).

use std::f64::consts::PI;

use englobe::Vec3;
use rand::SeedableRng;
use rand_pcg::Pcg32;

/// Cells along `cos θ` over `[-1, 1]` (a boundary at the horizon) and along `φ`.
pub const COS_BINS: usize = 32;
pub const PHI_BINS: usize = 32;
/// Samples per chi-square test (pbrt-v4's and Mitsuba's count).
pub const SAMPLES: usize = 1_000_000;
/// Significance of the whole family of chi-square tests.
pub const SIGNIFICANCE: f64 = 0.01;
/// Cells expecting fewer samples are pooled.
const MIN_EXPECTED: f64 = 5.0;

/// A seeded generator: every test draws the same numbers on every run.
pub fn rng(seed: u64) -> Pcg32 {
    Pcg32::seed_from_u64(seed)
}

/// The unit direction of `cos θ = c` and azimuth `phi`.
pub fn direction(c: f64, phi: f64) -> Vec3 {
    let s = (1.0 - c * c).max(0.0).sqrt();
    Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32)
}

/// A direction at polar angle `theta_deg` from `+z` and azimuth `phi_deg`.
pub fn dir(theta_deg: f64, phi_deg: f64) -> Vec3 {
    direction(theta_deg.to_radians().cos(), phi_deg.to_radians())
}

/// `∫ f` over `[a, b]` by adaptive Simpson, to about `eps`, splitting at least `min_depth` times.
pub fn simpson(f: &mut dyn FnMut(f64) -> f64, a: f64, b: f64, eps: f64, min_depth: u32) -> f64 {
    let (fa, fm, fb) = (f(a), f(0.5 * (a + b)), f(b));
    let whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    simpson_step(f, a, b, fa, fm, fb, whole, eps, 0, min_depth)
}

#[allow(clippy::too_many_arguments)]
fn simpson_step(
    f: &mut dyn FnMut(f64) -> f64,
    a: f64,
    b: f64,
    fa: f64,
    fm: f64,
    fb: f64,
    whole: f64,
    eps: f64,
    depth: u32,
    min_depth: u32,
) -> f64 {
    const MAX_DEPTH: u32 = 14;
    let m = 0.5 * (a + b);
    let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
    let (flm, frm) = (f(lm), f(rm));
    let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    let delta = left + right - whole;
    if depth >= MAX_DEPTH || (depth >= min_depth && delta.abs() <= 15.0 * eps) {
        return left + right + delta / 15.0;
    }
    simpson_step(f, a, m, fa, flm, fm, left, 0.5 * eps, depth + 1, min_depth)
        + simpson_step(f, m, b, fm, frm, fb, right, 0.5 * eps, depth + 1, min_depth)
}

/// `∫∫ f(cos θ, φ)` over a cell of the sphere: the integral of a density over solid angle.
pub fn integrate_cell(f: &dyn Fn(f64, f64) -> f64, c: (f64, f64), phi: (f64, f64), eps: f64) -> f64 {
    let inner_eps = eps / (c.1 - c.0);
    let mut outer = |cv: f64| simpson(&mut |p: f64| f(cv, p), phi.0, phi.1, inner_eps, 2);
    simpson(&mut outer, c.0, c.1, eps, 2)
}

/// The probability of each cell of the `(cos θ, φ)` grid under the density `pdf` of directions.
pub fn cell_probabilities(pdf: &dyn Fn(Vec3) -> f64, eps_per_cell: f64) -> Vec<f64> {
    let f = |c: f64, p: f64| pdf(direction(c, p));
    let mut cells = Vec::with_capacity(COS_BINS * PHI_BINS);
    for i in 0..COS_BINS {
        let c = (-1.0 + 2.0 * i as f64 / COS_BINS as f64, -1.0 + 2.0 * (i + 1) as f64 / COS_BINS as f64);
        for j in 0..PHI_BINS {
            let p = (2.0 * PI * j as f64 / PHI_BINS as f64, 2.0 * PI * (j + 1) as f64 / PHI_BINS as f64);
            cells.push(integrate_cell(&f, c, p, eps_per_cell));
        }
    }
    cells
}

/// The cell of a direction.
pub fn cell_of(w: Vec3) -> usize {
    let c = (w.z as f64).clamp(-1.0, 1.0);
    let i = (((c + 1.0) * 0.5 * COS_BINS as f64) as usize).min(COS_BINS - 1);
    let mut phi = (w.y as f64).atan2(w.x as f64);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    let j = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    i * PHI_BINS + j
}

/// `ln Γ(x)` for `x > 0` (Lanczos, g = 7, n = 9; accurate to about 1e-15).
fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (k, g) in G.iter().enumerate().skip(1) {
        a += g / (x + k as f64);
    }
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularised upper incomplete gamma function `Q(a, x) = Γ(a, x) / Γ(a)` (series below
/// `a + 1`, Lentz's continued fraction above: Press et al., "Numerical Recipes", section 6.2).
fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let log_prefactor = -x + a * x.ln() - ln_gamma(a);
    if x < a + 1.0 {
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        1.0 - sum * log_prefactor.exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        log_prefactor.exp() * h
    }
}

/// The probability that a chi-square variable of `dof` degrees of freedom exceeds `x`.
pub fn chi2_survival(x: f64, dof: usize) -> f64 {
    gamma_q(0.5 * dof as f64, 0.5 * x)
}

/// The per-test significance that keeps the family of `tests` tests at [`SIGNIFICANCE`]
/// (Šidák).
pub fn sidak(tests: usize) -> f64 {
    1.0 - (1.0 - SIGNIFICANCE).powf(1.0 / tests as f64)
}

/// Pearson's statistic of observed against expected counts, cells expecting fewer than five
/// pooled (in increasing order of expectation, as pbrt-v4 pools them), and its p-value. An
/// observation in a cell of zero probability is an error.
pub fn pearson(observed: &[u64], expected: &[f64]) -> Result<(f64, usize, f64), String> {
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut chi2, mut dof) = (0.0, 0usize);
    let (mut pooled_obs, mut pooled_exp) = (0.0, 0.0);
    for &k in &order {
        let (o, e) = (observed[k] as f64, expected[k]);
        if e <= 0.0 {
            if o > 0.0 {
                return Err(format!("{o} samples in cell {k}, where the density is zero"));
            }
        } else if e < MIN_EXPECTED || (pooled_exp > 0.0 && pooled_exp < MIN_EXPECTED) {
            pooled_obs += o;
            pooled_exp += e;
        } else {
            chi2 += (o - e) * (o - e) / e;
            dof += 1;
        }
    }
    if pooled_exp > 0.0 {
        chi2 += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
        dof += 1;
    }
    // The expected counts are scaled to the observed total: one degree of freedom fewer.
    if dof < 2 {
        return Err(format!("only {dof} cells to compare"));
    }
    let dof = dof - 1;
    Ok((chi2, dof, chi2_survival(chi2, dof)))
}

/// The outcome of [`chi2_test`].
#[derive(Debug)]
pub struct Chi2Outcome {
    pub p_value: f64,
    pub statistic: f64,
    pub dof: usize,
    /// `∫ pdf` over the sphere, by quadrature.
    pub mass: f64,
    /// The fraction of samples that came back as directions (neither lost nor delta).
    pub accepted: f64,
}

/// Draws [`SAMPLES`] directions with `sample` (`None`: lost or from a delta lobe), bins them on
/// the `(cos θ, φ)` grid, and compares the counts with those `pdf` predicts for the samples that
/// came back (its cell integrals scaled to their number). Also returns `∫ pdf`, which must equal
/// the fraction that came back.
pub fn chi2_test(
    seed: u64,
    sample: &mut dyn FnMut(&mut Pcg32) -> Option<Vec3>,
    pdf: &dyn Fn(Vec3) -> f64,
) -> Result<Chi2Outcome, String> {
    let mut rng = rng(seed);
    let mut observed = vec![0u64; COS_BINS * PHI_BINS];
    let mut accepted = 0u64;
    for _ in 0..SAMPLES {
        if let Some(w) = sample(&mut rng) {
            if !w.is_finite() || (w.length() - 1.0).abs() > 1e-3 {
                return Err(format!("a sampled direction {w} is not a unit vector"));
            }
            observed[cell_of(w)] += 1;
            accepted += 1;
        }
    }
    let cells = cell_probabilities(pdf, 1e-7);
    let mass: f64 = cells.iter().sum();
    if accepted == 0 || mass <= 0.0 {
        return Err(format!("{accepted} samples came back, the density integrates to {mass}"));
    }
    let expected: Vec<f64> = cells.iter().map(|p| p / mass * accepted as f64).collect();
    let (statistic, dof, p_value) = pearson(&observed, &expected)?;
    Ok(Chi2Outcome { p_value, statistic, dof, mass, accepted: accepted as f64 / SAMPLES as f64 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bsdf_stats_chi2_survival_matches_closed_forms() {
        // dof 2: exp(-x/2); dof 4: exp(-x/2)(1 + x/2); dof 1 at x = 3.841459: 0.05.
        for x in [0.1, 1.0, 5.0, 30.0, 200.0] {
            assert!((chi2_survival(x, 2) - (-x / 2.0f64).exp()).abs() < 1e-12, "{x}");
            let four = (-x / 2.0f64).exp() * (1.0 + x / 2.0);
            assert!((chi2_survival(x, 4) - four).abs() < 1e-12 * four.max(1e-300).max(1.0), "{x}");
        }
        assert!((chi2_survival(3.841_458_820_694_124, 1) - 0.05).abs() < 1e-9);
        // The 99th percentile of 1000 degrees of freedom is 1106.969.
        assert!((chi2_survival(1106.969, 1000) - 0.01).abs() < 1e-5);
    }

    #[test]
    fn bsdf_stats_quadrature_of_the_sphere() {
        // The uniform density integrates to 1, cos θ / π over the upper hemisphere too.
        let uniform: f64 = cell_probabilities(&|_| 0.25 / PI, 1e-9).iter().sum();
        assert!((uniform - 1.0).abs() < 1e-9);
        let cosine: f64 = cell_probabilities(&|w| (w.z.max(0.0) as f64) / PI, 1e-9).iter().sum();
        assert!((cosine - 1.0).abs() < 1e-7, "{cosine}");
    }

    #[test]
    fn bsdf_stats_cells_cover_the_sphere() {
        assert_eq!(cell_of(Vec3::Z), (COS_BINS - 1) * PHI_BINS);
        assert_eq!(cell_of(-Vec3::Z) / PHI_BINS, 0);
        assert_eq!(cell_of(direction(0.01, 0.0)), (COS_BINS / 2) * PHI_BINS);
        assert_eq!(cell_of(direction(0.01, 2.0 * PI - 1e-6)), (COS_BINS / 2) * PHI_BINS + PHI_BINS - 1);
    }
}
