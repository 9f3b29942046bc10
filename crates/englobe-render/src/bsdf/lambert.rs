//! Lambert's diffuse reflector: `f = R / π` on the side of the viewer, sampled with density
//! `|cos θ| / π` (Malley's method; Pharr, Jakob and Humphreys, "Physically Based Rendering",
//! 4th edition, sections 9.2 and A.5.3). Two-sided: it reflects alike on both sides of the
//! surface.

use std::f32::consts::{FRAC_1_PI, PI};

use englobe::{Vec2, Vec3};

use super::local::{abs_cos_theta, same_hemisphere};
use super::sample::{BsdfSample, SampleKind};

/// A Lambertian reflector of reflectance `reflectance` (per channel, in `[0, 1]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambert {
    /// The directional-hemispherical reflectance, the same from every direction.
    pub reflectance: Vec3,
}

impl Lambert {
    /// `f(wo, wi)`, not multiplied by the cosine.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if same_hemisphere(wo, wi) { self.reflectance * FRAC_1_PI } else { Vec3::ZERO }
    }

    /// The density of [`Lambert::sample`] per unit solid angle.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if same_hemisphere(wo, wi) { abs_cos_theta(wi) * FRAC_1_PI } else { 0.0 }
    }

    /// A cosine-distributed direction on `wo`'s side.
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let mut wi = cosine_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = abs_cos_theta(wi) * FRAC_1_PI;
        if pdf == 0.0 {
            return None;
        }
        Some(BsdfSample { wi, weight: self.reflectance, pdf, delta: false, kind: SampleKind::Reflection, eta: 1.0 })
    }
}

/// A direction of the upper hemisphere with density `cos θ / π`, from two uniform numbers.
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u.x).max(0.0).sqrt())
}
