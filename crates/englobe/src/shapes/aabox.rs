//! Axis-aligned boxes as solid shapes (as opposed to [`crate::Aabb`], the bounding volume).

use glam::Vec3;

use super::{Bounded, Intersect};
use crate::PrimHit;
use crate::{Aabb, Ray};

/// A solid axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AaBox {
    /// Its extent.
    pub bounds: Aabb,
}

impl AaBox {
    /// The box spanning two opposite corners, in any order.
    pub fn new(a: Vec3, b: Vec3) -> Self {
        AaBox { bounds: Aabb::new(a.min(b), a.max(b)) }
    }
}

impl Bounded for AaBox {
    fn bounds(&self) -> Aabb {
        self.bounds
    }
}

impl Intersect for AaBox {
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<PrimHit> {
        // The unwidened slab test over the whole line: a surface needs the exact crossing points.
        let line = ray.with_range(f32::NEG_INFINITY, f32::INFINITY);
        let (t_enter, t_exit) = self.bounds.slab_distances(&line, 1.0);
        if t_enter > t_exit || t_enter.is_nan() || t_exit.is_nan() {
            return None;
        }
        // A ray starting inside (or on the surface going in) leaves through the far side.
        [t_enter, t_exit].into_iter().find(|&t| t >= ray.t_min && t <= ray.t_max && t.is_finite()).map(PrimHit::at)
    }

    fn normal(&self, p: Vec3, _hit: &PrimHit) -> Vec3 {
        // The face whose plane the point is closest to, relative to the box's half size.
        let c = self.bounds.center();
        let half = (self.bounds.extent() * 0.5).max(Vec3::splat(f32::MIN_POSITIVE));
        let d = (p - c) / half;
        let a = d.abs();
        let axis = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut n = Vec3::ZERO;
        n[axis] = if d[axis] >= 0.0 { 1.0 } else { -1.0 };
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> AaBox {
        AaBox::new(Vec3::splat(1.0), Vec3::splat(-1.0))
    }

    #[test]
    fn hit_from_all_six_sides_with_the_right_normal() {
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let mut o = Vec3::ZERO;
                o[axis] = 3.0 * sign;
                let ray = Ray::new(o, -o);
                let hit = cube().intersect(&ray).expect("hit");
                assert!((hit.t - 2.0 / 3.0).abs() < 1e-6);
                let n = cube().normal(ray.at(hit.t), &hit);
                assert_eq!(n, o / 3.0);
            }
        }
    }

    #[test]
    fn from_inside_exits() {
        let ray = Ray::new(Vec3::new(0.5, 0.0, 0.0), Vec3::X);
        let hit = cube().intersect(&ray).unwrap();
        assert_eq!(hit.t, 0.5);
        assert_eq!(cube().normal(ray.at(hit.t), &hit), Vec3::X);
    }

    #[test]
    fn zero_components_and_origin_on_a_face() {
        let ray = Ray::new(Vec3::new(1.0, 0.0, -4.0), Vec3::new(-0.0, 0.0, 1.0));
        let hit = cube().intersect(&ray).expect("ray in the face plane meets the box");
        assert_eq!(hit.t, 3.0);
        let ray = Ray::new(Vec3::new(1.0, 0.2, 0.3), -Vec3::X);
        assert_eq!(cube().intersect(&ray).unwrap().t, 0.0);
        let ray = Ray::new(Vec3::new(1.5, 0.0, -4.0), Vec3::Z);
        assert!(cube().intersect(&ray).is_none());
    }

    #[test]
    fn behind_misses() {
        assert!(cube().intersect(&Ray::new(Vec3::new(0.0, 0.0, 3.0), Vec3::Z)).is_none());
    }
}
