//! The node test in Embree's form (Wald et al. 2014): one fused multiply-add per plane,
//! `plane * inv + c` with `c = -origin * inv` made once per ray, and the entry and exit as the
//! largest and smallest of four values in two steps rather than three, for the AVX-512 walk's
//! rays to which it applies. A node's critical path, from its rows' loads to the mask of the
//! children entered, is then a multiply-add and two `max` deep instead of a difference, a
//! product and three `max`: about a fifth shorter, and a single ray's walk waits on it at every
//! node.
//!
//! The fused form is not the difference-and-product test rounded differently: `c` is rounded
//! once per ray, an absolute error that the far scale of Ize (2013), "Robust BVH Ray Traversal",
//! does not cover when a box lies close to an origin far from the scene's zero. So the constants
//! are rounded each its safe way ([`FusedPlanes::new`]), which AVX-512's per-instruction rounding
//! makes as cheap as rounding them to nearest:
//!
//! - the near constant is `-origin * inv` rounded down, so a near plane's distance is at most
//!   the exact `(plane - origin) * inv` rounded up once: at most `t (1 + 3u)` for any distance
//!   `t >= 0` that the exact-order test ([`super::node::child_entry_scalar`], and the triangle
//!   block's box correction) finds on a box inside the child, `u` being the unit roundoff;
//! - the far planes' factor is the inverse direction times `1 + 2^-19` (the node test's factor
//!   in both forms, [`super::node::FAR_SCALE`]) and the far constant is
//!   `-origin * inv_far + 2^-126` rounded up, so that a far plane's distance is at least
//!   `1 + 30u` times the exact one, where the exact-order test's exit, which bounds the `t` of
//!   every hit inside, is at most `1 + 10u` times it; and at least the smallest normal float
//!   above the exact distance: a far distance that the
//!   exact-order test rounds to zero, at an origin on a box's face, stays above a near distance
//!   of the same plane and above a `t_min` of zero. Within `reach(t)`, the slack the walk allows
//!   a box beyond the closest hit, the child is then still entered.
//!
//! The form applies to rays with `t_min >= 0` (a hit is never behind the origin) whose inverse
//! direction components' far factors and their products with the origin are below `1e38` ([`applies`]:
//! no zero direction component, whose infinite inverse would make `inf - inf`, and finite
//! constants). No distance is then NaN, so the order in which the four values are compared does
//! not matter, and the two-step order is taken. The dispatch gives the other rays the walk with the
//! exact-order test, whose three-step order is the one that skips a NaN distance (see
//! [`super::kernels`]); the AVX2 walk keeps it for every ray, its vectors having no per-instruction
//! rounding.
//!
//! The tests below put boxes around two points of a ray, their faces two or three floats out,
//! and boxes that a ray meets at a corner or along a face, inside boxes as large or a float
//! larger, at scales from `1e-30` to `1e20`, and check that every distance the exact-order test
//! accepts on the inner box enters the outer one; they fail with the constants rounded to nearest
//! or the far factor taken out. The kernel's tests check [`FusedPlanes::new_avx512`] against
//! [`FusedPlanes::new`] and the kernel against [`child_entry_fused_scalar`], bit for bit.

use glam::Vec3A;

use super::node::{FAR_SCALE, NodeRay, WideNode};

/// Largest magnitude of an inverse direction's far factor and of its product with the origin
/// for which the form applies: far enough below the largest float that the constants, rounded
/// away from the nearest, stay finite.
const LARGEST: f32 = 1e38;

/// Whether the fused form applies to a ray of origin `origin`, inverse direction `inv_dir` and
/// start `t_min` (see the module documentation): three-lane vector operations, no branch, cheap
/// enough for the dispatch to ask before it picks a walk.
#[inline(always)]
pub fn applies(origin: Vec3A, inv_dir: Vec3A, t_min: f32) -> bool {
    applies_with_far(origin, inv_dir * FAR_SCALE, t_min)
}

/// [`applies`] to the ray `ray` was prepared from, with the far factors it holds.
#[inline(always)]
pub fn applies_to(ray: &NodeRay) -> bool {
    applies_with_far(ray.origin.into(), ray.inv_far.into(), ray.t_min)
}

/// [`applies`], given the far factors `inv_far` (the inverse direction times [`FAR_SCALE`]).
#[inline(always)]
fn applies_with_far(origin: Vec3A, inv_far: Vec3A, t_min: f32) -> bool {
    let bound = Vec3A::splat(LARGEST);
    // `cmplt` is false for NaN and the infinities: an infinite inverse (a zero direction
    // component) or product leaves the form out.
    (inv_far.abs().cmplt(bound) & (origin * inv_far).abs().cmplt(bound)).all() & (t_min >= 0.0)
}

