//! The node test in Embree's form (Wald et al. 2014): one fused multiply-add per plane,
//! `plane * inv + c` with `c = -origin * inv` made once per ray, and the entry and exit as the
//! largest and smallest of four values in two steps rather than three, for the x86 kernels'
//! rays to which it applies. A node's critical path, from its rows' loads to the mask of the
//! children entered, is then a multiply-add and two `max` deep instead of a difference, a
//! product and three `max`: about a fifth shorter, and the single-ray walk waits on it at every
//! node.
//!
//! The fused form is not the difference-and-product test rounded differently: `c` is rounded
//! once per ray, an absolute error that the far scale of Ize (2013), "Robust BVH Ray Traversal",
//! does not cover when a box lies close to an origin far from the scene's zero. So the constants
//! carry margins that make the form conservative by construction ([`FusedPlanes::new`]):
//!
//! - the near constant is lowered by `2^-20 |origin * inv|` plus the smallest normal float,
//!   more than the error of making it (subnormal results included), so that a near plane's
//!   distance is at most the exact one rounded up once: at most `t (1 + 2u)` for any distance
//!   `t >= 0` that the exact-order test ([`super::node::child_entry_scalar`], and the triangle
//!   block's box correction) finds on a box inside the child, `u` the unit roundoff;
//! - the far planes' factor is the inverse direction times `1 + 2^-19` and the far constant is
//!   raised by the same margin, so that a far plane's distance is at least `t (1 + 28u)` for any
//!   such `t`, where the exact-order exit reaches at most `t (1 + 10u)`; within `reach(t)`, the
//!   slack the walk allows a box beyond the closest hit, the child is then still entered.
//!
//! The margins' floor (the smallest normal float) keeps a far distance that the exact-order test
//! rounds to zero, at an origin on a box's face, from falling below a `t_min` of zero.
//!
//! The form applies to rays with `t_min >= 0` (a hit is never behind the origin), whose three
//! inverse direction components and far factors are finite (no zero direction component, whose
//! infinite inverse would make `inf - inf`), and whose `|origin * inv|` is below `1e30` (so that
//! the margins stay finite). No distance is then NaN, so the order in which the four values are
//! compared does not matter, and the two-step order is taken. Other rays keep the exact-order test,
//! whose three-step order is the one that skips a NaN distance (see [`super::kernels`]).
//!
//! The tests below put boxes around two points of a ray, their faces two or three floats out,
//! inside boxes as large or one float or two larger, at scales from `1e-30` to `1e20`, and check
//! that every distance the exact-order test accepts on the inner box enters the outer one; they
//! fail with the margins or the far factor taken out.

use glam::Vec3A;

use super::node::{NodeRay, WideNode};
use crate::Ray;

/// The far planes' factor over the inverse direction: `1 + 2^-19`, exact in `f32`.
pub const FUSED_FAR_SCALE: f32 = 1.0 + 1.0 / (1 << 19) as f32;

/// The relative part of the constants' margins.
const MARGIN: f32 = 1.0 / (1 << 20) as f32;

/// Largest `|origin * inv|` for which the form applies.
const LARGEST_PRODUCT: f32 = 1e30;

/// The per-ray constants of the fused node test (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct FusedPlanes {
    /// Per axis, `-origin * inv` lowered by its margin: the near planes' constant.
    pub near: [f32; 3],
    /// Per axis, the far planes' factor: the inverse direction times [`FUSED_FAR_SCALE`].
    pub inv_far: [f32; 3],
    /// Per axis, `-origin * inv_far` raised by its margin: the far planes' constant.
    pub far: [f32; 3],
    /// Whether the form applies to the ray (see the module documentation); the constants mean
    /// nothing where it does not.
    pub applies: bool,
}

impl FusedPlanes {
    /// The constants of `ray`, made with three-lane vectors and no branch.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let (o, inv) = (ray.origin_a(), ray.inv_dir_a());
        let inv_far = inv * FUSED_FAR_SCALE;
        let (near, far) = (-(o * inv), -(o * inv_far));
        let margin = |c: Vec3A| c.abs() * MARGIN + Vec3A::splat(f32::MIN_POSITIVE);
        let finite = inv_far.abs().cmplt(Vec3A::INFINITY)
            & near.abs().cmplt(Vec3A::splat(LARGEST_PRODUCT))
            & far.abs().cmplt(Vec3A::splat(LARGEST_PRODUCT));
        FusedPlanes {
            near: (near - margin(near)).to_array(),
            inv_far: inv_far.to_array(),
            far: (far + margin(far)).to_array(),
            applies: finite.all() & (ray.t_min >= 0.0),
        }
    }
}

