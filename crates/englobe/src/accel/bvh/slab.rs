//! The ray/box test of the BVH traversals: the robust slab test of [`crate::Aabb::intersect`]
//! (Williams, Barrus, Morley and Shirley (2005), "An Efficient and Robust Ray-Box Intersection
//! Algorithm"; far distance scaled by `1 + 2 * gamma(3)` as in Ize (2013), "Robust BVH Ray
//! Traversal"), computed for the three axes at once in SIMD lanes, on a [`BvhNode`] directly.
//!
//! What a ray needs for every box (origin, inverse direction, which slab plane is near on each
//! axis) is prepared once per query. The result is bit for bit that of [`crate::Aabb::intersect`],
//! including for rays lying in a box face: where a zero direction meets an origin on the plane,
//! the lane's NaN is replaced by the bound that leaves the interval unchanged (`-inf` for an entry,
//! `+inf` for an exit) before the lanes are reduced, which is what the scalar test's comparisons
//! do. The replacement is explicit rather than left to the NaN rules of SIMD `min`/`max`, which
//! differ between instruction sets.

use glam::{BVec3A, Vec3A, Vec4};

use super::BvhNode;
use crate::Ray;
use crate::geom::aabb::ROBUST_FAR_SCALE;

/// A ray prepared for slab tests.
#[derive(Clone, Copy, Debug)]
pub struct RaySlabs {
    origin: Vec3A,
    inv_dir: Vec3A,
    /// Lanes where the inverse direction is not negative: the near plane is the box's minimum.
    positive: BVec3A,
    t_min: f32,
    /// Bit `a` set if the ray goes down axis `a`.
    negative_bits: u32,
}

impl RaySlabs {
    /// Prepares `ray`.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let inv_dir = Vec3A::from(ray.inv_dir());
        let positive = inv_dir.cmpge(Vec3A::ZERO);
        RaySlabs {
            origin: Vec3A::from(ray.origin()),
            inv_dir,
            positive,
            t_min: ray.t_min,
            negative_bits: !positive.bitmask() & 7,
        }
    }

    /// Bit `a` is set if the ray goes down axis `a` (its inverse direction is negative).
    #[inline(always)]
    pub fn negative_bits(&self) -> u32 {
        self.negative_bits
    }

    /// The distance at which the ray enters the node's box, if it does within `t_min..=t_max`.
    #[inline(always)]
    pub fn enter(&self, node: &BvhNode, t_max: f32) -> Option<f32> {
        let (t_enter, t_exit) = self.distances(node, t_max);
        (t_enter <= t_exit).then_some(t_enter)
    }

    /// The slab test's entry and exit distances, clipped to `t_min..=t_max`, exactly as
    /// [`crate::Aabb::slab_distances`] with [`ROBUST_FAR_SCALE`] computes them.
    #[inline(always)]
    pub fn distances(&self, node: &BvhNode, t_max: f32) -> (f32, f32) {
        // Four neighbouring fields each, so that each is one vector load; the fourth lane (the
        // index or count, as bits) is never reduced.
        let lo = Vec3A::from_vec4(Vec4::new(node.min[0], node.min[1], node.min[2], f32::from_bits(node.index)));
        let hi = Vec3A::from_vec4(Vec4::new(node.max[0], node.max[1], node.max[2], f32::from_bits(node.count)));
        let near = Vec3A::select(self.positive, lo, hi);
        let far = Vec3A::select(self.positive, hi, lo);
        let t_near = (near - self.origin) * self.inv_dir;
        let t_far = (far - self.origin) * self.inv_dir * ROBUST_FAR_SCALE;
        // NaN (0 * inf: an origin on the plane of a parallel ray) leaves the interval unchanged.
        let t_near = Vec3A::select(t_near.cmpeq(t_near), t_near, Vec3A::NEG_INFINITY);
        let t_far = Vec3A::select(t_far.cmpeq(t_far), t_far, Vec3A::INFINITY);
        // Neither side is NaN any more: plain comparisons, as in the scalar test.
        let (enter, exit) = (t_near.max_element(), t_far.min_element());
        (if enter > self.t_min { enter } else { self.t_min }, if exit < t_max { exit } else { t_max })
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;
    use crate::Aabb;

    #[test]
    fn agrees_bit_for_bit_with_the_scalar_test() {
        // Integer coordinates and axis-parallel directions of both signs, zeros of both signs,
        // so that origins on planes, rays in faces and flat boxes all occur.
        let mut rng = Pcg32::seed_from_u64(0x1234_5678);
        let mut next = move |n: u32| rng.random_range(0..n);
        let values = [-2.0f32, -1.0, -0.0, 0.0, 0.5, 1.0, 2.0];
        let dirs = [-1.0f32, -0.0, 0.0, 0.3, 1.0];
        let mut hits = 0;
        for _ in 0..200_000 {
            let mut pick = |v: &[f32]| v[next(v.len() as u32) as usize];
            let a = Vec3::new(pick(&values), pick(&values), pick(&values));
            let b = Vec3::new(pick(&values), pick(&values), pick(&values));
            let bounds = Aabb::new(a.min(b), a.max(b));
            let origin = Vec3::new(pick(&values), pick(&values), pick(&values)) * 1.5;
            let dir = Vec3::new(pick(&dirs), pick(&dirs), pick(&dirs));
            let t_max = [f32::INFINITY, 1.0, 2.5][next(3) as usize];
            let ray = Ray::segment(origin, dir, 0.0, t_max);
            let node = BvhNode::leaf(bounds, 0, 1);
            let (e0, x0) = bounds.slab_distances(&ray, ROBUST_FAR_SCALE);
            let (e1, x1) = RaySlabs::new(&ray).distances(&node, ray.t_max);
            // Equal as numbers (an entry of -0 and +0 compare equal and order the same).
            assert!(e0 == e1 && x0 == x1, "{bounds:?} {ray:?}: scalar {e0} {x0}, lanes {e1} {x1}");
            assert_eq!(bounds.intersect(&ray).map(|(t, _)| t), RaySlabs::new(&ray).enter(&node, ray.t_max));
            hits += bounds.intersect(&ray).is_some() as u32;
        }
        assert!(hits > 10_000, "{hits}");
    }

    #[test]
    fn direction_signs() {
        let ray = Ray::new(Vec3::ZERO, Vec3::new(-1.0, 0.0, -0.0));
        assert_eq!(RaySlabs::new(&ray).negative_bits(), 0b001);
        let ray = Ray::new(Vec3::ZERO, Vec3::new(1.0, -2.0, -3.0));
        assert_eq!(RaySlabs::new(&ray).negative_bits(), 0b110);
    }
}
