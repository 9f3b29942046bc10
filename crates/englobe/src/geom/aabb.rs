//! Axis-aligned bounding boxes and the robust ray/box slab test.
//!
//! The slab test follows Williams, Barrus, Morley and Shirley (2005), "An Efficient and Robust
//! Ray-Box Intersection Algorithm": the near and far planes of each axis are chosen by the sign of
//! the inverse direction, so no per-axis min/max swap is needed. Two refinements:
//!
//! * **Parallel rays.** A zero direction component has an inverse of `+inf` (see [`crate::Ray`]).
//!   If the origin lies exactly on a slab plane, `(plane - origin) * inf` is NaN; the running
//!   `max`/`min` below ignore NaN operands (a comparison with NaN is false), so a ray
//!   lying in a face counts as inside that slab, and a ray parallel to a slab but outside it gets
//!   `+inf`/`-inf` entries and misses.
//! * **Rounding.** The far distance is scaled by `1 + 2 * gamma(3)` (Ize 2013, "Robust BVH Ray
//!   Traversal"), so that rounding in the three products never makes a ray that grazes a shared
//!   edge or vertex on a box face miss the box.

use glam::{Vec3, Vec3A};

use crate::Ray;

/// `gamma(n) = n * eps / (1 - n * eps)` with `eps` the unit roundoff of `f32`, the bound on the
/// relative error of `n` chained floating-point operations (Higham; pbrt's `gamma`).
pub const fn gamma(n: u32) -> f32 {
    let e = f32::EPSILON * 0.5;
    (n as f32 * e) / (1.0 - n as f32 * e)
}

/// Scale applied to a slab test's far distance: `1 + 2 * gamma(3)`.
pub const ROBUST_FAR_SCALE: f32 = 1.0 + 2.0 * gamma(3);

