//! Emissive spheres as area lights, sampled by solid angle: from a point outside a sphere, the
//! sphere fills a cone of half-angle `θmax` (`sin θmax = r / d`), and directions are drawn
//! uniformly inside that cone, each mapped to the point of the sphere it first meets (Pharr, Jakob
//! and Humphreys, "Physically Based Rendering", 4th ed., section 6.2.4, "Sampling spheres"). Every
//! sample then lands on the visible cap, and the density is `1 / (2π (1 - cos θmax))` over
//! directions, however small or far the sphere.
//!
//! One sphere is chosen per sample, uniformly among the scene's emissive spheres (at most
//! [`MAX_SPHERE_LIGHTS`] of them; further ones are found by bounces alone, with full weight).

use std::f32::consts::PI;

use englobe::{Object, Shape, Vec3};
use englobe_scene::Scene;

use crate::sampling::orthonormal_frame;

/// Most emissive spheres sampled as lights.
pub const MAX_SPHERE_LIGHTS: usize = 1 << 16;

/// One emissive sphere.
#[derive(Clone, Copy, Debug)]
struct SphereLight {
    /// Its object's index in the scene.
    object: u32,
    center: Vec3,
    radius: f32,
    emission: Vec3,
}

/// A point sampled on a sphere light, seen from a point outside it.
#[derive(Clone, Copy, Debug)]
pub struct SphereSample {
    /// The point on the sphere.
    pub point: Vec3,
    /// The unit direction from the shaded point to it.
    pub direction: Vec3,
    /// The radiance it emits towards the shaded point.
    pub radiance: Vec3,
    /// The density of the direction with respect to solid angle (with the choice of the sphere).
    pub pdf: f32,
}

/// The emissive spheres of a scene, in the order of their objects.
#[derive(Clone, Debug, Default)]
pub struct SphereLights {
    lights: Vec<SphereLight>,
}

/// `1 - cos θmax` of the cone a sphere of radius `r` fills seen from distance `d` (with `d² > r²`),
/// without the cancellation of `1 - cos` for small cones.
fn one_minus_cos_max(r2: f32, d2: f32) -> f32 {
    let sin2 = r2 / d2;
    sin2 / (1.0 + (1.0 - sin2).max(0.0).sqrt())
}

impl SphereLights {
    /// The scene's spheres whose material emits light.
    pub fn of(scene: &Scene) -> Self {
        let mut lights = Vec::new();
        for (i, o) in scene.objects.iter().enumerate() {
            if let Object::Shape(Shape::Sphere(s)) = &o.object {
                let emission = scene.materials[o.material_of(0) as usize].emission;
                if emission != Vec3::ZERO && lights.len() < MAX_SPHERE_LIGHTS {
                    lights.push(SphereLight { object: i as u32, center: s.center, radius: s.radius, emission });
                }
            }
        }
        SphereLights { lights }
    }

    /// True if there is nothing to sample.
    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// A point on a sphere light seen from `p`, from three uniform numbers in `[0, 1)`; `None`
    /// if `p` is inside the sphere chosen (nothing there lights it: spheres emit outwards).
    pub fn sample(&self, p: Vec3, u0: f32, u1: f32, u2: f32) -> Option<SphereSample> {
        let n = self.lights.len();
        let light = self.lights.get(((u0 * n as f32) as usize).min(n.checked_sub(1)?))?;
        let to_center = light.center - p;
        let (d2, r2) = (to_center.length_squared(), light.radius * light.radius);
        if !(d2 > r2) {
            return None;
        }
        let d = d2.sqrt();
        let omc_max = one_minus_cos_max(r2, d2);
        // A direction uniform in the cone: 1 - cos θ uniform in [0, 1 - cos θmax].
        let omc = u1 * omc_max;
        let (cos_theta, sin2_theta) = (1.0 - omc, omc * (2.0 - omc));
        // The angle α at the centre between the axis and the point the direction meets first.
        let sin_max = light.radius / d;
        let cos_alpha = sin2_theta / sin_max + cos_theta * (1.0 - sin2_theta / (sin_max * sin_max)).max(0.0).sqrt();
        let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
        let phi = 2.0 * PI * u2;
        let axis = to_center / d;
        let (t, b) = orthonormal_frame(axis);
        let normal = -(t * (sin_alpha * phi.cos()) + b * (sin_alpha * phi.sin()) + axis * cos_alpha);
        let point = light.center + normal * light.radius;
        let direction = (point - p).normalize();
        Some(SphereSample { point, direction, radiance: light.emission, pdf: 1.0 / (n as f32 * 2.0 * PI * omc_max) })
    }

