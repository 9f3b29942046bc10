//! A Monte Carlo path tracer (Kajiya 1986, "The Rendering Equation"), beyond the seed's Whitted
//! recursion: diffuse surfaces bounce light in random directions (cosine-weighted), so light
//! inter-reflects between surfaces and emissive objects light the scene.
//!
//! At each hit one lobe of the material is chosen at random with the material's own weights:
//! mirror (`reflectivity`), dielectric (`transparency`, reflecting or refracting with the Fresnel
//! probability) or diffuse (the rest). The choice probabilities equal the lobes' weights, so the
//! path's throughput is multiplied by the lobe's colour alone. Point and directional lights are
//! sampled explicitly at every hit (next-event estimation, one shadow ray per light, weighted
//! exactly as the Whitted integrator weights them; see [`crate::shading`]). Emissive triangles
//! are sampled too, one point per diffuse hit, and combined with the bounces that hit them by
//! multiple importance sampling (see [`crate::emitters`]); so are the environment and emissive
//! spheres (see [`crate::light_sampling`]); other emissive shapes, and the background of a scene
//! without an environment, are found by the bounces alone. Surfaces emit from their front side only (the side
//! their outward normal, or a triangle's winding, points to), as physical lamps do. The scene's
//! `ambient` term, a stand-in for the
//! indirect light this integrator computes, is not used. Paths end at the scene's maximum depth or,
//! after three bounces, by Russian roulette (Arvo and Kirk 1990), which keeps the estimate unbiased.

use std::f32::consts::PI;

use englobe::{Counters, Object, Ray, Shape, Vec3, World, WorldHit};
use englobe_scene::Scene;
use rand::RngExt;
use rand_pcg::Pcg32;

use crate::emitters::{Emitters, power_heuristic};
use crate::light_sampling::SampledLights;
use crate::optics::{fresnel_dielectric, reflect, refract};
use crate::sampling::cosine_hemisphere;
use crate::shading::{SHADOW_RAY_END, Surface};
use crate::stats::{RayKind, Tally};

/// Bounces before Russian roulette may end a path.
const ROULETTE_AFTER: u32 = 3;

/// The path tracer over a scene and its world (built from the scene's objects, in order).
pub struct PathTracer<'a> {
    scene: &'a Scene,
    world: &'a World,
    emitters: Emitters,
    lights: SampledLights,
}

impl<'a> PathTracer<'a> {
    /// The integrator. `world` must hold the scene's objects in the scene's order.
    pub fn new(scene: &'a Scene, world: &'a World) -> Self {
        PathTracer { scene, world, emitters: Emitters::of(scene), lights: SampledLights::of(scene) }
    }

    /// True if the hit lies on a triangle, which [`Emitters`] samples when it emits.
    fn is_sampled_emitter(&self, hit: &WorldHit) -> bool {
        matches!(
            self.world.objects()[hit.object as usize],
            Object::Shape(Shape::Triangle(_)) | Object::Mesh(_) | Object::Instance(_)
        )
    }

    /// Light from one point sampled on the emissive triangles, reflected by the diffuse lobe of
    /// `s` (not yet weighted by the lobe's share), with its power-heuristic weight.
    fn sample_emitters<C: Counters>(&self, s: &Surface, rng: &mut Pcg32, tally: &mut Tally<C>) -> Vec3 {
        let Some(e) = self.emitters.sample(rng.random(), rng.random(), rng.random()) else {
            return Vec3::ZERO;
        };
        let v = e.point - s.p;
        let dist2 = v.length_squared();
        let wi = v / dist2.sqrt();
        let (cos_s, cos_l) = (s.ns.dot(wi), -e.normal.dot(wi));
        if !(cos_s > 0.0 && cos_l > 0.0 && wi.dot(s.n) > 0.0) {
            return Vec3::ZERO;
        }
        let origin = s.outside();
        tally.rays[RayKind::Shadow as usize] += 1;
        let shadow = Ray::segment(origin, e.point - origin, 0.0, SHADOW_RAY_END);
        if self.world.any_hit(&shadow, &mut tally.work[RayKind::Shadow as usize]) {
            return Vec3::ZERO;
        }
        let pdf_light = self.emitters.area_pdf() * dist2 / cos_l;
        let pdf_bounce = cos_s / PI;
        s.material.diffuse / PI * e.emission * (cos_s * power_heuristic(pdf_light, pdf_bounce) / pdf_light)
    }

