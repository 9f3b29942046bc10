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

use englobe::{Counters, Object, Ray, Shape, Vec2, Vec3, World, WorldHit};
use englobe_scene::{MaterialModel, Scene};
use rand::{Rng, RngExt};

use crate::bsdf::{Bsdf, Frame, SampleKind, TrowbridgeReitz};
use crate::emitters::{Emitters, power_heuristic};
use crate::light_sampling::SampledLights;
use crate::optics::{fresnel_dielectric, reflect, refract};
use crate::ray_cone::RayCone;
use crate::sampling::cosine_hemisphere;
use crate::shading::{PlainMaterials, SHADOW_RAY_END, Surface};
use crate::stats::{RayKind, Tally};
use crate::visibility::Visibility;

/// Bounces before Russian roulette may end a path.
const ROULETTE_AFTER: u32 = 3;

/// The path tracer over a scene and its world (built from the scene's objects, in order).
pub struct PathTracer<'a> {
    scene: &'a Scene,
    world: &'a World,
    vis: Visibility<'a>,
    emitters: Emitters,
    lights: SampledLights,
    cone: Option<RayCone>,
    plain: PlainMaterials,
}

/// Where a path goes from a hit: the next ray, its kind, the factor on the throughput and the
/// density of its direction when emitters were sampled at the hit too (for their MIS weights).
struct Scatter {
    ray: Ray,
    kind: RayKind,
    weight: Vec3,
    pdf: Option<f32>,
}

impl<'a> PathTracer<'a> {
    /// The integrator. `world` must hold the scene's objects in the scene's order.
    pub fn new(scene: &'a Scene, world: &'a World) -> Self {
        PathTracer {
            scene,
            world,
            vis: Visibility::new(scene, world),
            emitters: Emitters::of(scene),
            lights: SampledLights::of(scene),
            cone: None,
            plain: PlainMaterials::new(scene),
        }
    }

    /// The integrator with textures read over the footprint of the primary rays' cone `cone`
    /// (see [`crate::ray_cone`]; `None`: at the hit points). Only the first hit is filtered: a
    /// diffuse bounce's cone would cover whole objects.
    pub fn with_cone(mut self, cone: Option<RayCone>) -> Self {
        self.cone = cone;
        self
    }

    /// True if the hit lies on a triangle, which [`Emitters`] samples when it emits.
    fn is_sampled_emitter(&self, hit: &WorldHit, s: &Surface) -> bool {
        Emitters::samples(s.material)
            && matches!(
                self.world.objects()[hit.object as usize],
                Object::Shape(Shape::Triangle(_)) | Object::Mesh(_) | Object::Instance(_)
            )
    }

    /// Light from one point sampled on the emissive triangles, reflected at `s` by `bsdf` (which
    /// gives `f * cos` and the density of sampling that direction), with its power-heuristic
    /// weight.
    fn sample_emitters<C: Counters>(
        &self,
        s: &Surface,
        rng: &mut impl Rng,
        tally: &mut Tally<C>,
        bsdf: impl Fn(Vec3) -> (Vec3, f32),
    ) -> Vec3 {
        let Some(e) = self.emitters.sample(rng.random(), rng.random(), rng.random()) else {
            return Vec3::ZERO;
        };
        let v = e.point - s.p;
        let dist2 = v.length_squared();
        let wi = v / dist2.sqrt();
        let cos_l = -e.normal.dot(wi);
        if !(cos_l > 0.0 && wi.dot(s.n) > 0.0) {
            return Vec3::ZERO;
        }
        let (f_cos, pdf_bounce) = bsdf(wi);
        if f_cos == Vec3::ZERO {
            return Vec3::ZERO;
        }
        let origin = s.outside();
        tally.rays[RayKind::Shadow as usize] += 1;
        let shadow = Ray::segment(origin, e.point - origin, 0.0, SHADOW_RAY_END);
        if self.vis.any_hit(&shadow, &mut tally.work[RayKind::Shadow as usize]) {
            return Vec3::ZERO;
        }
        let pdf_light = self.emitters.area_pdf() * dist2 / cos_l;
        f_cos * e.emission * (power_heuristic(pdf_light, pdf_bounce) / pdf_light)
    }

