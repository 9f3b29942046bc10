//! The Whitted integrator (Whitted 1980, "An Improved Illumination Model for Shaded Display"), the
//! seed report's setting: at every hit, one shadow ray per light, one mirror ray and, through
//! transparent surfaces, one refracted ray, recursively up to a maximum depth.
//!
//! The colour of a hit is
//! `emission + (1 - kr - kt) * (ambient + diffuse) + specular + kr * R + kt * (F * R + (1 - F) * T)`
//! where `R` and `T` are the colours seen along the reflected and refracted rays, `kr` and `kt` the
//! material's reflectivity and transparency, and `F` the Fresnel reflectance of the dielectric
//! (1 under total internal reflection). A material with `kt = 1`, index 1 and no highlight is thus
//! exactly invisible: its colour is `T`, and `T` is the colour behind it.
//!
//! Rays that hit nothing see the scene's environment (looked up, never sampled: the lights are
//! the point and directional ones), or its background.
//!
//! Adaptive depth (Hall and Greenberg 1983, "A Testbed for Realistic Image Synthesis"): a
//! secondary ray's contribution to its pixel is the product of the factors (`kr`, `kt (1 - F)`,
//! ...) along its path; with the scene's `min_contribution`, a ray whose contribution would fall
//! below it is not cast, so that deep trees are cut where they no longer change the pixel, instead
//! of at one fixed depth for every path.
//!
//! Textures shade it as they shade the path tracer (base colour, highlight colour, emission, normal
//! maps, cut-outs); a metallic-roughness material reaches it as its diffuse base colour. With the
//! scene's `texture_filter = "cone"`, every ray carries a cone (see [`crate::ray_cone`]) that
//! its reflections and refractions continue, and textures are read over its footprint.

use englobe::{Counters, Ray, Vec3, World, WorldHit};
use englobe_scene::Scene;

use crate::environment::EnvironmentLight;
use crate::optics::{fresnel_dielectric, reflect, refract};
use crate::ray_cone::RayCone;
use crate::shading::{PlainMaterials, Surface, shadow_ray};
use crate::stats::{RayKind, Tally};
use crate::visibility::Visibility;

/// Most primary rays [`Whitted::radiance_packet`] takes at once.
pub const PACKET: usize = 16;

/// The Whitted integrator over a scene and its world (built from the scene's objects, in order).
pub struct Whitted<'a> {
    scene: &'a Scene,
    world: &'a World,
    vis: Visibility<'a>,
    environment: Option<EnvironmentLight>,
    cone: Option<RayCone>,
    plain: PlainMaterials,
}

impl<'a> Whitted<'a> {
    /// The integrator. `world` must hold the scene's objects in the scene's order.
    pub fn new(scene: &'a Scene, world: &'a World) -> Self {
        Whitted {
            scene,
            world,
            vis: Visibility::new(scene, world),
            environment: scene.environment.as_ref().map(EnvironmentLight::new),
            cone: None,
            plain: PlainMaterials::new(scene),
        }
    }

    /// The integrator with textures read over the footprints of ray cones, `cone` being the
    /// primary rays' (`None`: at the hit points).
    pub fn with_cone(mut self, cone: Option<RayCone>) -> Self {
        self.cone = cone;
        self
    }

