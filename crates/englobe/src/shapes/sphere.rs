//! Spheres.
//!
//! The intersection follows Haines, Günther and Akenine-Möller (2019), "Precision Improvements for
//! Ray/Sphere Intersection" (Ray Tracing Gems, chapter 7): the discriminant is computed from the
//! distance between the centre and the ray's line rather than as `b² - 4ac`, and the nearer root
//! from `c / q`, which keeps small spheres far away accurate where the textbook formula cancels
//! catastrophically. The arithmetic runs in `f64`: it costs little on one shape and keeps `t`
//! accurate to `f32` precision over the whole range `f32` coordinates can hold.

use glam::{DVec3, Vec3};

use super::{Bounded, Intersect};
use crate::PrimHit;
use crate::{Aabb, Ray};

/// A sphere of centre `center` and radius `radius > 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius; positive.
    pub radius: f32,
}

impl Sphere {
    /// A sphere. The radius is expected positive and finite (scene loaders check it).
    pub fn new(center: Vec3, radius: f32) -> Self {
        Sphere { center, radius }
    }

    /// Both parameters where the ray's line crosses the sphere, nearest first, or `None` if it
    /// misses. Tangent rays give two equal roots.
    pub fn roots(&self, ray: &Ray) -> Option<(f64, f64)> {
        let f = ray.origin().as_dvec3() - self.center.as_dvec3();
        let d = ray.dir().as_dvec3();
        let r = self.radius as f64;
        let a = d.dot(d);
        let b = -f.dot(d); // half of -b in the textbook formula
        // Squared distance from the centre to the line, computed without cancellation.
        let l = f + d * (b / a);
        let discriminant = a * (r * r - l.dot(l));
        if discriminant < 0.0 || discriminant.is_nan() {
            return None;
        }
        let c = f.dot(f) - r * r;
        let q = b + discriminant.sqrt().copysign(b);
        if q == 0.0 {
            // Both roots coincide at the origin (origin on the sphere, ray tangent).
            return Some((0.0, 0.0));
        }
        let (t0, t1) = (c / q, q / a);
        Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
    }

    /// Moves a point computed as `origin + t * dir` back onto the surface, which shrinks the error
    /// of hit points far from the ray's origin before they start secondary rays.
    pub fn project_to_surface(&self, p: Vec3) -> Vec3 {
        let c = self.center.as_dvec3();
        let d: DVec3 = p.as_dvec3() - c;
        let len = d.length();
        if len == 0.0 { p } else { (c + d * (self.radius as f64 / len)).as_vec3() }
    }
}

impl Bounded for Sphere {
    fn bounds(&self) -> Aabb {
        Aabb::new(self.center - Vec3::splat(self.radius), self.center + Vec3::splat(self.radius))
    }
}

impl Intersect for Sphere {
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<PrimHit> {
        let (t0, t1) = self.roots(ray)?;
        let (lo, hi) = (ray.t_min as f64, ray.t_max as f64);
        [t0, t1]
            .into_iter()
            .map(|t| t as f32)
            .find(|&t| (lo..=hi).contains(&(t as f64)) && t.is_finite())
            .map(PrimHit::at)
    }

    fn normal(&self, p: Vec3, _hit: &PrimHit) -> Vec3 {
        (p.as_dvec3() - self.center.as_dvec3()).normalize_or_zero().as_vec3()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> Sphere {
        Sphere::new(Vec3::ZERO, 1.0)
    }

    #[test]
    fn from_outside_hits_the_near_side() {
        let hit = unit().intersect(&Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z)).unwrap();
        assert_eq!(hit.t, 4.0);
        assert_eq!(unit().normal(Vec3::new(0.0, 0.0, -1.0), &hit), -Vec3::Z);
    }

    #[test]
    fn from_inside_hits_the_far_side() {
        let hit = unit().intersect(&Ray::new(Vec3::ZERO, Vec3::new(0.0, 2.0, 0.0))).unwrap();
        assert_eq!(hit.t, 0.5);
    }

    #[test]
    fn tangent_ray_touches_once() {
        let hit = unit().intersect(&Ray::new(Vec3::new(1.0, 0.0, -3.0), Vec3::Z)).unwrap();
        assert!((hit.t - 3.0).abs() < 1e-6);
        assert!(unit().intersect(&Ray::new(Vec3::new(1.0001, 0.0, -3.0), Vec3::Z)).is_none());
    }

    #[test]
    fn sphere_behind_the_ray_is_missed() {
        assert!(unit().intersect(&Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z)).is_none());
    }

    #[test]
    fn interval_is_respected() {
        let ray = Ray::segment(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 0.0, 3.9);
        assert!(unit().intersect(&ray).is_none());
        let ray = Ray::segment(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 4.5, 10.0);
        assert_eq!(unit().intersect(&ray).unwrap().t, 6.0);
    }

    #[test]
    fn small_sphere_far_away_is_accurate() {
        // A sphere of radius 1e-3 at a distance of 1e5: the textbook f32 formula loses every digit.
        let s = Sphere::new(Vec3::new(0.0, 0.0, 1.0e5), 1.0e-3);
        let hit = s.intersect(&Ray::new(Vec3::ZERO, Vec3::Z)).expect("must be hit");
        assert_eq!(hit.t, 1.0e5 - 1.0e-3);
        // Grazing the edge: still a hit just inside, a miss just outside.
        assert!(s.intersect(&Ray::new(Vec3::new(0.9e-3, 0.0, 0.0), Vec3::Z)).is_some());
        assert!(s.intersect(&Ray::new(Vec3::new(1.1e-3, 0.0, 0.0), Vec3::Z)).is_none());
    }

    #[test]
    fn unnormalised_directions_give_parameters_in_their_units() {
        let hit = unit().intersect(&Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::new(0.0, 0.0, 4.0))).unwrap();
        assert_eq!(hit.t, 1.0);
    }

    #[test]
    fn zero_direction_components_give_no_nan() {
        let ray = Ray::new(Vec3::new(0.5, 0.0, -5.0), Vec3::new(0.0, -0.0, 1.0));
        let hit = unit().intersect(&ray).unwrap();
        assert!(hit.t.is_finite());
        assert!((hit.t - (5.0 - 0.75f32.sqrt())).abs() < 1e-6);
    }

    #[test]
    fn surface_projection() {
        let p = unit().project_to_surface(Vec3::new(0.0, 2.0, 0.0));
        assert_eq!(p, Vec3::Y);
    }
}
