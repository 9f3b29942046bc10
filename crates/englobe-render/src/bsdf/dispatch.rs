//! [`Bsdf`]: every scattering model of the renderer behind one enum, with the constructors the
//! scene's materials map to. The conventions are those of the module ([`crate::bsdf`]).

use englobe::{Vec2, Vec3};

use super::conductor::{Conductor, ConductorFresnel};
use super::dielectric::Dielectric;
use super::lambert::Lambert;
use super::metallic_roughness::MetallicRoughness;
use super::microfacet::TrowbridgeReitz;
use super::sample::BsdfSample;

/// A BSDF in the local shading frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    /// Lambertian diffuse reflection.
    Lambert(Lambert),
    /// A smooth or rough metal.
    Conductor(Conductor),
    /// A smooth or rough dielectric boundary (glass).
    Dielectric(Dielectric),
    /// glTF 2.0's metallic-roughness material.
    MetallicRoughness(MetallicRoughness),
}

impl Bsdf {
    /// Lambertian reflection of `reflectance` (each channel clamped to `[0, 1]`).
    pub fn lambert(reflectance: Vec3) -> Bsdf {
        Bsdf::Lambert(Lambert { reflectance: reflectance.clamp(Vec3::ZERO, Vec3::ONE) })
    }

    /// A conductor of complex index `eta + i k` per channel (relative to the outside medium)
    /// over `distribution` (smooth when its alphas are below
    /// [`crate::bsdf::SMOOTH_ALPHA`]).
    pub fn conductor(eta: Vec3, k: Vec3, distribution: TrowbridgeReitz) -> Bsdf {
        Bsdf::Conductor(Conductor { distribution, fresnel: ConductorFresnel::Complex { eta, k } })
    }

    /// A conductor with Schlick's Fresnel from its reflectance at normal incidence `f0`
    /// (clamped to `[0, 1]`).
    pub fn conductor_schlick(f0: Vec3, distribution: TrowbridgeReitz) -> Bsdf {
        let f0 = f0.clamp(Vec3::ZERO, Vec3::ONE);
        Bsdf::Conductor(Conductor { distribution, fresnel: ConductorFresnel::Schlick { f0 } })
    }

    /// A clear dielectric boundary of relative index `eta` (inside over outside; non-finite or
    /// non-positive read as 1.5) over `distribution`.
    pub fn dielectric(eta: f32, distribution: TrowbridgeReitz) -> Bsdf {
        let eta = if eta.is_finite() && eta > 0.0 { eta } else { 1.5 };
        Bsdf::Dielectric(Dielectric { eta, distribution, tint: Vec3::ONE })
    }

    /// glTF 2.0's metallic-roughness material: linear `base_color`, `metallic`, perceptual
    /// `roughness` (`alpha = roughness²`), `KHR_materials_transmission`'s `transmission` and
    /// `KHR_materials_ior`'s `ior` (1.5 by default in glTF). See
    /// [`MetallicRoughness`]. An opaque dielectric of index 1 is [`Bsdf::lambert`] of its base
    /// colour: a boundary between equal indices reflects nothing, where Schlick's approximation
    /// would still reflect at grazing angles (MTL materials without a highlight map to it).
    pub fn metallic_roughness(base_color: Vec3, metallic: f32, roughness: f32, transmission: f32, ior: f32) -> Bsdf {
        if ior == 1.0 && metallic <= 0.0 && transmission <= 0.0 {
            return Bsdf::lambert(base_color);
        }
        Bsdf::MetallicRoughness(MetallicRoughness::new(base_color, metallic, roughness, transmission, ior))
    }

    /// Plastic: a Lambertian base of `reflectance` under a dielectric specular layer of index
    /// `ior` and microfacet `alpha` (clamped to `[0, 1]`), the opaque part of
    /// [`Bsdf::metallic_roughness`]: Schlick's Fresnel, the base coupled by albedo scaling. It
    /// stands in for pbrt-v4's `coateddiffuse` (and pbrt-v3's `plastic`), which simulates the
    /// light bouncing between the two layers stochastically: here the base keeps its own colour,
    /// where pbrt's darkens and saturates a little through the bounces, and the specular layer
    /// uses Schlick's Fresnel where pbrt uses the exact equations.
    pub fn plastic(reflectance: Vec3, alpha: f32, ior: f32) -> Bsdf {
        Bsdf::MetallicRoughness(MetallicRoughness::with_alpha(reflectance, 0.0, alpha, 0.0, ior))
    }

    /// `f(wo, wi)`, not multiplied by any cosine, over the non-delta lobes (a delta lobe is zero
    /// here). `wo` toward the viewer, `wi` toward the light, both local and unit.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self {
            Bsdf::Lambert(b) => b.eval(wo, wi),
            Bsdf::Conductor(b) => b.eval(wo, wi),
            Bsdf::Dielectric(b) => b.eval(wo, wi),
            Bsdf::MetallicRoughness(b) => b.eval(wo, wi),
        }
    }

    /// The density per unit solid angle with which [`Bsdf::sample`] returns `wi` from `wo` as a
    /// non-delta sample.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Bsdf::Lambert(b) => b.pdf(wo, wi),
            Bsdf::Conductor(b) => b.pdf(wo, wi),
            Bsdf::Dielectric(b) => b.pdf(wo, wi),
            Bsdf::MetallicRoughness(b) => b.pdf(wo, wi),
        }
    }

    /// A direction `wi` from `wo`, from three uniform numbers in `[0, 1)`: `u_lobe` chooses the
    /// lobe (and, rescaled, between reflection and refraction), `u` the direction within it.
    /// `None` when the sample is lost (a reflection below the surface, a grazing `wo`).
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        match self {
            Bsdf::Lambert(b) => b.sample(wo, u),
            Bsdf::Conductor(b) => b.sample(wo, u),
            Bsdf::Dielectric(b) => b.sample(wo, u_lobe, u),
            Bsdf::MetallicRoughness(b) => b.sample(wo, u_lobe, u),
        }
    }

    /// True if every lobe is a Dirac delta: `eval` and `pdf` are zero everywhere, so sampling
    /// lights at this surface is pointless.
    pub fn is_delta(&self) -> bool {
        match self {
            Bsdf::Lambert(_) => false,
            Bsdf::Conductor(b) => b.distribution.effectively_smooth(),
            Bsdf::Dielectric(b) => b.is_smooth(),
            Bsdf::MetallicRoughness(b) => b.is_delta(),
        }
    }

    /// True if light can cross the surface. Such a BSDF needs the frame's `z` on the outside
    /// (the geometric outward normal's side); one without transmission is two-sided and may be
    /// given either orientation.
    pub fn has_transmission(&self) -> bool {
        match self {
            Bsdf::Lambert(_) | Bsdf::Conductor(_) => false,
            Bsdf::Dielectric(_) => true,
            Bsdf::MetallicRoughness(b) => b.transmission() > 0.0 && b.metallic() < 1.0,
        }
    }
}
