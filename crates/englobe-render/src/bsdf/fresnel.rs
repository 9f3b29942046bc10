//! Fresnel reflectance: the exact unpolarised equations for a dielectric boundary (with total
//! internal reflection) and for a conductor of complex index `η + iκ` per colour channel, and
//! Schlick's approximation from the reflectance at normal incidence.
//!
//! The exact forms follow Pharr, Jakob and Humphreys, "Physically Based Rendering", 4th edition,
//! chapter 9 (`FrDielectric`, `FrComplex`); Schlick (1994), "An Inexpensive BRDF Model for
//! Physically-based Rendering" gives `F0 + (1 - F0)(1 - cos θ)^5`, which glTF 2.0 (Appendix B,
//! "Fresnel") uses for both its metals (`F0` = base colour) and its dielectrics
//! (`F0 = ((ior - 1) / (ior + 1))²`).

use englobe::Vec3;

/// Reflectance of a dielectric boundary for light arriving at cosine `cos_i` to the normal,
/// where `eta = n_below / n_above` (the side the normal points away from over the side it points
/// to). A negative `cos_i` means the light arrives from below, and the index is inverted.
/// 1 under total internal reflection.
#[inline]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let (mut cos_i, mut eta) = (cos_i.clamp(-1.0, 1.0), eta);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    (0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)).clamp(0.0, 1.0)
}

/// Reflectance of a dielectric boundary from both cosines of a refraction: `cos_i` on the
/// incident side and `cos_t` on the transmitted side (both non-negative), `eta = n_t / n_i`.
/// The same value as [`fresnel_dielectric`], but with no square root: near the critical angle,
/// where `cos_t` computed from `cos_i` loses every digit, this form stays exact when both
/// cosines are known (a refraction through a known microfacet), and it is the same for the path
/// and its reverse.
#[inline]
pub fn fresnel_dielectric_cosines(cos_i: f32, cos_t: f32, eta: f32) -> f32 {
    let r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    (0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)).clamp(0.0, 1.0)
}

/// A complex number, only as wide as the conductor's Fresnel equations need.
#[derive(Clone, Copy, Debug)]
struct Complex {
    re: f32,
    im: f32,
}

impl Complex {
    fn new(re: f32, im: f32) -> Complex {
        Complex { re, im }
    }
    fn add(self, o: Complex) -> Complex {
        Complex::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: Complex) -> Complex {
        Complex::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: Complex) -> Complex {
        Complex::new(self.re * o.re - self.im * o.im, self.re * o.im + self.im * o.re)
    }
    fn scale(self, s: f32) -> Complex {
        Complex::new(self.re * s, self.im * s)
    }
    /// `|z|²`.
    fn norm(self) -> f32 {
        self.re * self.re + self.im * self.im
    }
    fn div(self, o: Complex) -> Complex {
        let d = o.norm();
        Complex::new((self.re * o.re + self.im * o.im) / d, (self.im * o.re - self.re * o.im) / d)
    }
    /// The principal square root (non-negative real part), computed without cancellation.
    fn sqrt(self) -> Complex {
        let n = self.norm().sqrt();
        if n == 0.0 {
            return Complex::new(0.0, 0.0);
        }
        let t1 = (0.5 * (n + self.re.abs())).sqrt();
        let t2 = 0.5 * self.im / t1;
        if self.re >= 0.0 { Complex::new(t1, t2) } else { Complex::new(t2.abs(), t1.copysign(self.im)) }
    }
}

/// Reflectance of a conductor of complex relative index `eta + i k` (the metal's over the
/// outside medium's) for light at cosine `cos_i` (its absolute value is used: a conductor
/// reflects alike from both sides).
pub fn fresnel_complex(cos_i: f32, eta: f32, k: f32) -> f32 {
    let cos_i = cos_i.abs().min(1.0);
    let eta = Complex::new(eta, k);
    let sin2_i = 1.0 - cos_i * cos_i;
    // sin² θt = sin² θi / η², cos θt = sqrt(1 - sin² θt), all complex.
    let sin2_t = Complex::new(sin2_i, 0.0).div(eta.mul(eta));
    let cos_t = Complex::new(1.0, 0.0).sub(sin2_t).sqrt();
    let ci = Complex::new(cos_i, 0.0);
    let eci = eta.scale(cos_i);
    let r_parallel = eci.sub(cos_t).div(eci.add(cos_t));
    let r_perpendicular = ci.sub(eta.mul(cos_t)).div(ci.add(eta.mul(cos_t)));
    (0.5 * (r_parallel.norm() + r_perpendicular.norm())).clamp(0.0, 1.0)
}

/// [`fresnel_complex`] per colour channel.
pub fn fresnel_complex_rgb(cos_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
    Vec3::new(
        fresnel_complex(cos_i, eta.x, k.x),
        fresnel_complex(cos_i, eta.y, k.y),
        fresnel_complex(cos_i, eta.z, k.z),
    )
}