    /// A surface with a BSDF ([`surface_bsdf`], see [`crate::bsdf`]): light from
    /// the point and directional lights and from the emitters, added to `radiance`, and where the
    /// path goes on, drawn from the BSDF.
    fn scatter_microfacet<C: Counters>(
        &self,
        s: &Surface,
        rng: &mut impl Rng,
        tally: &mut Tally<C>,
        throughput: Vec3,
        radiance: &mut Vec3,
    ) -> Option<Scatter> {
        let bsdf = surface_bsdf(s);
        // The frame of a transmitting BSDF must face outward; the others are two-sided.
        let frame = Frame::from_z(if s.entering { s.ns } else { -s.ns });
        let wo = frame.to_local(-s.d);
        if !bsdf.is_delta() {
            let f_cos = |wi: Vec3| {
                let l = frame.to_local(wi);
                (bsdf.eval(wo, l) * l.z.abs(), bsdf.pdf(wo, l))
            };
            // Point and directional lights: their intensities are pi times radiant intensities
            // (see `crate::shading`), so f * cos * pi * radiance.
            let mut lit = Vec3::ZERO;
            s.for_each_light(self.scene, &self.vis, tally, |wi, light| lit += f_cos(wi).0 * PI * light);
            if !self.emitters.is_empty() {
                lit += self.sample_emitters(s, rng, tally, f_cos);
            }
            lit += self.lights.sample(s, &self.vis, rng, tally, f_cos);
            *radiance += throughput * lit;
        }
        let sample = bsdf.sample(wo, rng.random(), Vec2::new(rng.random(), rng.random()))?;
        let wi = frame.from_local(sample.wi);
        let through = sample.kind == SampleKind::Transmission;
        // A direction on the wrong side of the true surface (a bent shading normal): no light
        // comes from there.
        if (wi.dot(s.n) > 0.0) == through {
            return None;
        }
        let kind = match (through, sample.delta) {
            (true, _) => RayKind::Refracted,
            (false, true) => RayKind::Reflected,
            (false, false) => RayKind::Bounce,
        };
        let origin = if through { s.inside() } else { s.outside() };
        let pdf = (!sample.delta && !bsdf.is_delta()).then_some(sample.pdf);
        Some(Scatter { ray: Ray::new(origin, wi), kind, weight: sample.weight, pdf })
    }

    /// The seed's model (see the module's documentation): direct light through the Whitted
    /// weights plus the emitters, then one lobe drawn by its weight.
    fn scatter_classic<C: Counters>(
        &self,
        s: &Surface,
        rng: &mut impl Rng,
        tally: &mut Tally<C>,
        throughput: Vec3,
        radiance: &mut Vec3,
    ) -> Option<Scatter> {
        let m = s.material;
        let base = s.params.base_color;
        let (kr, kt) = (m.reflectivity, m.transparency);
        if kr + kt < 1.0 || m.specular != Vec3::ZERO {
            // Direct light at every hit, weighted as the Whitted integrator weights it, so
            // that the first bounce of both integrators agrees.
            let (mut lit, highlight) = s.direct_light(self.scene, &self.vis, tally);
            if kr + kt < 1.0 && !self.emitters.is_empty() {
                let lambert = |wi: Vec3| {
                    let cos = s.ns.dot(wi).max(0.0);
                    (base / PI * cos, cos / PI)
                };
                lit += self.sample_emitters(s, rng, tally, lambert);
            }
            if kr + kt < 1.0 {
                let lambert = |wi: Vec3| {
                    let cos = s.ns.dot(wi).max(0.0);
                    (base / PI * cos, cos / PI)
                };
                lit += self.lights.sample(s, &self.vis, rng, tally, lambert);
            }
            *radiance += throughput * (lit * (1.0 - kr - kt) + highlight);
        }
        let lobe: f32 = rng.random();
        if lobe < kr {
            let ray = Ray::new(s.outside(), reflect(s.d, s.n));
            return Some(Scatter { ray, kind: RayKind::Reflected, weight: Vec3::ONE, pdf: None });
        }
        if lobe < kr + kt {
            let eta = if s.entering { 1.0 / m.ior } else { m.ior };
            let refracted = refract(s.d, s.n, eta).and_then(|(t_dir, cos_t)| {
                let f = fresnel_dielectric(-s.d.dot(s.n), cos_t, eta);
                (rng.random::<f32>() >= f).then_some(t_dir)
            });
            let (ray, kind) = match refracted {
                Some(t_dir) => (Ray::new(s.inside(), t_dir), RayKind::Refracted),
                None => (Ray::new(s.outside(), reflect(s.d, s.n)), RayKind::Reflected),
            };
            return Some(Scatter { ray, kind, weight: Vec3::ONE, pdf: None });
        }
        let dir = cosine_hemisphere(s.ns, rng.random(), rng.random());
        if dir.dot(s.n) <= 0.0 {
            return None; // a smooth normal bent below the true surface: no light comes from there
        }
        let pdf = Some(dir.dot(s.ns) / PI);
        Some(Scatter { ray: Ray::new(s.outside(), dir), kind: RayKind::Bounce, weight: base, pdf })
    }

