//! A dielectric boundary (glass, water): smooth (Dirac delta reflection and refraction) or rough
//! (microfacet reflection and refraction over the Trowbridge-Reitz distribution), with the exact
//! dielectric Fresnel equations and total internal reflection. Light crosses it both ways: a
//! `wo` below the surface (`wo.z < 0`) is inside the denser medium.
//!
//! The rough form is Walter, Marschner, Li and Torrance (2007), "Microfacet Models for Refraction
//! through Rough Surfaces" (EGSR): their BRDF and BTDF over the generalised half vector, in the
//! form of pbrt-v4's `DielectricBxDF` (Pharr, Jakob and Humphreys, "Physically Based Rendering",
//! 4th edition, chapter 9): the microfacet normal is drawn among those visible
//! from `wo`, then reflection or refraction with the Fresnel probability at that normal; the
//! density is that choice times the Jacobian of the half-vector mapping (Walter et al.).
//!
//! Radiance, not importance, is transported: a transmitted `f` is divided by `η'²`, where
//! `η' = n_i / n_o` is the index on `wi`'s side over the index on `wo`'s side, because radiance
//! is `n²` times larger in the denser medium (Veach 1997, "Robust Monte Carlo Methods for Light
//! Transport Simulation", chapter 5; pbrt's `TransportMode::Radiance`). The transmitted light
//! may be tinted (glTF's `KHR_materials_transmission` tints it with the base colour).

use englobe::{Vec2, Vec3};

use super::fresnel::{fresnel_dielectric, fresnel_dielectric_cosines};
use super::local::{abs_cos_theta, reflect, refract, same_hemisphere};
use super::microfacet::TrowbridgeReitz;
use super::sample::{BsdfSample, SampleKind};

/// A smooth or rough dielectric boundary.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    /// The relative index `n_below / n_above` (inside over outside, the normal pointing out):
    /// 1.5 for glass in air. An index of exactly 1 is a pass-through boundary, smooth whatever
    /// the roughness (pbrt-v4 does the same: refraction without bending has no microfacets).
    pub eta: f32,
    /// The microfacet distribution; smooth below [`crate::bsdf::SMOOTH_ALPHA`].
    pub distribution: TrowbridgeReitz,
    /// The colour that transmitted light is multiplied by (white for clear glass).
    pub tint: Vec3,
}

impl Dielectric {
    /// True if both lobes are Dirac deltas.
    pub fn is_smooth(&self) -> bool {
        self.eta == 1.0 || self.distribution.effectively_smooth()
    }

    /// The probabilities of sampling reflection and transmission for a Fresnel reflectance `r`.
    fn lobe_probabilities(&self, r: f32) -> (f32, f32) {
        let pr = r;
        let pt = (1.0 - r) * mean(self.tint);
        let sum = pr + pt;
        if sum > 0.0 { (pr / sum, pt / sum) } else { (0.0, 0.0) }
    }

