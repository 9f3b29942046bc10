//! glTF 2.0's metallic-roughness material (the specification's Appendix B), with
//! `KHR_materials_transmission` and `KHR_materials_ior`:
//!
//! ```text
//! material = mix(dielectric, metal, metallic)
//! metal      = specular_brdf(α) · schlick(F0 = base_colour, |wo·m|)
//! dielectric = mix(opaque, glass, transmission)
//! opaque     = specular_brdf(α) · schlick(F0 = ((ior - 1)/(ior + 1))², |wo·m|) + diffuse beneath it
//! glass      = rough dielectric of index ior (Walter et al. 2007), transmission tinted by base_colour
//! ```
//!
//! with `α = roughness²` and `specular_brdf` the Trowbridge-Reitz microfacet reflection with
//! height-correlated Smith masking (the specification's `V_GGX · D_GGX`).
//!
//! The diffuse beneath the specular layer departs from the specification's literal
//! `fresnel_mix`, which weights the Lambertian base by `1 - F(wo·h)` at the half vector of the
//! pair: seen at grazing angles that base keeps nearly all of its reflectance while the specular
//! layer reflects most of the light, and a white material of roughness 0.3 seen at 85 degrees
//! reflects more than 1.2 times the light it receives (`tests/bsdf/bsdf_energy.rs` measures
//! it). Here the base is coupled by albedo scaling (Kelemen and Szirmay-Kalos 2001; Kulla and
//! Conty 2017, "Revisiting Physically Based Shading at Imageworks"), which is reciprocal and
//! conserves energy (up to the interpolation of the albedo table):
//!
//! ```text
//! diffuse(wo, wi) = base_colour / π · (1 - E(wo)) (1 - E(wi)) / (1 - Ē)
//! ```
//!
//! where `E` is the specular layer's directional albedo and `Ē` its hemispherical mean (see
//! [`super::specular_albedo`]): the diffuse part then reflects `(1 - E(wo)) · base_colour` of
//! the light from `wo`, the specular part `E(wo)`, and a white dielectric reflects everything
//! the single-scattering microfacet lobe does not lose. The specification presents its BRDF as an
//! example implementation of the model's intent (Appendix B), which this keeps: the same lobes,
//! parameters, Fresnel and mix.
//!
//! The glass part uses the exact dielectric Fresnel equations of its index rather than Schlick's,
//! since light also leaves it from inside, where the equations give total internal reflection.
//!
//! Sides: the metal and the opaque dielectric are two-sided (`wo.z < 0` reflects as `wo.z > 0`,
//! for double-sided glTF materials and backs of open meshes); the glass part is a boundary whose
//! normal points to the outside (`wo.z < 0` is inside the material).
//!
//! Sampling picks one of three lobes (specular reflection of metal and opaque dielectric, which
//! share a distribution; the diffuse base; the glass) in proportion to the light each reflects
//! from `wo` (their albedos from the table and the Fresnel equations at `wo`), and weights the
//! direction by the whole material's `f |cos θi| / pdf`, `pdf` the mixture of the three lobes'
//! densities (Veach 1997's one-sample model with the balance heuristic, thesis chapter 9;
//! pbrt-v3's `BSDF::Sample_f` does the same).

use std::f32::consts::FRAC_1_PI;

use englobe::{Vec2, Vec3};

use super::conductor::half_vector;
use super::dielectric::{Dielectric, mean};
use super::fresnel::{f0_from_ior, fresnel_dielectric, fresnel_schlick, schlick_weight};
use super::lambert::cosine_hemisphere;
use super::local::{abs_cos_theta, reflect, same_hemisphere};
use super::microfacet::{TrowbridgeReitz, roughness_to_alpha};
use super::sample::{BsdfSample, SampleKind};
use super::specular_albedo::{albedo_parts, mean_specular_albedo};

/// glTF 2.0's metallic-roughness material, with transmission and index of refraction. Its
/// parameters are read through methods: the weights and tables derived from them are fixed when
/// it is made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetallicRoughness {
    base_color: Vec3,
    metallic: f32,
    transmission: f32,
    ior: f32,
    distribution: TrowbridgeReitz,
    /// Weights of the three parts: metal, opaque dielectric, glass (summing to 1).
    w_metal: f32,
    w_opaque: f32,
    w_glass: f32,
    /// The opaque dielectric's Schlick `F0`.
    f0: f32,
    /// The `alpha` the albedo table is read at (0 for a smooth surface).
    table_alpha: f32,
    /// `1 - Ē` of the opaque dielectric's specular layer.
    one_minus_mean: f32,
    glass: Dielectric,
}

/// `x` clamped to `[0, 1]`, and 0 when not finite.
fn unit(x: f32) -> f32 {
    if x.is_finite() { x.clamp(0.0, 1.0) } else { 0.0 }
}