/// `(1 - |cos θ|)^5`, the weight of `1 - F0` in Schlick's approximation.
#[inline]
pub fn schlick_weight(cos_i: f32) -> f32 {
    let m = (1.0 - cos_i.abs()).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// Schlick's approximation `F0 + (1 - F0)(1 - |cos θ|)^5`, per channel.
#[inline]
pub fn fresnel_schlick(f0: Vec3, cos_i: f32) -> Vec3 {
    f0 + (Vec3::ONE - f0) * schlick_weight(cos_i)
}

/// The reflectance at normal incidence of a dielectric of relative index `eta`:
/// `((eta - 1) / (eta + 1))²`.
#[inline]
pub fn f0_from_ior(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_closed_forms() {
        // Normal incidence: ((n - 1) / (n + 1))², from either side.
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-7);
        assert!((fresnel_dielectric(-1.0, 1.5) - 0.04).abs() < 1e-7);
        assert!((fresnel_dielectric(1.0, 1.33) - f0_from_ior(1.33)).abs() < 1e-7);
        // 80 degrees from air into glass of 1.5 (the value pbrt-v4's tests quote).
        let c80 = 80f64.to_radians().cos() as f32;
        assert!((fresnel_dielectric(c80, 1.5) - 0.387_704_35).abs() < 2e-6, "{}", fresnel_dielectric(c80, 1.5));
        // Brewster's angle, tan θ = 1.5: r_p vanishes and R = sin²(θi - θt) / 2 = (5/13)² / 2.
        let brewster = 1.5f64.atan().cos() as f32;
        assert!((fresnel_dielectric(brewster, 1.5) - 25.0 / 338.0).abs() < 1e-6);
        // Total internal reflection from inside beyond asin(1 / 1.5) = 41.8103 degrees.
        let critical = (1.0f64 / 1.5).asin();
        assert_eq!(fresnel_dielectric(-((critical + 1e-4).cos() as f32), 1.5), 1.0);
        assert!(fresnel_dielectric(-((critical - 1e-3).cos() as f32), 1.5) < 1.0);
        // Grazing incidence reflects everything; matched indices nothing.
        assert!((fresnel_dielectric(0.0, 1.5) - 1.0).abs() < 1e-6);
        assert_eq!(fresnel_dielectric(0.7, 1.0), 0.0);
    }

    #[test]
    fn dielectric_reflectance_is_the_same_along_a_reversed_path() {
        // The reflectance seen from outside at θi equals the one seen from inside at θt.
        for deg in [5.0f32, 30.0, 60.0, 85.0] {
            let ci = deg.to_radians().cos();
            let sin_t = deg.to_radians().sin() / 1.5;
            let ct = (1.0 - sin_t * sin_t).sqrt();
            let (outside, inside) = (fresnel_dielectric(ci, 1.5), fresnel_dielectric(-ct, 1.5));
            assert!((outside - inside).abs() < 1e-5, "{deg}: {outside} {inside}");
        }
    }

    #[test]
    fn both_cosines_give_the_same_reflectance_both_ways() {
        for deg in [0.0f32, 30.0, 41.0, 60.0, 89.0] {
            let ci = deg.to_radians().cos();
            let ct = (1.0 - (1.0 - ci * ci) / 2.25).sqrt();
            let r = fresnel_dielectric_cosines(ci, ct, 1.5);
            assert!((r - fresnel_dielectric(ci, 1.5)).abs() < 1e-6, "{deg}");
            assert!((r - fresnel_dielectric_cosines(ct, ci, 1.0 / 1.5)).abs() < 1e-7, "{deg}");
        }
    }

    #[test]
    fn a_conductor_without_absorption_is_a_dielectric() {
        for c in [1.0f32, 0.8, 0.4, 0.1] {
            assert!((fresnel_complex(c, 1.5, 0.0) - fresnel_dielectric(c, 1.5)).abs() < 1e-6, "{c}");
        }
    }

    #[test]
    fn conductor_closed_forms() {
        // Normal incidence: ((η - 1)² + κ²) / ((η + 1)² + κ²); gold at 600 nm, η = 0.25, κ = 3.0.
        let (eta, k) = (0.25f32, 3.0f32);
        let f0 = ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k);
        assert!((fresnel_complex(1.0, eta, k) - f0).abs() < 1e-6);
        assert!((fresnel_complex(-1.0, eta, k) - f0).abs() < 1e-6, "both sides alike");
        // Grazing incidence reflects everything.
        assert!((fresnel_complex(0.0, eta, k) - 1.0).abs() < 1e-5);
        let rgb = fresnel_complex_rgb(1.0, Vec3::new(0.2, 0.9, 1.2), Vec3::new(3.9, 2.4, 1.8));
        assert!((rgb.y - fresnel_complex(1.0, 0.9, 2.4)).abs() < 1e-7);
        // Against a double-precision evaluation of the textbook formula at 60 degrees.
        let c = 60f64.to_radians().cos();
        let reference = {
            // rs and rp from n² - sin² θ = a² + b² ... the classic real form (Born and Wolf).
            let (n, kk, s2) = (eta as f64, k as f64, 1.0 - c * c);
            let t = n * n - kk * kk - s2;
            let a2b2 = (t * t + 4.0 * n * n * kk * kk).sqrt();
            let a = (0.5 * (a2b2 + t)).sqrt();
            let rs = (a2b2 + c * c - 2.0 * a * c) / (a2b2 + c * c + 2.0 * a * c);
            let rp = rs * (a2b2 * c * c + s2 * s2 - 2.0 * a * c * s2) / (a2b2 * c * c + s2 * s2 + 2.0 * a * c * s2);
            0.5 * (rs + rp)
        };
        assert!((fresnel_complex(c as f32, eta, k) as f64 - reference).abs() < 1e-5, "{reference}");
    }

    #[test]
    fn schlick_limits() {
        let f0 = Vec3::new(0.9, 0.6, 0.2);
        assert_eq!(fresnel_schlick(f0, 1.0), f0);
        assert!((fresnel_schlick(f0, 0.0) - Vec3::ONE).length() < 1e-6);
        assert!((fresnel_schlick(f0, 0.5) - (f0 + (Vec3::ONE - f0) / 32.0)).length() < 1e-6);
        assert!((f0_from_ior(1.5) - 0.04).abs() < 1e-7);
    }
}
