//! The Trowbridge-Reitz (GGX) microfacet distribution, anisotropic, with its Smith masking and
//! the sampling of its visible normals.
//!
//! - The distribution of normals `D` is Trowbridge and Reitz (1975), "Average irregularity
//!   representation of a rough surface for ray reflection", named GGX by Walter, Marschner, Li
//!   and Torrance (2007), "Microfacet Models for Refraction through Rough Surfaces" (EGSR), with
//!   the anisotropic form of Heitz (2014), "Understanding the Masking-Shadowing Function in
//!   Microfacet-Based BRDFs" (JCGT 3(2)), section 5.
//! - Masking is Smith's, `G1 = 1 / (1 + Λ)`, and masking-shadowing the height-correlated
//!   `G2 = 1 / (1 + Λ(wo) + Λ(wi))` of Heitz (2014), section 6.
//! - The distribution of visible normals, `D_wo(m) = G1(wo) max(0, wo·m) D(m) / cos θo` (Heitz
//!   2014, section 3), is sampled exactly with the spherical caps of Dupuy and Benyoub (2023),
//!   "Sound and Complete Visible-Normal Sampling of the GGX Distribution" (arXiv:2306.05044), a
//!   simpler equivalent of Heitz (2018), "Sampling the GGX Distribution of Visible Normals"
//!   (JCGT 7(4)): stretch `wo` to the configuration of roughness 1, sample the visible
//!   hemisphere there as a uniform point on a spherical cap, and stretch back.
//!
//! Roughness follows glTF 2.0 (its metallic-roughness material): `alpha = roughness²`
//! ([`roughness_to_alpha`]). Below [`SMOOTH_ALPHA`] the distribution is treated as a perfectly
//! smooth surface (a Dirac delta) as pbrt-v4 does (`EffectivelySmooth`), since its lobes are then
//! narrower than any light could be sampled; pbrt-v4 tests the smaller of the two alphas, this
//! the larger, so that a surface rough along one axis alone (brushed metal) keeps its streaks.

use std::f32::consts::PI;

use englobe::{Vec2, Vec3};

use super::local::abs_cos_theta;

/// Below this `alpha` (on both axes) a surface is smooth: a mirror or a perfect refractor
/// (pbrt-v4's threshold).
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// The microfacet `alpha` of a glTF (perceptual) roughness in `[0, 1]`: `roughness²`.
#[inline]
pub fn roughness_to_alpha(roughness: f32) -> f32 {
    let r = roughness.clamp(0.0, 1.0);
    r * r
}

/// The microfacet `alpha` of a pbrt-v4 `roughness` parameter when the scene asks for it to be
/// remapped (`remaproughness`, true by default): `sqrt(roughness)`.
#[inline]
pub fn pbrt_roughness_to_alpha(roughness: f32) -> f32 {
    roughness.max(0.0).sqrt()
}

/// The Trowbridge-Reitz (GGX) distribution of microfacet normals, with roughness `alpha_x` along
/// the local `x` axis and `alpha_y` along `y`. All directions are local (`z` the macro normal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrowbridgeReitz {
    /// Roughness along the tangent `x`.
    pub alpha_x: f32,
    /// Roughness along the bitangent `y`.
    pub alpha_y: f32,
}

impl TrowbridgeReitz {
    /// The anisotropic distribution. Non-finite or negative `alpha`s are read as 0 (smooth);
    /// larger than 1 is allowed.
    pub fn new(alpha_x: f32, alpha_y: f32) -> TrowbridgeReitz {
        let clean = |a: f32| if a.is_finite() && a > 0.0 { a } else { 0.0 };
        TrowbridgeReitz { alpha_x: clean(alpha_x), alpha_y: clean(alpha_y) }
    }

    /// The isotropic distribution of `alpha`.
    pub fn isotropic(alpha: f32) -> TrowbridgeReitz {
        TrowbridgeReitz::new(alpha, alpha)
    }

    /// True if the surface is smooth enough to be a Dirac delta (see [`SMOOTH_ALPHA`]).
    #[inline]
    pub fn effectively_smooth(&self) -> bool {
        self.alpha_x.max(self.alpha_y) < SMOOTH_ALPHA
    }

    /// The density of microfacet normals `D(m)` per unit solid angle of `m`, normalised so that
    /// `∫ D(m) cos θm dm = 1` over the upper hemisphere. Zero below the horizon.
    ///
    /// Written as `1 / (π αx αy (x²/αx² + y²/αy² + z²)²)` for the unit `m = (x, y, z)`, which
    /// equals the textbook `1 / (π αx αy cos⁴θ (1 + tan²θ (cos²φ/αx² + sin²φ/αy²))²)` but needs no
    /// cut-off near the horizon, where that form divides by `cos⁴θ → 0`.
    pub fn d(&self, wm: Vec3) -> f32 {
        if wm.z <= 0.0 {
            return 0.0;
        }
        let (x, y) = (wm.x / self.alpha_x, wm.y / self.alpha_y);
        let t = x * x + y * y + wm.z * wm.z;
        1.0 / (PI * self.alpha_x * self.alpha_y * t * t)
    }