/// The probabilities of the three lobes at one `wo`.
#[derive(Clone, Copy, Debug)]
struct LobeChoice {
    specular: f32,
    diffuse: f32,
    glass: f32,
}

impl MetallicRoughness {
    /// The material of a glTF base colour, metalness, perceptual roughness, transmission and
    /// index; each clamped to its range (`ior` at least 1, 1.5 when not finite).
    pub fn new(base_color: Vec3, metallic: f32, roughness: f32, transmission: f32, ior: f32) -> MetallicRoughness {
        MetallicRoughness::with_alpha(base_color, metallic, roughness_to_alpha(unit(roughness)), transmission, ior)
    }

    /// The same material from the microfacet `alpha` itself (clamped to `[0, 1]`, the range of
    /// the albedo table) instead of glTF's perceptual roughness.
    pub fn with_alpha(base_color: Vec3, metallic: f32, alpha: f32, transmission: f32, ior: f32) -> MetallicRoughness {
        let base_color = Vec3::new(unit(base_color.x), unit(base_color.y), unit(base_color.z));
        let (metallic, transmission) = (unit(metallic), unit(transmission));
        let ior = if ior.is_finite() { ior.max(1.0) } else { 1.5 };
        let distribution = TrowbridgeReitz::isotropic(unit(alpha));
        let f0 = f0_from_ior(ior);
        // A smooth layer's albedo is its Fresnel factor: the table's first row, exactly.
        let table_alpha = if distribution.effectively_smooth() { 0.0 } else { distribution.alpha_x };
        let one_minus_mean = (1.0 - mean_specular_albedo(table_alpha, f0)).max(1e-6);
        MetallicRoughness {
            base_color,
            metallic,
            transmission,
            ior,
            distribution,
            w_metal: metallic,
            w_opaque: (1.0 - metallic) * (1.0 - transmission),
            w_glass: (1.0 - metallic) * transmission,
            f0,
            table_alpha,
            one_minus_mean,
            glass: Dielectric { eta: ior, distribution, tint: base_color },
        }
    }

    /// Base colour (linear), each channel in `[0, 1]`.
    pub fn base_color(&self) -> Vec3 {
        self.base_color
    }

    /// Metalness in `[0, 1]`.
    pub fn metallic(&self) -> f32 {
        self.metallic
    }

    /// `KHR_materials_transmission`'s fraction in `[0, 1]` of the dielectric that transmits.
    pub fn transmission(&self) -> f32 {
        self.transmission
    }

    /// The index of refraction (`KHR_materials_ior`, 1.5 without it), at least 1.
    pub fn ior(&self) -> f32 {
        self.ior
    }

    /// The microfacet distribution (isotropic, `alpha = roughness²`).
    pub fn distribution(&self) -> TrowbridgeReitz {
        self.distribution
    }

    /// True if the surface is smooth: its specular reflection and glass are Dirac deltas, and
    /// only the diffuse base is seen by `eval`.
    pub fn is_smooth(&self) -> bool {
        self.distribution.effectively_smooth()
    }

    /// True if every lobe of nonzero weight is a Dirac delta.
    pub fn is_delta(&self) -> bool {
        self.is_smooth() && (self.w_opaque == 0.0 || self.base_color == Vec3::ZERO)
    }

    /// The specular layer's albedo at `μ = |cos θ|` for Schlick's `f0`.
    fn albedo(&self, mu: f32, f0: f32) -> f32 {
        let (a, b) = albedo_parts(mu, self.table_alpha);
        f0 * a + (1.0 - f0) * b
    }

    /// The Fresnel factor of the specular reflection lobe at `cos = wo·m`: metal and opaque
    /// dielectric together.
    fn specular_fresnel(&self, cos: f32) -> Vec3 {
        fresnel_schlick(self.base_color, cos) * self.w_metal
            + Vec3::splat((self.f0 + (1.0 - self.f0) * schlick_weight(cos)) * self.w_opaque)
    }

    fn lobe_choice(&self, wo: Vec3) -> LobeChoice {
        let mu = abs_cos_theta(wo);
        let (a, b) = albedo_parts(mu, self.table_alpha);
        let metal = mean(self.base_color * a + (Vec3::ONE - self.base_color) * b);
        let opaque_specular = self.f0 * a + (1.0 - self.f0) * b;
        let specular = self.w_metal * metal + self.w_opaque * opaque_specular;
        let diffuse = self.w_opaque * (1.0 - opaque_specular) * mean(self.base_color);
        let glass = if self.w_glass > 0.0 {
            let r = fresnel_dielectric(wo.z, self.ior);
            self.w_glass * (r + (1.0 - r) * mean(self.base_color))
        } else {
            0.0
        };
        let sum = specular + diffuse + glass;
        if !(sum > 0.0) {
            return LobeChoice { specular: 0.0, diffuse: 0.0, glass: 0.0 };
        }
        LobeChoice { specular: specular / sum, diffuse: diffuse / sum, glass: glass / sum }
    }

