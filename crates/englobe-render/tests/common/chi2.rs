//! Pearson's chi-square test of observed counts against expected ones, as pbrt-v4's sampling
//! tests and Mitsuba's `chi2` do: bins expected to hold fewer than 5 samples are pooled into one,
//! and the p-value comes from the regularized upper incomplete gamma function (Numerical Recipes,
//! 3rd ed., section 6.2: its series below `a + 1`, its continued fraction above).

/// The p-value of the counts `observed` against `expected` (same length; the expected counts sum
/// to the number of samples), and the statistic with its degrees of freedom.
pub fn chi2_test(observed: &[f64], expected: &[f64]) -> (f64, f64, usize) {
    assert_eq!(observed.len(), expected.len());
    let (mut statistic, mut bins) = (0.0, 0usize);
    let (mut pooled_observed, mut pooled_expected) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e < 5.0 {
            pooled_observed += o;
            pooled_expected += e;
        } else {
            statistic += (o - e) * (o - e) / e;
            bins += 1;
        }
    }
    if pooled_expected > 0.0 {
        statistic += (pooled_observed - pooled_expected).powi(2) / pooled_expected;
        bins += 1;
    } else if pooled_observed > 0.0 {
        // Samples where the density says none can fall.
        return (0.0, f64::INFINITY, bins);
    }
    let dof = bins.saturating_sub(1).max(1);
    (gamma_q(dof as f64 / 2.0, statistic / 2.0), statistic, dof)
}

/// `ln Γ(x)` for `x > 0` (Lanczos, Numerical Recipes' coefficients).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 6] = [
        76.18009172947146,
        -86.50532032941677,
        24.01409824083091,
        -1.231739572450155,
        0.1208650973866179e-2,
        -0.5395239384953e-5,
    ];
    let mut y = x;
    let t = x + 5.5;
    let t = t - (x + 0.5) * t.ln();
    let mut series = 1.000000000190015;
    for c in C {
        y += 1.0;
        series += c / y;
    }
    -t + (2.5066282746310005 * series / x).ln()
}

/// The regularized upper incomplete gamma function `Q(a, x) = Γ(a, x) / Γ(a)`.
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let front = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        // P(a, x) by its series.
        let (mut term, mut sum, mut n) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * front
    } else {
        // Q(a, x) by Lentz's continued fraction.
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
            if (delta - 1.0).abs() < 1e-15 {
                break;
            }
        }
        front * h
    }
}

#[test]
fn the_p_values_match_tables() {
    // Upper tail of chi-square: 3.841 for 1 degree of freedom and 18.307 for 10 are the 5 %
    // points; 135.807 is the 1 % point for 100.
    let p = |stat: f64, dof: f64| gamma_q(dof / 2.0, stat / 2.0);
    assert!((p(3.841, 1.0) - 0.05).abs() < 1e-4);
    assert!((p(18.307, 10.0) - 0.05).abs() < 1e-4);
    assert!((p(135.807, 100.0) - 0.01).abs() < 1e-4);
    assert!((p(2.0, 2.0) - (-1.0f64).exp()).abs() < 1e-12, "Q(1, x) = e^-x");
}