    /// The density with which [`SphereLights::sample`] gives a direction from `p` that first
    /// meets the scene's object `object`, over solid angle: 0 if the object is not a sampled
    /// sphere light or `p` is inside it; `None` if it is not a sampled light at all.
    pub fn pdf(&self, object: u32, p: Vec3) -> Option<f32> {
        let i = self.lights.binary_search_by_key(&object, |l| l.object).ok()?;
        let light = &self.lights[i];
        let (d2, r2) = ((light.center - p).length_squared(), light.radius * light.radius);
        if !(d2 > r2) {
            return Some(0.0);
        }
        Some(1.0 / (self.lights.len() as f32 * 2.0 * PI * one_minus_cos_max(r2, d2)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lights(spheres: &[(Vec3, f32)]) -> SphereLights {
        SphereLights {
            lights: spheres
                .iter()
                .enumerate()
                .map(|(i, &(center, radius))| SphereLight { object: 3 * i as u32, center, radius, emission: Vec3::ONE })
                .collect(),
        }
    }

    #[test]
    fn samples_lie_on_the_visible_cap_inside_the_cone() {
        let center = Vec3::new(0.3, 4.0, -1.0);
        let l = lights(&[(center, 0.5)]);
        let p = Vec3::new(0.0, 0.0, 0.2);
        let d = (center - p).length();
        let cos_max = (1.0 - 0.25 / (d * d)).sqrt();
        let k = 40;
        for i in 0..k {
            for j in 0..k {
                let s = l.sample(p, 0.5, (i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32).unwrap();
                assert!(((s.point - center).length() - 0.5).abs() < 1e-5, "on the sphere");
                assert!((s.point - center).dot(p - center) >= -1e-4, "on the side facing p");
                assert!(s.direction.dot((center - p) / d) >= cos_max - 1e-6, "inside the cone");
                assert!((s.direction - (s.point - p).normalize()).length() < 1e-6);
                assert!((s.pdf - l.pdf(0, p).unwrap()).abs() < 1e-6 * s.pdf);
            }
        }
        assert_eq!(l.pdf(1, p), None, "not a light");
        assert_eq!(l.pdf(0, center), Some(0.0), "inside");
        assert!(l.sample(center + Vec3::X * 0.1, 0.5, 0.5, 0.5).is_none());
    }

    #[test]
    fn the_density_is_uniform_over_the_cone_and_integrates_to_one() {
        // The solid angle of the cone times its density is 1, and the mean of cos θ over
        // uniform directions in the cone is (1 + cos θmax) / 2.
        let l = lights(&[(Vec3::new(0.0, 0.0, 10.0), 3.0), (Vec3::new(0.0, 0.0, -5.0), 1.0)]);
        let p = Vec3::ZERO;
        let cos_max = (1.0f32 - 0.09).sqrt();
        let pdf = l.pdf(0, p).unwrap();
        assert!((pdf * 2.0 * 2.0 * PI * (1.0 - cos_max) - 1.0).abs() < 1e-5, "{pdf}");
        let k = 200;
        let mut sum = 0.0;
        for i in 0..k {
            let s = l.sample(p, 0.25, (i as f32 + 0.5) / k as f32, 0.37).unwrap();
            sum += s.direction.z as f64;
        }
        assert!((sum / k as f64 - (1.0 + cos_max as f64) / 2.0).abs() < 1e-5, "{}", sum / k as f64);
        // The second sphere is chosen for u0 >= 1/2.
        assert!(l.sample(p, 0.75, 0.5, 0.5).unwrap().direction.z < 0.0);
        // A tiny, far sphere keeps its density finite and exact: 1 - cos θmax ~ r²/(2 d²).
        let far = lights(&[(Vec3::new(0.0, 1e4, 0.0), 1e-2)]);
        let pdf = far.pdf(0, Vec3::ZERO).unwrap() as f64;
        assert!((pdf * 2.0 * std::f64::consts::PI * 0.5e-12 - 1.0).abs() < 1e-3, "{pdf}");
    }
}