/// The per-ray constants of the fused node test (see the module documentation), for a ray to
/// which the form [`applies`].
#[derive(Clone, Copy, Debug)]
pub struct FusedPlanes {
    /// Per axis, `-origin * inv` rounded down: the near planes' constant.
    pub near: [f32; 3],
    /// Per axis, `-origin * inv_far + 2^-126` rounded up: the far planes' constant, with the far
    /// factor of the node test ([`NodeRay::inv_far`]).
    pub far: [f32; 3],
}

impl FusedPlanes {
    /// Constants that no ray has: what a fused kernel holds before its walk prepares it.
    pub const NONE: FusedPlanes = FusedPlanes { near: [0.0; 3], far: [0.0; 3] };

    /// The constants of `ray`, each product computed exactly in `f64` and rounded its way: the
    /// reference [`FusedPlanes::new_avx512`] matches bit for bit.
    pub fn new(ray: &NodeRay) -> Self {
        debug_assert!(applies_to(ray));
        let mut planes = FusedPlanes::NONE;
        for a in 0..3 {
            let (o, inv, inv_far) = (ray.origin[a], ray.inv_dir[a], ray.inv_far[a]);
            // Products of two floats are exact in `f64`, and so is the far constant's sum unless
            // its terms lie more than 53 bits apart.
            planes.near[a] = round_down(-(o as f64) * inv as f64);
            let product = -(o as f64) * inv_far as f64;
            let sum = product + f32::MIN_POSITIVE as f64;
            planes.far[a] = if sum - product == f32::MIN_POSITIVE as f64 {
                round_up(sum)
            } else {
                // The sum was rounded: the product is so large that the float above it is
                // above the sum too.
                let above = round_up(product);
                if above as f64 == product { above.next_up() } else { above }
            };
        }
        planes
    }

    /// [`FusedPlanes::new`] with AVX-512's per-instruction rounding: each constant one scalar
    /// multiply-add rounded down or up, from the ray's fields, as quick to make as the product
    /// rounded to nearest.
    ///
    /// # Safety
    /// The processor has AVX-512 F and VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
    #[inline]
    pub unsafe fn new_avx512(ray: &NodeRay) -> Self {
        use std::arch::x86_64::*;
        const DOWN: i32 = _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC;
        const UP: i32 = _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC;
        let mut planes = FusedPlanes::NONE;
        let (zero, floor) = (_mm_setzero_ps(), _mm_set_ss(f32::MIN_POSITIVE));
        for a in 0..3 {
            let o = _mm_set_ss(ray.origin[a]);
            let (inv, inv_far) = (_mm_set_ss(ray.inv_dir[a]), _mm_set_ss(ray.inv_far[a]));
            // `-(o * inv) + 0` and `-(o * inv_far) + 2^-126`, each rounded once, its way.
            planes.near[a] = _mm_cvtss_f32(_mm_fnmadd_round_ss::<DOWN>(o, inv, zero));
            planes.far[a] = _mm_cvtss_f32(_mm_fnmadd_round_ss::<UP>(o, inv_far, floor));
        }
        planes
    }
}

/// The largest `f32` at most `x`.
fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x { f.next_down() } else { f }
}

/// The smallest `f32` at least `x`.
fn round_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x { f.next_up() } else { f }
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

/// The fused test of one child with the constants `planes`: the reference the fused SIMD kernel
/// matches bit for bit, for a ray to which the form applies. Returns the entry distance if the ray
/// enters the box within `t_min..=limit`.
pub fn child_entry_fused_scalar(
    node: &WideNode,
    slot: usize,
    ray: &NodeRay,
    planes: &FusedPlanes,
    limit: f32,
) -> Option<f32> {
    let (enter, exit) = child_distances_fused_scalar(node, slot, ray, planes, limit);
    (enter <= exit).then_some(enter)
}