    /// The specular reflection lobe (metal and opaque dielectric), without the cosine.
    fn eval_specular(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if self.is_smooth() || !same_hemisphere(wo, wi) || self.w_metal + self.w_opaque == 0.0 {
            return Vec3::ZERO;
        }
        let Some(wm) = half_vector(wo, wi) else { return Vec3::ZERO };
        let d_g = self.distribution.d(wm) * self.distribution.g2(wo, wi);
        self.specular_fresnel(wo.dot(wm)) * (d_g / (4.0 * (wo.z * wi.z).abs()))
    }

    fn pdf_specular(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.is_smooth() || !same_hemisphere(wo, wi) {
            return 0.0;
        }
        let Some(wm) = half_vector(wo, wi) else { return 0.0 };
        self.distribution.d_visible(wo, wm) / (4.0 * wo.dot(wm).abs())
    }

    /// The albedo-scaled diffuse base, without the cosine.
    fn eval_diffuse(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if self.w_opaque == 0.0 || !same_hemisphere(wo, wi) {
            return Vec3::ZERO;
        }
        let scale = (1.0 - self.albedo(wo.z.abs(), self.f0)) * (1.0 - self.albedo(wi.z.abs(), self.f0));
        self.base_color * (self.w_opaque * FRAC_1_PI * scale / self.one_minus_mean)
    }

    /// `f(wo, wi)` without the cosine: every lobe but the deltas of a smooth surface.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let glass = if self.w_glass > 0.0 { self.glass.eval(wo, wi) * self.w_glass } else { Vec3::ZERO };
        self.eval_specular(wo, wi) + self.eval_diffuse(wo, wi) + glass
    }

    fn pdf_with(&self, choice: LobeChoice, wo: Vec3, wi: Vec3) -> f32 {
        let mut pdf = 0.0;
        if choice.specular > 0.0 {
            pdf += choice.specular * self.pdf_specular(wo, wi);
        }
        if choice.diffuse > 0.0 && same_hemisphere(wo, wi) {
            pdf += choice.diffuse * abs_cos_theta(wi) * FRAC_1_PI;
        }
        if choice.glass > 0.0 {
            pdf += choice.glass * self.glass.pdf(wo, wi);
        }
        pdf
    }

    /// The density of [`MetallicRoughness::sample`] over its non-delta lobes.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.pdf_with(self.lobe_choice(wo), wo, wi)
    }

    /// One lobe chosen with `u_lobe`, a direction from it with `u` (and the rest of `u_lobe`
    /// when the glass chooses between reflection and refraction).
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let choice = self.lobe_choice(wo);
        let rescale = |x: f32, p: f32| (x / p).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        let sample = if u_lobe < choice.specular {
            if self.is_smooth() {
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                let weight = self.specular_fresnel(wo.z) / choice.specular;
                let pdf = choice.specular;
                return Some(BsdfSample { wi, weight, pdf, delta: true, kind: SampleKind::Reflection, eta: 1.0 });
            }
            let wm = self.distribution.sample_visible(wo, u);
            let wi = reflect(wo, if wo.z < 0.0 { -wm } else { wm });
            if !same_hemisphere(wo, wi) {
                return None; // below the surface: outside the lobe's density
            }
            wi
        } else if u_lobe < choice.specular + choice.diffuse {
            let mut wi = cosine_hemisphere(u);
            wi.z = wi.z.copysign(wo.z);
            wi
        } else {
            if !(choice.glass > 0.0) {
                return None;
            }
            let u_glass = rescale(u_lobe - choice.specular - choice.diffuse, choice.glass);
            let s = self.glass.sample(wo, u_glass, u)?;
            if s.delta {
                let weight = s.weight * (self.w_glass / choice.glass);
                return Some(BsdfSample { weight, pdf: s.pdf * choice.glass, ..s });
            }
            s.wi
        };
        let pdf = self.pdf_with(choice, wo, sample);
        if !(pdf > 0.0) || sample.z == 0.0 {
            return None;
        }
        let (kind, eta) = if same_hemisphere(wo, sample) {
            (SampleKind::Reflection, 1.0)
        } else {
            (SampleKind::Transmission, if wo.z > 0.0 { self.ior } else { 1.0 / self.ior })
        };
        let weight = self.eval(wo, sample) * (abs_cos_theta(sample) / pdf);
        Some(BsdfSample { wi: sample, weight, pdf, delta: false, kind, eta })
    }
}