    /// What decides which surfaces its rays see.
    pub(crate) fn visibility(&self) -> &Visibility<'a> {
        &self.vis
    }

    /// One estimate of the radiance along the primary ray `ray`.
    pub fn radiance<C: Counters>(&self, ray: &Ray, rng: &mut impl Rng, tally: &mut Tally<C>) -> Vec3 {
        self.radiance_from(ray, None, rng, tally)
    }

    /// [`PathTracer::radiance`] of a primary `ray` whose closest hit is `first` if it was found
    /// already (by a packet of primary rays): `Some(hit)`, `hit` being `None` for a miss.
    pub fn radiance_from<C: Counters>(
        &self,
        ray: &Ray,
        mut first: Option<Option<WorldHit>>,
        rng: &mut impl Rng,
        tally: &mut Tally<C>,
    ) -> Vec3 {
        let mut radiance = Vec3::ZERO;
        let mut throughput = Vec3::ONE;
        let mut ray = *ray;
        let mut kind = RayKind::Primary;
        // The density of the last bounce when emitters were sampled there too.
        let mut bounce_pdf: Option<f32> = None;
        for depth in 0..=self.scene.image.max_depth {
            tally.rays[kind as usize] += 1;
            let found = match first.take() {
                Some(hit) => hit,
                None => self.vis.closest_hit(&ray, &mut tally.work[kind as usize]),
            };
            let Some(hit) = found else {
                radiance += throughput * self.lights.escaped(ray.dir(), bounce_pdf, self.scene.image.background);
                break;
            };
            let cone = if depth == 0 { self.cone } else { None };
            let s = Surface::at_over(self.scene, &self.plain, self.world, &ray, &hit, cone);
            // Surfaces emit from their front side only (outward normal, or the winding's normal),
            // as physical lamps do.
            let emission = s.params.emission;
            if emission != Vec3::ZERO && s.entering {
                let weight = match bounce_pdf {
                    Some(pdf) if self.is_sampled_emitter(&hit, &s) => {
                        let pdf_light = self.emitters.area_pdf() * hit.t * hit.t / (-s.d.dot(s.n)).max(1e-12);
                        power_heuristic(pdf, pdf_light)
                    }
                    Some(pdf) => self.lights.emission_weight(hit.object, ray.origin(), pdf).unwrap_or(1.0),
                    _ => 1.0,
                };
                radiance += throughput * emission * weight;
            }
            if depth == self.scene.image.max_depth {
                break;
            }
            let next = match s.material.model {
                MaterialModel::Classic => self.scatter_classic(&s, rng, tally, throughput, &mut radiance),
                _ => self.scatter_microfacet(&s, rng, tally, throughput, &mut radiance),
            };
            let Some(next) = next else { break };
            throughput *= next.weight;
            (ray, kind, bounce_pdf) = (next.ray, next.kind, next.pdf);
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

/// The BSDF of a surface whose material is not classic: glTF's metallic-roughness model, or
/// pbrt-v4's conductor, dielectric and coated diffuse (see `englobe_scene::MaterialModel`).
fn surface_bsdf(s: &Surface) -> Bsdf {
    let p = &s.params;
    match s.material.model {
        MaterialModel::Conductor { eta, k, alpha } => Bsdf::conductor(eta, k, TrowbridgeReitz::isotropic(alpha)),
        MaterialModel::Dielectric { alpha } => Bsdf::dielectric(p.ior, TrowbridgeReitz::isotropic(alpha)),
        MaterialModel::CoatedDiffuse { alpha } => Bsdf::plastic(p.base_color, alpha, p.ior),
        _ => Bsdf::metallic_roughness(p.base_color, p.metallic, p.roughness, p.transmission, p.ior),
    }
}
