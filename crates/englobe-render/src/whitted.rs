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

use englobe::{Counters, Ray, Vec3, World, WorldHit};
use englobe_scene::{Light, Material, Scene};

use crate::optics::{fresnel_dielectric, offset_ray_origin, reflect, refract};
use crate::stats::{RayKind, Tally};

/// Shadow rays toward a point light stop this fraction short of it.
const SHADOW_RAY_END: f32 = 1.0 - 1e-4;

/// The Whitted integrator over a scene and its world (built from the scene's objects, in order).
pub struct Whitted<'a> {
    scene: &'a Scene,
    world: &'a World,
}

impl<'a> Whitted<'a> {
    /// The integrator. `world` must hold the scene's objects in the scene's order.
    pub fn new(scene: &'a Scene, world: &'a World) -> Self {
        Whitted { scene, world }
    }

    /// The material at a hit: the object's, or its triangle's when the mesh gives one per triangle.
    fn material(&self, hit: &WorldHit) -> &Material {
        let id = self.scene.objects[hit.object as usize].material_of(hit.prim);
        &self.scene.materials[id as usize]
    }

    /// The colour seen along `ray`, a ray of `kind` at recursion `depth` (0 for primary rays).
    pub fn radiance<C: Counters>(&self, ray: &Ray, kind: RayKind, depth: u32, tally: &mut Tally<C>) -> Vec3 {
        tally.rays[kind as usize] += 1;
        let Some(hit) = self.world.closest_hit(ray, &mut tally.work[kind as usize]) else {
            return self.scene.image.background;
        };
        let m = self.material(&hit);
        let p = self.world.hit_point(ray, &hit);
        let d = ray.dir().normalize();
        let geometric = self.world.geometric_normal(&hit, p);
        let entering = d.dot(geometric) < 0.0;
        // Normals facing the side the ray came from.
        let n = if entering { geometric } else { -geometric };
        let shading = self.world.shading_normal(&hit, p);
        let ns = if shading.dot(n) < 0.0 { -shading } else { shading };

        let (kr, kt) = (m.reflectivity, m.transparency);
        let mut diffuse = self.scene.image.ambient * m.diffuse;
        let mut highlight = Vec3::ZERO;
        let lit_side = offset_ray_origin(p, n);
        for light in &self.scene.lights {
            let (shadow_ray, to_light, radiance) = match *light {
                Light::Point { position, power } => {
                    // Shading uses the true point; only the shadow ray starts off the surface.
                    let v = position - p;
                    let dist2 = v.length_squared();
                    let shadow = Ray::segment(lit_side, position - lit_side, 0.0, SHADOW_RAY_END);
                    (shadow, v / dist2.sqrt(), power / dist2)
                }
                Light::Directional { direction, radiance } => (Ray::new(lit_side, -direction), -direction, radiance),
            };
            if to_light.dot(n) <= 0.0 || !to_light.is_finite() {
                continue; // the light is behind the surface
            }
            tally.rays[RayKind::Shadow as usize] += 1;
            if self.world.any_hit(&shadow_ray, &mut tally.work[RayKind::Shadow as usize]) {
                continue;
            }
            diffuse += m.diffuse * ns.dot(to_light).max(0.0) * radiance;
            if m.specular != Vec3::ZERO {
                let half = (to_light - d).normalize_or_zero();
                highlight += m.specular * ns.dot(half).max(0.0).powf(m.shininess) * radiance;
            }
        }
        let mut color = m.emission + diffuse * (1.0 - kr - kt) + highlight;

        if depth >= self.scene.image.max_depth {
            return color;
        }
        let mut mirror_weight = kr;
        if kt > 0.0 {
            let eta = if entering { 1.0 / m.ior } else { m.ior };
            match refract(d, n, eta) {
                None => mirror_weight += kt, // total internal reflection
                Some((t_dir, cos_t)) => {
                    let cos_i = -d.dot(n);
                    let f = fresnel_dielectric(cos_i, cos_t, eta);
                    mirror_weight += kt * f;
                    let refracted = Ray::new(offset_ray_origin(p, -n), t_dir);
                    color += self.radiance(&refracted, RayKind::Refracted, depth + 1, tally) * (kt * (1.0 - f));
                }
            }
        }
        if mirror_weight > 0.0 {
            let reflected = Ray::new(lit_side, reflect(d, n));
            color += self.radiance(&reflected, RayKind::Reflected, depth + 1, tally) * mirror_weight;
        }
        color
    }
}
