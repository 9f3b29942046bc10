//! Spectra as linear sRGB, for a renderer that works in RGB.
//!
//! pbrt-v4 divides every light's spectrum by its luminance (`SpectrumToPhotometric`), so that a
//! light's `scale` is in nits; an `rgb` light is its RGB value, and a `blackbody` light of
//! temperature `T` is the colour of Planck's law at `T` with luminance `Y = 1`. Colours here come
//! from the CIE 1931 colour matching functions in the multi-lobe Gaussian fit of Wyman, Sloan and
//! Shirley (2013, "Simple Analytic Approximations to the CIE XYZ Color Matching Functions", JCGT
//! 2(2)), integrated from 360 to 830 nm in 1 nm steps, then taken from XYZ to linear sRGB with the
//! sRGB (D65) matrix of IEC 61966-2-1.
//!
//! Spectra given as wavelength-value pairs become RGB by the same integral under an equal-energy
//! illuminant, with each channel divided by the value a constant spectrum of 1 gets, so that a flat
//! spectrum keeps its value: an approximation (pbrt multiplies spectra wavelength by wavelength).

use glam::DVec3;

/// One lobe of the fit: a Gaussian with a different width on each side of its mean.
fn lobe(lambda: f64, mean: f64, left: f64, right: f64) -> f64 {
    let t = (lambda - mean) / if lambda < mean { left } else { right };
    (-0.5 * t * t).exp()
}

/// The CIE 1931 2-degree colour matching functions at `lambda` nanometres (Wyman et al. 2013).
pub(super) fn cie_xyz(lambda: f64) -> DVec3 {
    let x = 1.056 * lobe(lambda, 599.8, 37.9, 31.0) + 0.362 * lobe(lambda, 442.0, 16.0, 26.7)
        - 0.065 * lobe(lambda, 501.1, 20.4, 26.2);
    let y = 0.821 * lobe(lambda, 568.8, 46.9, 40.5) + 0.286 * lobe(lambda, 530.9, 16.3, 31.1);
    let z = 1.217 * lobe(lambda, 437.0, 11.8, 36.0) + 0.681 * lobe(lambda, 459.0, 26.0, 13.8);
    DVec3::new(x, y, z)
}

/// Linear sRGB of CIE XYZ.
pub(super) fn xyz_to_srgb(c: DVec3) -> DVec3 {
    DVec3::new(
        3.2404542 * c.x - 1.5371385 * c.y - 0.4985314 * c.z,
        -0.9692660 * c.x + 1.8760108 * c.y + 0.0415560 * c.z,
        0.0556434 * c.x - 0.2040259 * c.y + 1.0572252 * c.z,
    )
}

/// The XYZ of a spectrum, `f(lambda)` integrated against the matching functions.
fn integrate(f: impl Fn(f64) -> f64) -> DVec3 {
    (360..=830).map(|l| cie_xyz(l as f64) * f(l as f64)).sum()
}

/// Planck's law: the spectral radiance of a black body at `kelvin`, at `lambda` nanometres (in
/// arbitrary units; only its shape matters here).
fn planck(lambda_nm: f64, kelvin: f64) -> f64 {
    const C: f64 = 299_792_458.0;
    const H: f64 = 6.626_070_15e-34;
    const KB: f64 = 1.380_649e-23;
    let l = lambda_nm * 1e-9;
    2.0 * H * C * C / (l.powi(5) * ((H * C / (l * KB * kelvin)).exp_m1()))
}

/// The linear sRGB colour of a black body at `kelvin` with luminance 1 (negative components, out
/// of the sRGB gamut, clamped to 0). `None` for a temperature that is not positive.
pub(super) fn blackbody_rgb(kelvin: f64) -> Option<DVec3> {
    if !(kelvin > 0.0) || !kelvin.is_finite() {
        return None;
    }
    let xyz = integrate(|l| planck(l, kelvin));
    if !(xyz.y > 0.0) || !xyz.is_finite() {
        return None;
    }
    Some(xyz_to_srgb(xyz / xyz.y).max(DVec3::ZERO))
}

/// The linear sRGB of a piecewise-linear spectrum given as `(wavelength, value)` pairs sorted by
/// wavelength (constant beyond its ends), white-balanced so that a constant spectrum keeps its
/// value. `None` if the wavelengths are not increasing.
pub(super) fn sampled_rgb(pairs: &[f64]) -> Option<DVec3> {
    let n = pairs.len() / 2;
    if n == 0 || (1..n).any(|i| !(pairs[2 * i] > pairs[2 * i - 2])) {
        return None;
    }
    let value = |l: f64| {
        let i = (0..n).position(|i| pairs[2 * i] >= l).unwrap_or(n);
        if i == 0 {
            return pairs[1];
        }
        if i == n {
            return pairs[2 * n - 1];
        }
        let (l0, v0, l1, v1) = (pairs[2 * i - 2], pairs[2 * i - 1], pairs[2 * i], pairs[2 * i + 1]);
        v0 + (v1 - v0) * (l - l0) / (l1 - l0)
    };
    let white = xyz_to_srgb(integrate(|_| 1.0));
    Some(xyz_to_srgb(integrate(value)) / white)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rec. 709 luminance of linear sRGB.
    fn luminance(c: DVec3) -> f64 {
        0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
    }

    #[test]
    fn the_matching_functions_peak_where_the_cie_tables_do() {
        // CIE 1931: y-bar peaks at 555 nm with value 1.0; x-bar has its main peak 1.06 near 599 nm.
        let y555 = cie_xyz(555.0).y;
        assert!((y555 - 1.0).abs() < 0.02, "{y555}");
        assert!((cie_xyz(600.0).x - 1.06).abs() < 0.02);
        // The equal-energy white point has x = y = 1/3.
        let w = integrate(|_| 1.0);
        let (x, y) = (w.x / w.element_sum(), w.y / w.element_sum());
        assert!((x - 1.0 / 3.0).abs() < 0.005 && (y - 1.0 / 3.0).abs() < 0.005, "({x}, {y})");
    }

    #[test]
    fn black_bodies_have_unit_luminance_and_shift_from_red_to_blue() {
        let warm = blackbody_rgb(2700.0).unwrap();
        let d65ish = blackbody_rgb(6504.0).unwrap();
        let cold = blackbody_rgb(12000.0).unwrap();
        for c in [warm, d65ish, cold] {
            assert!((luminance(c) - 1.0).abs() < 0.01, "{c}");
        }
        assert!(warm.x > warm.y && warm.y > warm.z, "{warm}");
        assert!(cold.z > cold.x, "{cold}");
        // The sRGB white (D65) lies near the Planckian locus at 6504 K.
        assert!((d65ish - DVec3::ONE).abs().max_element() < 0.12, "{d65ish}");
        assert!(blackbody_rgb(0.0).is_none() && blackbody_rgb(-5.0).is_none());
    }

    #[test]
    fn a_flat_spectrum_keeps_its_value() {
        let c = sampled_rgb(&[300.0, 0.25, 800.0, 0.25]).unwrap();
        assert!((c - DVec3::splat(0.25)).abs().max_element() < 1e-9, "{c}");
        let red = sampled_rgb(&[400.0, 0.0, 580.0, 0.0, 600.0, 1.0, 700.0, 1.0]).unwrap();
        assert!(red.x > 0.5 && red.z < 0.1, "{red}");
        assert!(sampled_rgb(&[500.0, 1.0, 400.0, 1.0]).is_none());
    }
}