/// An axis-aligned box `min..=max`. The empty box has `min = +inf`, `max = -inf`, so that growing
/// it by anything gives that thing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The box that contains nothing.
    pub const EMPTY: Aabb = Aabb { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    /// The box `min..=max` (components are not reordered).
    #[inline]
    pub const fn new(min: Vec3, max: Vec3) -> Self {
        Aabb { min, max }
    }

    /// The smallest box holding every point.
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| b.grown(p))
    }

    /// True if the box holds no point.
    #[inline]
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    /// True if both corners are finite (an empty box is not).
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }

    /// The box grown to hold `p`.
    #[inline]
    pub fn grown(&self, p: Vec3) -> Self {
        Aabb { min: self.min.min(p), max: self.max.max(p) }
    }

    /// The smallest box holding both.
    #[inline]
    pub fn union(&self, other: &Aabb) -> Self {
        Aabb { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    /// The common part of both (possibly empty).
    #[inline]
    pub fn intersection(&self, other: &Aabb) -> Self {
        Aabb { min: self.min.max(other.min), max: self.max.min(other.max) }
    }

    /// `max - min` (negative for the empty box).
    #[inline]
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// The centre point.
    #[inline]
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Surface area; zero for an empty box.
    #[inline]
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// The axis (0, 1 or 2) along which the box is longest.
    #[inline]
    pub fn longest_axis(&self) -> usize {
        let e = self.extent();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }

    /// True if `other` lies inside this box (boundaries included). The empty box lies in every box.
    #[inline]
    pub fn contains_box(&self, other: &Aabb) -> bool {
        other.is_empty() || (self.min.cmple(other.min).all() && other.max.cmple(self.max).all())
    }

    /// True if `p` (a `Vec3` or a `Vec3A`) lies inside the box (boundaries included). Both sides
    /// at once, in four-lane vectors: the wide BVH asks it of every ray's origin before its walk.
    #[inline]
    pub fn contains_point(&self, p: impl Into<Vec3A>) -> bool {
        let p = p.into();
        (Vec3A::from(self.min).cmple(p) & p.cmple(Vec3A::from(self.max))).all()
    }

    /// The part `t_enter..=t_exit` of the ray's interval that lies inside the box, or `None`.
    ///
    /// Boundaries count as inside. The exit distance is widened by [`ROBUST_FAR_SCALE`], so a
    /// ray is never lost to rounding, at the price of rare false positives for rays that pass
    /// within a few ulps of the box (harmless: the primitives inside are then tested exactly).
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray) -> Option<(f32, f32)> {
        let (t_enter, t_exit) = self.slab_distances(ray, ROBUST_FAR_SCALE);
        (t_enter <= t_exit).then_some((t_enter, t_exit))
    }

    /// The slab test's raw entry and exit distances, clipped to the ray's interval; `far_scale`
    /// multiplies each axis' exit distance (1.0 disables the rounding guard, for tests that show
    /// the guard is needed). The ray hits the box iff `enter <= exit`.
    #[inline(always)]
    pub fn slab_distances(&self, ray: &Ray, far_scale: f32) -> (f32, f32) {
        let o = ray.origin();
        let inv = ray.inv_dir();
        let (mut t_enter, mut t_exit) = (ray.t_min, ray.t_max);
        for axis in 0..3 {
            let (near, far) =
                if inv[axis] >= 0.0 { (self.min[axis], self.max[axis]) } else { (self.max[axis], self.min[axis]) };
            let t_near = (near - o[axis]) * inv[axis];
            let t_far = (far - o[axis]) * inv[axis] * far_scale;
            // A NaN (origin on the plane of a parallel ray) must leave the interval unchanged.
            // A comparison with NaN is false, so these keep the running bound then, as
            // `f32::max`/`min` would; unlike them they compile to a single `maxss`/`minss`, since
            // the running bound (from a valid ray's interval) is never NaN itself.
            t_enter = if t_near > t_enter { t_near } else { t_enter };
            t_exit = if t_far < t_exit { t_far } else { t_exit };
        }
        (t_enter, t_exit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> Aabb {
        Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))
    }

    #[test]
    fn hits_from_all_six_sides() {
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let mut o = Vec3::ZERO;
                o[axis] = 5.0 * sign;
                let ray = Ray::new(o, -o);
                let (t0, t1) = unit().intersect(&ray).expect("hit");
                assert!((t0 - 0.8).abs() < 1e-6, "{t0}");
                assert!((t1 - 1.2).abs() < 1e-5, "{t1}");
            }
        }
    }

    #[test]
    fn origin_inside_enters_at_t_min() {
        let ray = Ray::new(Vec3::ZERO, Vec3::new(0.3, -0.2, 1.0));
        let (t0, t1) = unit().intersect(&ray).unwrap();
        assert_eq!(t0, 0.0);
        assert!((t1 - 1.0).abs() < 1e-5);
    }

    #[test]
    fn parallel_rays_inside_and_outside_the_slab() {
        // Parallel to x slabs, inside them: hits.
        assert!(unit().intersect(&Ray::new(Vec3::new(0.5, -5.0, 0.0), Vec3::Y)).is_some());
        // Parallel to x slabs, outside them: misses, whatever the sign of the zero.
        assert!(unit().intersect(&Ray::new(Vec3::new(1.5, -5.0, 0.0), Vec3::Y)).is_none());
        assert!(unit().intersect(&Ray::new(Vec3::new(1.5, -5.0, 0.0), Vec3::new(-0.0, 1.0, 0.0))).is_none());
    }

    #[test]
    fn ray_lying_in_a_face_hits_without_nan() {
        for dir in [Vec3::Y, Vec3::new(0.0, 1.0, -0.0), Vec3::new(-0.0, -1.0, 0.0)] {
            for x in [-1.0f32, 1.0] {
                let ray = Ray::new(Vec3::new(x, -5.0 * dir.y, 0.0), dir);
                let (t0, t1) = unit().intersect(&ray).expect("a ray in a face is inside");
                assert!(t0.is_finite() && t1.is_finite());
                assert!((t0 - 4.0).abs() < 1e-5 && (t1 - 6.0).abs() < 1e-5, "{t0} {t1}");
            }
        }
    }

    #[test]
    fn origin_on_a_face_pointing_out_and_in() {
        let inward = Ray::new(Vec3::new(1.0, 0.0, 0.0), -Vec3::X);
        assert_eq!(unit().intersect(&inward).unwrap().0, 0.0);
        let outward = Ray::new(Vec3::new(1.0, 0.0, 0.0), Vec3::X);
        let (t0, t1) = unit().intersect(&outward).unwrap();
        assert_eq!((t0, t1), (0.0, 0.0), "touching counts as a hit at t = 0");
        let away = Ray::new(Vec3::new(1.0 + 1e-3, 0.0, 0.0), Vec3::X);
        assert!(unit().intersect(&away).is_none());
    }

    #[test]
    fn flat_box_is_hit_by_a_ray_in_its_plane_and_across_it() {
        let flat = Aabb::new(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0));
        assert!(flat.intersect(&Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z)).is_some());
        let (t0, _) = flat.intersect(&Ray::new(Vec3::new(0.2, 3.0, 0.1), -Vec3::Y)).unwrap();
        assert!((t0 - 3.0).abs() < 1e-6);
    }

    #[test]
    fn respects_the_ray_interval() {
        let ray = Ray::segment(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 0.0, 3.0);
        assert!(unit().intersect(&ray).is_none());
        let ray = Ray::segment(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 7.0, 9.0);
        assert!(unit().intersect(&ray).is_none());
    }

    #[test]
    fn empty_box_is_never_hit() {
        let ray = Ray::new(Vec3::ZERO, Vec3::ONE);
        assert!(Aabb::EMPTY.intersect(&ray).is_none());
        assert!(Aabb::EMPTY.is_empty());
        assert_eq!(Aabb::EMPTY.surface_area(), 0.0);
    }

    #[test]
    fn union_and_containment() {
        let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let b = Aabb::new(Vec3::splat(2.0), Vec3::splat(3.0));
        let u = a.union(&b);
        assert!(u.contains_box(&a) && u.contains_box(&b) && !a.contains_box(&b));
        assert_eq!(Aabb::EMPTY.union(&a), a);
        assert_eq!(u.surface_area(), 54.0);
        assert_eq!(u.longest_axis(), 0);
    }
}
