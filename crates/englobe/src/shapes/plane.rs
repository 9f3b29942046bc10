//! Infinite planes. They have no finite bounding box, so a [`crate::World`] tests them beside its
//! acceleration structure rather than inside it.

use glam::Vec3;

use super::{Bounded, Intersect};
use crate::PrimHit;
use crate::{Aabb, Ray};

/// The plane of points `p` with `normal · p = offset`; `normal` has unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub normal: Vec3,
    /// Signed distance of the plane from the origin along `normal`.
    pub offset: f32,
}

impl Plane {
    /// The plane through `point` with the given normal (normalised here). Returns `None` for a
    /// zero or non-finite normal.
    pub fn new(normal: Vec3, point: Vec3) -> Option<Self> {
        let n = normal.try_normalize()?;
        Some(Plane { normal: n, offset: n.dot(point) })
    }

    /// The parameter at which the line of `ray` crosses the plane, whatever the ray's interval:
    /// not finite for a ray parallel to the plane (either no point or every point of the ray
    /// lies in it; a ray that slides along a surface does not hit it). With no branch, so that
    /// the rays of a packet compute theirs side by side.
    #[inline(always)]
    pub fn parameter(&self, ray: &Ray) -> f32 {
        (self.offset - self.normal.dot(ray.origin())) / self.normal.dot(ray.dir())
    }

    /// Whether the parameter `t` (see [`Plane::parameter`]) is a hit within `t_min..=t_max`.
    #[inline(always)]
    pub fn hit_within(t: f32, t_min: f32, t_max: f32) -> bool {
        t >= t_min && t <= t_max && t.is_finite()
    }
}

impl Bounded for Plane {
    fn bounds(&self) -> Aabb {
        Aabb::new(Vec3::NEG_INFINITY, Vec3::INFINITY)
    }
}

impl Intersect for Plane {
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<PrimHit> {
        let t = self.parameter(ray);
        Plane::hit_within(t, ray.t_min, ray.t_max).then(|| PrimHit::at(t))
    }

    fn normal(&self, _p: Vec3, _hit: &PrimHit) -> Vec3 {
        self.normal
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hit_from_either_side() {
        let p = Plane::new(Vec3::Y, Vec3::ZERO).unwrap();
        assert_eq!(p.intersect(&Ray::new(Vec3::new(0.0, 2.0, 0.0), -Vec3::Y)).unwrap().t, 2.0);
        assert_eq!(p.intersect(&Ray::new(Vec3::new(3.0, -4.0, 1.0), Vec3::Y)).unwrap().t, 4.0);
    }

    #[test]
    fn parallel_ray_misses_even_in_the_plane() {
        let p = Plane::new(Vec3::Y, Vec3::ZERO).unwrap();
        assert!(p.intersect(&Ray::new(Vec3::new(0.0, 1.0, 0.0), Vec3::X)).is_none());
        assert!(p.intersect(&Ray::new(Vec3::ZERO, Vec3::new(1.0, -0.0, 0.0))).is_none());
    }

    #[test]
    fn pointing_away_misses() {
        let p = Plane::new(Vec3::Y, Vec3::ZERO).unwrap();
        assert!(p.intersect(&Ray::new(Vec3::new(0.0, 2.0, 0.0), Vec3::Y)).is_none());
    }

    #[test]
    fn zero_normal_is_refused() {
        assert!(Plane::new(Vec3::ZERO, Vec3::ONE).is_none());
        assert!(Plane::new(Vec3::new(f32::NAN, 1.0, 0.0), Vec3::ONE).is_none());
    }
}
