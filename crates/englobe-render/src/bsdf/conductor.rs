//! A conductor (metal): a smooth mirror or a rough Torrance-Sparrow microfacet reflector over
//! the Trowbridge-Reitz distribution, with either the exact Fresnel equations of a complex index
//! per channel or Schlick's approximation from a reflectance at normal incidence (glTF 2.0's
//! metals, Appendix B, "Metals").
//!
//! `f(wo, wi) = D(m) G2(wo, wi) F(wo·m) / (4 |cos θo| |cos θi|)` with `m` the half vector
//! (Torrance and Sparrow 1967; Walter et al. 2007), sampled through the visible
//! normals so that `pdf = D_wo(m) / (4 |wo·m|)` and the weight is `F G2 / G1(wo)` (Heitz 2018).
//! As pbrt-v4's `ConductorBxDF` (Pharr, Jakob and Humphreys, "Physically Based Rendering", 4th
//! edition, chapter 9). Two-sided: below the surface it reflects as above.

use englobe::{Vec2, Vec3};

use super::fresnel::{fresnel_complex_rgb, fresnel_schlick};
use super::local::{abs_cos_theta, reflect, same_hemisphere};
use super::microfacet::TrowbridgeReitz;
use super::sample::{BsdfSample, SampleKind};

/// How a conductor's reflectance depends on the angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConductorFresnel {
    /// The exact equations for the complex relative index `eta + i k`, per channel.
    Complex {
        /// Real part of the index, per channel.
        eta: Vec3,
        /// Imaginary part (absorption), per channel.
        k: Vec3,
    },
    /// Schlick's approximation from the reflectance at normal incidence `f0`, per channel.
    Schlick {
        /// Reflectance at normal incidence (glTF's base colour of a metal).
        f0: Vec3,
    },
}

impl ConductorFresnel {
    /// The reflectance at cosine `cos` (absolute value used).
    pub fn eval(&self, cos: f32) -> Vec3 {
        match *self {
            ConductorFresnel::Complex { eta, k } => fresnel_complex_rgb(cos, eta, k),
            ConductorFresnel::Schlick { f0 } => fresnel_schlick(f0, cos),
        }
    }
}

/// A smooth or rough conductor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// The microfacet distribution; smooth below [`crate::bsdf::SMOOTH_ALPHA`].
    pub distribution: TrowbridgeReitz,
    /// The reflectance of a microfacet.
    pub fresnel: ConductorFresnel,
}

impl Conductor {
    /// `f(wo, wi)` without the cosine; zero for a smooth conductor (a delta).
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if self.distribution.effectively_smooth() || !same_hemisphere(wo, wi) {
            return Vec3::ZERO;
        }
        let (cos_o, cos_i) = (abs_cos_theta(wo), abs_cos_theta(wi));
        let Some(wm) = half_vector(wo, wi) else { return Vec3::ZERO };
        let d_g = self.distribution.d(wm) * self.distribution.g2(wo, wi);
        self.fresnel.eval(wo.dot(wm)) * (d_g / (4.0 * cos_o * cos_i))
    }

    /// The density of [`Conductor::sample`]; zero for a smooth conductor.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.distribution.effectively_smooth() || !same_hemisphere(wo, wi) {
            return 0.0;
        }
        let Some(wm) = half_vector(wo, wi) else { return 0.0 };
        self.distribution.d_visible(wo, wm) / (4.0 * wo.dot(wm).abs())
    }

    /// The mirror direction (smooth) or a reflection off a visible microfacet (rough); `None`
    /// when the reflected direction goes below the surface.
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        if self.distribution.effectively_smooth() {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            let weight = self.fresnel.eval(wo.z);
            return Some(BsdfSample { wi, weight, pdf: 1.0, delta: true, kind: SampleKind::Reflection, eta: 1.0 });
        }
        let wm = self.distribution.sample_visible(wo, u);
        let wm = if wo.z < 0.0 { -wm } else { wm };
        let wi = reflect(wo, wm);
        if !same_hemisphere(wo, wi) {
            return None;
        }
        let pdf = self.pdf(wo, wi);
        if !(pdf > 0.0) {
            return None;
        }
        let weight = self.eval(wo, wi) * (abs_cos_theta(wi) / pdf);
        Some(BsdfSample { wi, weight, pdf, delta: false, kind: SampleKind::Reflection, eta: 1.0 })
    }
}

/// The unit half vector of a reflection, on the upper side, or `None` when degenerate.
pub(crate) fn half_vector(wo: Vec3, wi: Vec3) -> Option<Vec3> {
    let h = wo + wi;
    if h.length_squared() == 0.0 || wo.z == 0.0 || wi.z == 0.0 {
        return None;
    }
    let h = h.normalize();
    Some(if h.z < 0.0 { -h } else { h })
}