    /// What decides which surfaces its rays see.
    pub(crate) fn visibility(&self) -> &Visibility<'a> {
        &self.vis
    }

    /// The colour seen along a primary `ray`.
    pub fn radiance<C: Counters>(&self, ray: &Ray, tally: &mut Tally<C>) -> Vec3 {
        self.trace(ray, RayKind::Primary, 0, 1.0, self.cone, tally)
    }

    /// [`Whitted::radiance`] of a primary `ray` whose closest hit, `hit`, was found already (by a
    /// packet of primary rays).
    pub fn radiance_from<C: Counters>(&self, ray: &Ray, hit: Option<WorldHit>, tally: &mut Tally<C>) -> Vec3 {
        tally.rays[RayKind::Primary as usize] += 1;
        self.shade(ray, hit, 0, 1.0, self.cone, tally)
    }

    /// The colour seen along `ray`, a ray of `kind` at recursion `depth` (0 for primary rays)
    /// whose colour reaches the pixel multiplied by `weight`, and whose cone is `cone`.
    #[allow(clippy::too_many_arguments)]
    fn trace<C: Counters>(
        &self,
        ray: &Ray,
        kind: RayKind,
        depth: u32,
        weight: f32,
        cone: Option<RayCone>,
        tally: &mut Tally<C>,
    ) -> Vec3 {
        tally.rays[kind as usize] += 1;
        let hit = self.vis.closest_hit(ray, &mut tally.work[kind as usize]);
        self.shade(ray, hit, depth, weight, cone, tally)
    }

    /// [`Whitted::radiance_from`] of each primary ray, `out[i]` for `rays[i]` and its closest hit
    /// `hits[i]`, the shadow rays toward each light traced together, in packets (see
    /// [`Visibility::any_hit_packet`]). Each surface sums its lights in the scene's order, as
    /// [`Surface::direct_light`] does, so every colour is the same bits as `radiance_from`'s.
    pub fn radiance_packet<C: Counters>(
        &self,
        rays: &[Ray],
        hits: &[Option<WorldHit>],
        tally: &mut Tally<C>,
        out: &mut [Vec3],
    ) {
        let n = rays.len();
        assert!(n <= PACKET && hits.len() == n && out.len() == n, "a packet holds at most {PACKET} rays");
        tally.rays[RayKind::Primary as usize] += n as u64;
        // The hits' triangles are loaded together first: one after the other, their cache
        // misses (the triangle tree keeps its own copies of the vertices) would add up.
        for hit in hits.iter().flatten() {
            self.world.prefetch_shading(hit);
        }
        // Filled in place: a surface is large, and copies of it cost more than its shading.
        let mut surfaces: [Option<Surface>; PACKET] = std::array::from_fn(|_| None);
        for ((slot, ray), hit) in surfaces.iter_mut().zip(rays).zip(hits) {
            if let Some(hit) = hit {
                *slot = Some(Surface::at_over(self.scene, &self.plain, self.world, ray, hit, self.cone));
            }
        }
        let origins: [Vec3; PACKET] = std::array::from_fn(|i| surfaces[i].as_ref().map_or(Vec3::ZERO, |s| s.outside()));
        let mut light = [(Vec3::ZERO, Vec3::ZERO); PACKET];
        for source in &self.scene.lights {
            // The shadow rays of the surfaces in front of which this light is, side by side.
            let mut shadow = [Ray::new(Vec3::ZERO, Vec3::Z); PACKET];
            let mut arriving = [(0usize, Vec3::ZERO, Vec3::ZERO); PACKET];
            // Every surface's direction to the light first, with no branch on it, so that their
            // square roots and divisions overlap; then the surfaces in front of the light.
            let mut toward = [(Vec3::ZERO, Vec3::ZERO); PACKET];
            for (t, s) in toward.iter_mut().zip(&surfaces) {
                if let Some(s) = s {
                    *t = s.light_toward(source);
                }
            }
            let mut count = 0;
            for (i, (s, &(to_light, radiance))) in surfaces.iter().zip(&toward).enumerate() {
                if let Some(s) = s
                    && s.faces(to_light)
                {
                    shadow[count] = shadow_ray(source, origins[i]);
                    arriving[count] = (i, to_light, radiance);
                    count += 1;
                }
            }
            if count == 0 {
                continue;
            }
            tally.rays[RayKind::Shadow as usize] += count as u64;
            let mut blocked = [false; PACKET];
            self.vis.any_hit_packet(&shadow[..count], &mut blocked[..count], &mut tally.work[RayKind::Shadow as usize]);
            for (&(i, to_light, radiance), _) in arriving[..count].iter().zip(blocked).filter(|(_, b)| !b) {
                let s = surfaces[i].as_ref().expect("a shadow ray leaves a surface");
                let (d, h) = s.light_response(to_light, radiance);
                light[i].0 += d;
                light[i].1 += h;
            }
        }
        for (i, color) in out.iter_mut().enumerate() {
            *color = match &surfaces[i] {
                Some(s) => self.shade_lit(&rays[i], s, light[i], 0, 1.0, self.cone, tally),
                None => self.shade(&rays[i], None, 0, 1.0, self.cone, tally),
            };
        }
    }

    /// The colour seen along `ray` (see [`Whitted::trace`]), whose closest hit is `hit`.
    fn shade<C: Counters>(
        &self,
        ray: &Ray,
        hit: Option<WorldHit>,
        depth: u32,
        weight: f32,
        cone: Option<RayCone>,
        tally: &mut Tally<C>,
    ) -> Vec3 {
        let Some(hit) = hit else {
            return self.environment.as_ref().map_or(self.scene.image.background, |e| e.radiance(ray.dir()));
        };
        let s = Surface::at_over(self.scene, &self.plain, self.world, ray, &hit, cone);
        let (lit, highlight) = s.direct_light(self.scene, &self.vis, tally);
        self.shade_lit(ray, &s, (lit, highlight), depth, weight, cone, tally)
    }

    /// The colour seen along `ray` (see [`Whitted::trace`]), whose closest hit is the surface `s`
    /// and the direct light `(lit, highlight)` it receives (see [`Surface::direct_light`]).
    #[allow(clippy::too_many_arguments)]
    fn shade_lit<C: Counters>(
        &self,
        ray: &Ray,
        s: &Surface,
        (lit, highlight): (Vec3, Vec3),
        depth: u32,
        weight: f32,
        cone: Option<RayCone>,
        tally: &mut Tally<C>,
    ) -> Vec3 {
        let m = s.material;
        let (kr, kt) = (m.reflectivity, m.transparency);
        let diffuse = self.scene.image.ambient * s.params.base_color * s.params.occlusion + lit;
        let mut color = s.params.emission + diffuse * (1.0 - kr - kt) + highlight;

        if depth >= self.scene.image.max_depth {
            return color;
        }
        let worth = |factor: f32| weight * factor >= self.scene.image.min_contribution;
        let cone = cone.map(|c| c.continued((s.p - ray.origin()).length()));
        let mut mirror_weight = kr;
        if kt > 0.0 {
            let eta = if s.entering { 1.0 / m.ior } else { m.ior };
            match refract(s.d, s.n, eta) {
                None => mirror_weight += kt, // total internal reflection
                Some((t_dir, cos_t)) => {
                    let cos_i = -s.d.dot(s.n);
                    let f = fresnel_dielectric(cos_i, cos_t, eta);
                    mirror_weight += kt * f;
                    let factor = kt * (1.0 - f);
                    if worth(factor) {
                        let refracted = Ray::new(s.inside(), t_dir);
                        color += self.trace(&refracted, RayKind::Refracted, depth + 1, weight * factor, cone, tally)
                            * factor;
                    }
                }
            }
        }
        if mirror_weight > 0.0 && worth(mirror_weight) {
            let reflected = Ray::new(s.outside(), reflect(s.d, s.n));
            let seen = self.trace(&reflected, RayKind::Reflected, depth + 1, weight * mirror_weight, cone, tally);
            color += seen * mirror_weight;
        }
        color
    }
}