/// The fused test's entry and exit distances of one child, in the kernel's order.
pub fn child_distances_fused_scalar(
    node: &WideNode,
    slot: usize,
    ray: &NodeRay,
    planes: &FusedPlanes,
    limit: f32,
) -> (f32, f32) {
    let near = |a: usize| node.bounds[ray.row_index(a, 0)][slot].mul_add(ray.inv_dir[a], planes.near[a]);
    let far = |a: usize| node.bounds[ray.row_index(a, 1)][slot].mul_add(ray.inv_far[a], planes.far[a]);
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
    use crate::accel::wide::node::reach;
    use crate::geom::aabb::ROBUST_FAR_SCALE;
    use crate::{Aabb, Ray};

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
        assert!(applies(ray.origin_a(), ray.inv_dir_a(), ray.t_min), "{ray:?}");
        let planes = FusedPlanes::new(&r);
        for t in [lo, hi] {
            let limit = reach(t);
            let entry = if fused {
                child_entry_fused_scalar(&node, 2, &r, &planes, limit)
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

    /// [`holds`] for `inner` inside itself grown by `grow` floats on each face, in the fused form
    /// and then in the exact order, if the ray is valid and the fused form applies to it; true if
    /// some distance was checked.
    fn holds_grown(inner: &Aabb, grow: i32, ray: &Ray) -> bool {
        if !ray.is_valid() || !applies(ray.origin_a(), ray.inv_dir_a(), ray.t_min) {
            return false;
        }
        let outer = Aabb::new(inner.min.map(|x| nudge(x, -grow)), inner.max.map(|x| nudge(x, grow)));
        let checked = holds(inner, &outer, ray, true);
        if checked {
            assert!(holds(inner, &outer, ray, false));
        }
        checked
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
            let t_max = [f32::INFINITY, t1.max(t2), 2.0 * scale][i % 3];
            let ray = Ray::segment(origin, dir, 0.0, t_max);
            checked += holds_grown(&inner, rng.random_range(0..3), &ray) as u32;
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
                // The origin at zero: exact constants, the far factor alone. Any corner then gives
                // an exact direction; one with full mantissas makes the three axes' distances to
                // it round each its own way.
                let mut full = || (rng.random::<f32>() + 1.0) * unit * [-1.0, 1.0][rng.random_range(0..2)];
                (Vec3::ZERO, Vec3::new(full(), full(), full()))
            } else if i % 4 == 2 {
                // An origin thousands of steps from zero and a few from the corner: `origin * inv`
                // is a thousand times the distance, and its rounding outweighs the far factor
                // unless the constants are rounded their ways.
                let mut int = |n| int(&mut rng, n);
                let origin = Vec3::new(int(4), int(4), int(4)) + Vec3::new(4093.0, -2039.0, 3067.0) * unit;
                (origin, origin + Vec3::new(int(3), int(3), int(3)))
            } else {
                let mut int = |n| int(&mut rng, n);
                (Vec3::new(int(64), int(64), int(64)), Vec3::new(int(16), int(16), int(16)))
            };
            let mut size = || int(&mut rng, 4).abs();
            let extent = Vec3::new(size(), size(), size()) * [0.0, 1.0][i % 2];
            let inner = Aabb::new(corner, corner + extent);
            let ray = Ray::segment(origin, corner - origin, 0.0, [f32::INFINITY, 1.0][i % 2]);
            checked += holds_grown(&inner, [0, 0, 1][i % 3], &ray) as u32;
        }
        assert!(checked > 50_000, "only {checked} boxes checked");
    }

    #[test]
    fn the_form_applies_only_where_its_bounds_hold() {
        let applies = |o: Vec3, d: Vec3, t_min: f32| {
            let ray = Ray::segment(o, d, t_min, 1e30);
            applies(ray.origin_a(), ray.inv_dir_a(), ray.t_min)
        };
        assert!(applies(Vec3::new(1.0, -2.0, 3.0), Vec3::new(0.5, 1.0, -2.0), 0.0));
        assert!(applies(Vec3::ZERO, Vec3::ONE, -0.0));
        // A zero component (an infinite inverse), a tiny one whose inverse overflows, a negative
        // start, an origin so far out that its product with the inverse overflows.
        assert!(!applies(Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0), 0.0));
        assert!(!applies(Vec3::ZERO, Vec3::new(1.0, 1e-39, 1.0), 0.0));
        assert!(!applies(Vec3::ZERO, Vec3::ONE, -1.0));
        assert!(!applies(Vec3::new(-1e30, 0.0, 0.0), Vec3::new(1e-20, 1.0, 1.0), 0.0));
        assert!(!applies(Vec3::new(1e30, 0.0, 0.0), Vec3::new(-1e-9, 1.0, 1.0), 0.0));
        assert!(applies(Vec3::new(1e30, 0.0, 0.0), Vec3::new(-1e-7, 1.0, 1.0), 0.0));
    }
}