    /// Smith's auxiliary function `Λ(w) = (sqrt(1 + α(φ)² tan²θ) - 1) / 2` (Heitz 2014,
    /// section 5), with `α(φ)² tan²θ = (αx² x² + αy² y²) / z²`; the same for `w` and `-w`,
    /// infinite on the horizon.
    pub fn lambda(&self, w: Vec3) -> f32 {
        if w.z == 0.0 {
            return f32::INFINITY;
        }
        let (x, y) = (self.alpha_x * w.x, self.alpha_y * w.y);
        let alpha2_tan2 = (x * x + y * y) / (w.z * w.z);
        0.5 * ((1.0 + alpha2_tan2).sqrt() - 1.0)
    }

    /// Smith's masking `G1(w) = 1 / (1 + Λ(w))`: the fraction of the microsurface seen from `w`.
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// The height-correlated masking-shadowing `G2(wo, wi) = 1 / (1 + Λ(wo) + Λ(wi))`.
    #[inline]
    pub fn g2(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// The density of the normals visible from `w`, `D_w(m) = G1(w) max(0, w·m) D(m) / |cos θ|`,
    /// per unit solid angle of `m` (Heitz 2014, section 3). For `w` below the surface the
    /// normals visible from its mirror image `-w` count (so `w·m` is taken in absolute value).
    pub fn d_visible(&self, w: Vec3, wm: Vec3) -> f32 {
        let cos = abs_cos_theta(w);
        if cos == 0.0 {
            return 0.0;
        }
        let w = if w.z < 0.0 { -w } else { w };
        self.g1(w) / cos * self.d(wm) * w.dot(wm).max(0.0)
    }

    /// A microfacet normal drawn with density [`TrowbridgeReitz::d_visible`] from two uniform
    /// numbers in `[0, 1)` (Dupuy and Benyoub 2023). Always in the upper hemisphere.
    pub fn sample_visible(&self, w: Vec3, u: Vec2) -> Vec3 {
        let w = if w.z < 0.0 { -w } else { w };
        // To the configuration of roughness 1, where the visible normals are a spherical cap.
        let wh = Vec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
        let phi = 2.0 * PI * u.x;
        let z = (1.0 - u.y) * (1.0 + wh.z) - wh.z;
        let sin_theta = (1.0 - z * z).clamp(0.0, 1.0).sqrt();
        let h = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), z) + wh;
        // Back to the surface's roughness (the inverse transpose of the stretch, for normals).
        Vec3::new(self.alpha_x * h.x, self.alpha_y * h.y, h.z.max(1e-6)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gltf_roughness_is_squared() {
        assert_eq!(roughness_to_alpha(0.5), 0.25);
        assert_eq!(roughness_to_alpha(2.0), 1.0);
        assert_eq!(roughness_to_alpha(-1.0), 0.0);
        assert!(TrowbridgeReitz::isotropic(roughness_to_alpha(0.03)).effectively_smooth());
        assert!(!TrowbridgeReitz::isotropic(roughness_to_alpha(0.04)).effectively_smooth());
        assert!(TrowbridgeReitz::new(f32::NAN, -1.0).effectively_smooth());
    }

    #[test]
    fn hand_values() {
        // D at the normal is 1 / (π αx αy); Λ(normal) = 0, so G1 = 1.
        let m = TrowbridgeReitz::new(0.3, 0.6);
        assert!((m.d(Vec3::Z) - 1.0 / (PI * 0.18)).abs() < 1e-4);
        assert_eq!(m.lambda(Vec3::Z), 0.0);
        // Isotropic Λ at tan θ = 1: (sqrt(1 + α²) - 1) / 2.
        let m = TrowbridgeReitz::isotropic(0.5);
        let w = Vec3::new(1.0, 0.0, 1.0).normalize();
        assert!((m.lambda(w) - 0.5 * ((1.25f32).sqrt() - 1.0)).abs() < 1e-6);
        assert!((m.lambda(-w) - m.lambda(w)).abs() < 1e-7);
        // G2 lies below the product of the G1s' bound and above zero.
        let wi = Vec3::new(-0.6, 0.2, 0.3).normalize();
        let g2 = m.g2(w, wi);
        assert!(g2 > 0.0 && g2 <= m.g1(w).min(m.g1(wi)));
        // Grazing directions see nothing.
        assert_eq!(m.g1(Vec3::X), 0.0);
    }

    #[test]
    fn visible_normals_face_the_viewer() {
        let m = TrowbridgeReitz::new(0.8, 0.2);
        let w = Vec3::new(0.7, -0.3, 0.2).normalize();
        for i in 0..32 {
            for j in 0..32 {
                let u = Vec2::new((i as f32 + 0.5) / 32.0, (j as f32 + 0.5) / 32.0);
                let wm = m.sample_visible(w, u);
                assert!((wm.length() - 1.0).abs() < 1e-5 && wm.z > 0.0);
                assert!(w.dot(wm) >= -1e-5, "a back-facing normal {wm}");
                assert_eq!(wm, m.sample_visible(-w, u), "below, the mirror image samples alike");
            }
        }
    }
}
