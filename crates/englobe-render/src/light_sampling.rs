//! Next-event estimation of the environment and of the sphere lights for the path tracer, each
//! combined with the BSDF's own sampling by the power heuristic (Veach and Guibas 1995,
//! "Optimally Combining Sampling Techniques for Monte Carlo Rendering"; Pharr, Jakob and Humphreys,
//! "Physically Based Rendering", 3rd ed., section 14.3.1).
//!
//! At a hit where the BSDF can be evaluated, each kind of light gets one sample: a direction of
//! the environment ([`crate::environment`]) and a point on one sphere light
//! ([`crate::sphere_lights`]), each with its shadow ray. A bounce drawn from the BSDF that then
//! escapes to the environment, or hits a sampled sphere light, is weighted against the density
//! with which that light's own sampling would have found the same direction; the two weights of
//! every direction sum to one, so the sum is unbiased, and each light is found by whichever
//! technique finds it better: the small bright sun by light sampling, a wide soft sky by both.
//!
//! Units: an environment and a sphere's `emission` are radiances, like the emissive triangles'
//! (see [`crate::emitters`]): a sample of density `pdf` contributes `f * L * cos / pdf`, with `f`
//! the BSDF (`diffuse / π` for Lambert).

use englobe::{Counters, Ray, Vec2, Vec3};
use englobe_scene::Scene;
use rand::{Rng, RngExt};

use crate::emitters::power_heuristic;
use crate::environment::EnvironmentLight;
use crate::shading::{SHADOW_RAY_END, Surface};
use crate::sphere_lights::SphereLights;
use crate::stats::{RayKind, Tally};
use crate::visibility::Visibility;

/// The lights that next-event estimation samples besides the point, directional and triangle
/// lights: the environment and the emissive spheres.
#[derive(Clone, Debug, Default)]
pub struct SampledLights {
    /// The scene's environment, if it has one.
    pub environment: Option<EnvironmentLight>,
    /// The scene's emissive spheres.
    pub spheres: SphereLights,
}

impl SampledLights {
    /// The environment and sphere lights of `scene`.
    pub fn of(scene: &Scene) -> Self {
        SampledLights {
            environment: scene.environment.as_ref().map(EnvironmentLight::new),
            spheres: SphereLights::of(scene),
        }
    }

    /// True if there is nothing to sample (so that scenes without these lights draw no random
    /// numbers for them).
    pub fn is_empty(&self) -> bool {
        self.environment.as_ref().is_none_or(EnvironmentLight::is_black) && self.spheres.is_empty()
    }

    /// Light reaching the surface `s` from one sample of the environment and one of the sphere
    /// lights, reflected by the BSDF and weighted against BSDF sampling. `bsdf(wi)` is the
    /// BSDF times the cosine at the shading normal, and the density with which the BSDF samples
    /// `wi` (solid angle), for a unit direction `wi` on the side the ray came from.
    pub fn sample<C: Counters>(
        &self,
        s: &Surface,
        vis: &Visibility,
        rng: &mut impl Rng,
        tally: &mut Tally<C>,
        bsdf: impl Fn(Vec3) -> (Vec3, f32),
    ) -> Vec3 {
        if self.is_empty() {
            return Vec3::ZERO;
        }
        let mut light = Vec3::ZERO;
        if let Some(env) = self.environment.as_ref().filter(|e| !e.is_black()) {
            let u = Vec2::new(rng.random(), rng.random());
            if let Some(e) = env.sample(u)
                && e.direction.dot(s.n) > 0.0
            {
                let (f, pdf_bsdf) = bsdf(e.direction);
                if f != Vec3::ZERO {
                    tally.rays[RayKind::Shadow as usize] += 1;
                    let shadow = Ray::new(s.outside(), e.direction);
                    if !vis.any_hit(&shadow, &mut tally.work[RayKind::Shadow as usize]) {
                        light += f * e.radiance * (power_heuristic(e.pdf, pdf_bsdf) / e.pdf);
                    }
                }
            }
        }
        if !self.spheres.is_empty() {
            let (u0, u1, u2) = (rng.random(), rng.random(), rng.random());
            if let Some(l) = self.spheres.sample(s.p, u0, u1, u2)
                && l.direction.dot(s.n) > 0.0
            {
                let (f, pdf_bsdf) = bsdf(l.direction);
                if f != Vec3::ZERO {
                    let origin = s.outside();
                    tally.rays[RayKind::Shadow as usize] += 1;
                    let shadow = Ray::segment(origin, l.point - origin, 0.0, SHADOW_RAY_END);
                    if !vis.any_hit(&shadow, &mut tally.work[RayKind::Shadow as usize]) {
                        light += f * l.radiance * (power_heuristic(l.pdf, pdf_bsdf) / l.pdf);
                    }
                }
            }
        }
        light
    }

    /// What a ray that hit nothing brings back, in direction `dir`: the environment, weighted
    /// against its sampling when the ray was a bounce drawn with density `bounce_pdf` from a
    /// surface where the environment was sampled too; without an environment, `background`.
    pub fn escaped(&self, dir: Vec3, bounce_pdf: Option<f32>, background: Vec3) -> Vec3 {
        let Some(env) = &self.environment else { return background };
        let radiance = env.radiance(dir);
        match bounce_pdf {
            Some(pdf) if !env.is_black() => radiance * power_heuristic(pdf, env.pdf(dir)),
            _ => radiance,
        }
    }

    /// The weight of the emission of object `object`, hit by a bounce from `origin` drawn with
    /// density `bounce_pdf`: its power-heuristic weight if it is a sampled sphere light, else
    /// `None` (it is not sampled here).
    pub fn emission_weight(&self, object: u32, origin: Vec3, bounce_pdf: f32) -> Option<f32> {
        self.spheres.pdf(object, origin).map(|pdf_light| power_heuristic(bounce_pdf, pdf_light))
    }
}