/// `if a > b { a } else { b }`: the kernels' `max`, and with no NaN the larger of the two.
#[inline(always)]
fn greater(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// `if a < b { a } else { b }`: the kernels' `min`.
#[inline(always)]
fn less(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// The fused test of one child: the reference the fused SIMD kernels match bit for bit, for a ray
/// to which the form applies. Returns the entry distance if the ray enters the box within
/// `t_min..=limit`.
pub fn child_entry_fused_scalar(node: &WideNode, slot: usize, ray: &NodeRay, limit: f32) -> Option<f32> {
    let (enter, exit) = child_distances_fused_scalar(node, slot, ray, limit);
    (enter <= exit).then_some(enter)
}

/// The fused test's entry and exit distances of one child, in the kernels' order.
pub fn child_distances_fused_scalar(node: &WideNode, slot: usize, ray: &NodeRay, limit: f32) -> (f32, f32) {
    debug_assert!(ray.fused.applies);
    let p = &ray.fused;
    let near = |a: usize| node.bounds[ray.row_index(a, 0)][slot].mul_add(ray.inv_dir[a], p.near[a]);
    let far = |a: usize| node.bounds[ray.row_index(a, 1)][slot].mul_add(p.inv_far[a], p.far[a]);
    let enter = greater(greater(near(0), near(1)), greater(near(2), ray.t_min));
    let exit = less(less(far(0), far(1)), less(far(2), limit));
    (enter, exit)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;
    use crate::Aabb;
    use crate::accel::wide::node::reach;
    use crate::geom::aabb::ROBUST_FAR_SCALE;

    /// The box correction of the triangle block test (`triangles::intersect_block`), one box: the
    /// interval of distances a hit in the box may be given, in the exact-order form.
    fn exact_order_interval(b: &Aabb, ray: &Ray) -> (f32, f32) {
        let (o, inv) = (ray.origin(), ray.inv_dir());
        let (mut enter, mut exit) = (f32::NEG_INFINITY, f32::INFINITY);
        for a in 0..3 {
            let (near, far) = if inv[a] < 0.0 { (b.max[a], b.min[a]) } else { (b.min[a], b.max[a]) };
            let t_near = (near - o[a]) * inv[a];
            let t_far = (far - o[a]) * inv[a] * ROBUST_FAR_SCALE;
            enter = greater(t_near, enter);
            exit = less(t_far, exit);
        }
        (enter, exit)
    }

    /// `x` moved by `steps` floats (up if positive).
    fn nudge(mut x: f32, steps: i32) -> f32 {
        for _ in 0..steps.abs() {
            x = if steps > 0 { x.next_up() } else { x.next_down() };
        }
        x
    }

    /// Checks every distance the exact-order test gives a hit in `inner` (its interval's two ends,
    /// as closest hits) against the fused test of `outer`; true if some distance was checked.
    fn holds(inner: &Aabb, outer: &Aabb, ray: &Ray, fused: bool) -> bool {
        let (enter, exit) = exact_order_interval(inner, ray);
        let (lo, hi) = (greater(enter, ray.t_min), less(exit, ray.t_max));
        if !(lo <= hi) {
            return false;
        }
        let mut node = WideNode::EMPTY_NODE;
        node.set_child(2, outer, 0, 0);
        let r = NodeRay::new(ray);
        assert!(r.fused.applies, "{ray:?}");
        for t in [lo, hi] {
            let limit = reach(t);
            let entry = if fused {
                child_entry_fused_scalar(&node, 2, &r, limit)
            } else {
                crate::accel::wide::node::child_entry_scalar(&node, 2, &r, limit)
            };
            assert!(
                entry.is_some_and(|e| e <= limit),
                "fused {fused}: a hit at {t} in {inner:?} is lost in {outer:?} ({entry:?}, limit {limit}), {ray:?}"
            );
        }
        true
    }

    #[test]
    fn every_box_around_a_hit_the_exact_order_test_accepts_is_entered() {
        let mut rng = Pcg32::seed_from_u64(0xf05e_d5ab);
        let mut checked = 0;
        for i in 0..200_000 {
            let scale = [1e-30f32, 1e-3, 1.0, 1e3, 1e20][i % 5];
            let mut unit = || rng.random::<f32>() * 2.0 - 1.0;
            // Origins far from the boxes as well as near them, so that `origin * inv` dwarfs the
            // distances; directions with tiny components too, whose inverses are huge.
            let origin = Vec3::new(unit(), unit(), unit()) * scale * [1.0, 1e4, 1e-4][i % 3];
            let mut dir = Vec3::new(unit(), unit(), unit());
            if i % 7 == 0 {
                dir[i % 3] *= 1e-30;
            }
            if dir.cmpeq(Vec3::ZERO).any() {
                continue;
            }
            // Two points of the ray span the inner box, its faces moved out by two floats or three,
            // more than the rounding of the points: the ray meets it, as a triangle's box holds
            // the point where the ray meets the triangle.
            let mut at = || [0.0f32, 1e-38, 1e-7, 0.5, 1.0, 7.0][rng.random_range(0..6)] * scale;
            let (t1, t2) = (at(), at());
            let (p, q) = (origin + dir * t1, origin + dir * t2);
            let mut out = || rng.random_range(2..=3);
            let (mut lo, mut hi) = (p.min(q), p.max(q));
            for a in 0..3 {
                lo[a] = nudge(lo[a], -out());
                hi[a] = nudge(hi[a], out());
            }
            let inner = Aabb::new(lo, hi);
            // The outer box: the same, or a float or more larger on each face.
            let grow = rng.random_range(0..3);
            let outer = Aabb::new(inner.min.map(|x| nudge(x, -grow)), inner.max.map(|x| nudge(x, grow)));
            let t_max = [f32::INFINITY, t1.max(t2), 2.0 * scale][i % 3];
            let ray = Ray::segment(origin, dir, 0.0, t_max);
            if !ray.is_valid() || !NodeRay::new(&ray).fused.applies {
                continue;
            }
            if holds(&inner, &outer, &ray, true) {
                assert!(holds(&inner, &outer, &ray, false));
                checked += 1;
            }
        }
        assert!(checked > 50_000, "only {checked} boxes checked");
    }

    #[test]
    fn boxes_a_ray_touches_at_a_corner_or_along_a_face_are_entered() {
        // Small integers times a power of two, so that the direction from the origin to a
        // corner of the box is exact: the ray meets the box at that corner at `t = 1`, and
        // often there alone (flat boxes, rays leaving a corner); the tightest cases for the far
        // planes.
        let mut rng = Pcg32::seed_from_u64(0x0c0f_fee5);
        let mut checked = 0;
        for i in 0..200_000 {
            let unit = [2.0f32.powi(-100), 2.0f32.powi(-20), 1.0, 2.0f32.powi(20), 2.0f32.powi(60)][i % 5];
            let int = |rng: &mut Pcg32, n: i32| rng.random_range(-n..=n) as f32 * unit;
            let (origin, corner) = if i % 4 == 0 {
                // The origin at zero: no margin, the far factor alone. Any corner then gives an
                // exact direction; one with full mantissas makes the three axes' distances to it
                // round each its own way.
                let mut full = || (rng.random::<f32>() + 1.0) * unit * [-1.0, 1.0][rng.random_range(0..2)];
                (Vec3::ZERO, Vec3::new(full(), full(), full()))
            } else {
                let mut int = |n| int(&mut rng, n);
                (Vec3::new(int(64), int(64), int(64)), Vec3::new(int(16), int(16), int(16)))
            };
            let mut size = || int(&mut rng, 4).abs();
            let extent = Vec3::new(size(), size(), size()) * [0.0, 1.0][i % 2];
            let inner = Aabb::new(corner, corner + extent);
            let grow = [0, 0, 1][i % 3];
            let outer = Aabb::new(inner.min.map(|x| nudge(x, -grow)), inner.max.map(|x| nudge(x, grow)));
            let ray = Ray::segment(origin, corner - origin, 0.0, [f32::INFINITY, 1.0][i % 2]);
            if !ray.is_valid() || !NodeRay::new(&ray).fused.applies {
                continue;
            }
            if holds(&inner, &outer, &ray, true) {
                assert!(holds(&inner, &outer, &ray, false));
                checked += 1;
            }
        }
        assert!(checked > 50_000, "only {checked} boxes checked");
    }

    #[test]
    fn the_form_applies_only_where_its_bounds_hold() {
        let applies = |o: Vec3, d: Vec3, t_min: f32| FusedPlanes::new(&Ray::segment(o, d, t_min, 1e30)).applies;
        assert!(applies(Vec3::new(1.0, -2.0, 3.0), Vec3::new(0.5, 1.0, -2.0), 0.0));
        assert!(applies(Vec3::ZERO, Vec3::ONE, -0.0));
        // A zero component (an infinite inverse), a tiny one whose inverse overflows, a negative
        // start, an origin so far out that its product with the inverse passes 1e30.
        assert!(!applies(Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0), 0.0));
        assert!(!applies(Vec3::ZERO, Vec3::new(1.0, 1e-39, 1.0), 0.0));
        assert!(!applies(Vec3::ZERO, Vec3::ONE, -1.0));
        assert!(!applies(Vec3::new(1e20, 0.0, 0.0), Vec3::new(1e-11, 1.0, 1.0), 0.0));
    }
}