    /// One estimate of the radiance along the primary ray `ray`.
    pub fn radiance<C: Counters>(&self, ray: &Ray, rng: &mut Pcg32, tally: &mut Tally<C>) -> Vec3 {
        let mut radiance = Vec3::ZERO;
        let mut throughput = Vec3::ONE;
        let mut ray = *ray;
        let mut kind = RayKind::Primary;
        // The density of the last bounce when it was diffuse (emitters were sampled there too).
        let mut bounce_pdf: Option<f32> = None;
        for depth in 0..=self.scene.image.max_depth {
            tally.rays[kind as usize] += 1;
            let Some(hit) = self.world.closest_hit(&ray, &mut tally.work[kind as usize]) else {
                radiance += throughput * self.lights.escaped(ray.dir(), bounce_pdf, self.scene.image.background);
                break;
            };
            let s = Surface::at(self.scene, self.world, &ray, &hit);
            let m = s.material;
            // Surfaces emit from their front side only (outward normal, or the winding's normal).
            if m.emission != Vec3::ZERO && s.entering {
                let weight = match bounce_pdf {
                    Some(pdf) if self.is_sampled_emitter(&hit) => {
                        let pdf_light = self.emitters.area_pdf() * hit.t * hit.t / (-s.d.dot(s.n)).max(1e-12);
                        power_heuristic(pdf, pdf_light)
                    }
                    Some(pdf) => self.lights.emission_weight(hit.object, ray.origin(), pdf).unwrap_or(1.0),
                    _ => 1.0,
                };
                radiance += throughput * m.emission * weight;
            }
            if depth == self.scene.image.max_depth {
                break;
            }
            let (kr, kt) = (m.reflectivity, m.transparency);
            if kr + kt < 1.0 || m.specular != Vec3::ZERO {
                // Direct light at every hit, weighted as the Whitted integrator weights it, so
                // that the first bounce of both integrators agrees.
                let (mut lit, highlight) = s.direct_light(self.scene, self.world, tally);
                if kr + kt < 1.0 && !self.emitters.is_empty() {
                    lit += self.sample_emitters(&s, rng, tally);
                }
                if kr + kt < 1.0 {
                    let lambert = |wi: Vec3| {
                        let cos = s.ns.dot(wi).max(0.0);
                        (m.diffuse / PI * cos, cos / PI)
                    };
                    lit += self.lights.sample(&s, self.world, rng, tally, lambert);
                }
                radiance += throughput * (lit * (1.0 - kr - kt) + highlight);
            }
            bounce_pdf = None;
            let lobe: f32 = rng.random();
            if lobe < kr {
                ray = Ray::new(s.outside(), reflect(s.d, s.n));
                kind = RayKind::Reflected;
            } else if lobe < kr + kt {
                let eta = if s.entering { 1.0 / m.ior } else { m.ior };
                let refracted = refract(s.d, s.n, eta).and_then(|(t_dir, cos_t)| {
                    let f = fresnel_dielectric(-s.d.dot(s.n), cos_t, eta);
                    (rng.random::<f32>() >= f).then_some(t_dir)
                });
                (ray, kind) = match refracted {
                    Some(t_dir) => (Ray::new(s.inside(), t_dir), RayKind::Refracted),
                    None => (Ray::new(s.outside(), reflect(s.d, s.n)), RayKind::Reflected),
                };
            } else {
                let dir = cosine_hemisphere(s.ns, rng.random(), rng.random());
                if dir.dot(s.n) <= 0.0 {
                    break; // a smooth normal bent below the true surface: no light comes from there
                }
                throughput *= m.diffuse;
                bounce_pdf = Some(dir.dot(s.ns) / PI);
                ray = Ray::new(s.outside(), dir);
                kind = RayKind::Bounce;
            }
            if depth >= ROULETTE_AFTER {
                let survive = throughput.max_element().min(1.0);
                if !(rng.random::<f32>() < survive) {
                    break;
                }
                throughput /= survive;
            }
        }
        radiance
    }
}