    /// `f(wo, wi)` without the cosine; zero when smooth (both lobes are deltas).
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if self.is_smooth() {
            return Vec3::ZERO;
        }
        let Some(h) = self.generalized_half(wo, wi) else { return Vec3::ZERO };
        let (cos_o, cos_i) = (wo.z, wi.z);
        let r = h.reflectance(wo, wi, self.eta);
        let d_g = self.distribution.d(h.wm) * self.distribution.g2(wo, wi);
        if h.reflect {
            return Vec3::splat(d_g * r / (4.0 * cos_i * cos_o).abs());
        }
        let (dot_i, dot_o) = (wi.dot(h.wm), wo.dot(h.wm));
        let denom = (dot_i + dot_o / h.etap).powi(2) * cos_i * cos_o;
        let ft = (1.0 - r) * d_g * (dot_i * dot_o / denom).abs();
        self.tint * (ft / (h.etap * h.etap))
    }

    /// The density of [`Dielectric::sample`]; zero when smooth.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.is_smooth() {
            return 0.0;
        }
        let Some(h) = self.generalized_half(wo, wi) else { return 0.0 };
        let (pr, pt) = self.lobe_probabilities(h.reflectance(wo, wi, self.eta));
        let visible = self.distribution.d_visible(wo, h.wm);
        if h.reflect {
            pr * visible / (4.0 * wo.dot(h.wm).abs())
        } else {
            let (dot_i, dot_o) = (wi.dot(h.wm), wo.dot(h.wm));
            let dwm_dwi = dot_i.abs() / (dot_i + dot_o / h.etap).powi(2);
            pt * visible * dwm_dwi
        }
    }

    /// Reflection or refraction, chosen with `u_lobe` in proportion to the Fresnel reflectance
    /// and the (tinted) transmittance; a microfacet normal from `u` when rough.
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        if self.is_smooth() {
            return self.sample_smooth(wo, u_lobe);
        }
        let wm = self.distribution.sample_visible(wo, u);
        let r = fresnel_dielectric(wo.dot(wm), self.eta);
        let (pr, pt) = self.lobe_probabilities(r);
        if pr + pt == 0.0 {
            return None;
        }
        let (wi, kind, eta) = if u_lobe < pr {
            let wi = reflect(wo, wm);
            if !same_hemisphere(wo, wi) {
                return None;
            }
            (wi, SampleKind::Reflection, 1.0)
        } else {
            let (wi, etap) = refract(wo, wm, self.eta)?;
            if same_hemisphere(wo, wi) || wi.z == 0.0 {
                return None;
            }
            (wi, SampleKind::Transmission, etap)
        };
        let pdf = self.pdf(wo, wi);
        if !(pdf > 0.0) {
            return None;
        }
        let weight = self.eval(wo, wi) * (abs_cos_theta(wi) / pdf);
        Some(BsdfSample { wi, weight, pdf, delta: false, kind, eta })
    }

    /// The smooth boundary: the mirror direction with probability `pr`, the refracted one with
    /// `pt`. The weight of each is its Fresnel factor over its probability (divided by `η'²`
    /// for the refraction, which transports radiance).
    fn sample_smooth(&self, wo: Vec3, u_lobe: f32) -> Option<BsdfSample> {
        let r = fresnel_dielectric(wo.z, self.eta);
        let (pr, pt) = self.lobe_probabilities(r);
        if u_lobe < pr {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            let weight = Vec3::splat(r / pr);
            return Some(BsdfSample { wi, weight, pdf: pr, delta: true, kind: SampleKind::Reflection, eta: 1.0 });
        }
        if pt == 0.0 {
            return None;
        }
        let (wi, etap) = refract(wo, Vec3::Z, self.eta)?;
        let weight = self.tint * ((1.0 - r) / (pt * etap * etap));
        Some(BsdfSample { wi, weight, pdf: pt, delta: true, kind: SampleKind::Transmission, eta: etap })
    }

    /// The generalised half vector of `wo` and `wi` (Walter et al. 2007), facing up,
    /// or `None` for a degenerate pair or a microfacet that faces away from either direction.
    fn generalized_half(&self, wo: Vec3, wi: Vec3) -> Option<Half> {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 || cos_i == 0.0 {
            return None;
        }
        let reflect = cos_o * cos_i > 0.0;
        let etap = if reflect {
            1.0
        } else if cos_o > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        };
        let wm = wi * etap + wo;
        if wm.length_squared() == 0.0 {
            return None;
        }
        let wm = wm.normalize();
        let wm = if wm.z < 0.0 { -wm } else { wm };
        // Microfacets seen from behind by either direction scatter nothing.
        if wm.dot(wi) * cos_i < 0.0 || wm.dot(wo) * cos_o < 0.0 {
            return None;
        }
        Some(Half { wm, reflect, etap })
    }
}

/// A generalised half vector and what it says of the pair of directions.
struct Half {
    wm: Vec3,
    reflect: bool,
    /// `n_i / n_o`, 1 for a reflection.
    etap: f32,
}

impl Half {
    /// The Fresnel reflectance at this microfacet: for a refraction, from both directions'
    /// cosines, which keeps `1 - F` accurate near the critical angle and the same both ways.
    fn reflectance(&self, wo: Vec3, wi: Vec3, eta: f32) -> f32 {
        if self.reflect {
            fresnel_dielectric(wo.dot(self.wm), eta)
        } else {
            fresnel_dielectric_cosines(wo.dot(self.wm).abs(), wi.dot(self.wm).abs(), self.etap)
        }
    }
}

/// The mean of the three channels.
#[inline]
pub(crate) fn mean(v: Vec3) -> f32 {
    (v.x + v.y + v.z) / 3.0
}
