//! The node of the wide BVH: eight children's boxes stored as a structure of arrays, so that one
//! SIMD instruction handles the same plane of all eight boxes, and the children's references.
//!
//! This is the multi-BVH node of Wald, Benthin and Boulos (2008), "Getting Rid of Packets:
//! Efficient SIMD Single-Ray Traversal using Multi-branching BVHs" (IEEE Symposium on Interactive
//! Ray Tracing), at the width of Embree's `BVH8` (Wald, Woop, Benthin, Johnson and Ernst 2014,
//! "Embree: A Kernel Framework for Efficient CPU Ray Tracing", ACM TOG 33(4)): one 256-byte node,
//! four cache lines, aligned so that each row of eight floats is one aligned AVX load.
//!
//! A child reference is a `u32`: the index of an interior node, or [`LEAF`] plus the index of the
//! leaf's first item (a primitive reference or a block of triangles, depending on the structure),
//! with the number of items in [`WideNode::counts`]. Unused slots have [`EMPTY`] and an empty box
//! (`+inf` below, `-inf` above) that no ray enters: the slab test rejects it without a special case.

use crate::geom::aabb::ROBUST_FAR_SCALE;
use crate::{Aabb, Ray};

/// Children per node.
pub const WIDTH: usize = 8;

/// Flag of a child reference naming a leaf.
pub const LEAF: u32 = 1 << 31;

/// The reference of an unused child slot.
pub const EMPTY: u32 = u32::MAX;

/// Most items one leaf reference can hold (its count is a byte).
pub const MAX_LEAF_ITEMS: usize = u8::MAX as usize;

/// Rows of [`WideNode::bounds`]: lower x, upper x, lower y, upper y, lower z, upper z.
pub const ROWS: usize = 6;

/// One node: eight children's boxes (row `2 * axis` the lower planes, `2 * axis + 1` the upper
/// planes, column = child slot) and references.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct WideNode {
    /// The children's planes, one row of eight per plane (see [`ROWS`]).
    pub bounds: [[f32; WIDTH]; ROWS],
    /// The children: an interior node's index, [`LEAF`] plus a first item, or [`EMPTY`].
    pub children: [u32; WIDTH],
    /// Items of each leaf child (0 for interior and empty slots).
    pub counts: [u8; WIDTH],
}

const _: () = assert!(std::mem::size_of::<WideNode>() == 256);

impl WideNode {
    /// A node with every slot empty.
    pub const EMPTY_NODE: WideNode = WideNode {
        bounds: [
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
        ],
        children: [EMPTY; WIDTH],
        counts: [0; WIDTH],
    };

    /// Puts a child in slot `slot`: its box, its reference, and its item count (leaves only).
    pub fn set_child(&mut self, slot: usize, bounds: &Aabb, reference: u32, count: u8) {
        for axis in 0..3 {
            self.bounds[2 * axis][slot] = bounds.min[axis];
            self.bounds[2 * axis + 1][slot] = bounds.max[axis];
        }
        self.children[slot] = reference;
        self.counts[slot] = count;
    }

    /// The box of slot `slot` (the empty box for an unused slot).
    pub fn child_bounds(&self, slot: usize) -> Aabb {
        let b = &self.bounds;
        Aabb::new(
            glam::Vec3::new(b[0][slot], b[2][slot], b[4][slot]),
            glam::Vec3::new(b[1][slot], b[3][slot], b[5][slot]),
        )
    }

    /// Number of used slots.
    pub fn child_count(&self) -> usize {
        self.children.iter().filter(|&&c| c != EMPTY).count()
    }
}

/// Whether a child reference names a leaf (an unused slot's does too, but no ray reaches it).
#[inline(always)]
pub fn is_leaf(reference: u32) -> bool {
    reference & LEAF != 0
}

/// The index a child reference carries: the interior node's, or the leaf's first item.
#[inline(always)]
pub fn index_of(reference: u32) -> u32 {
    reference & !LEAF
}

/// A ray prepared for the slab tests of wide nodes: which row is the near plane on each axis, by
/// the sign of the inverse direction, exactly as [`Aabb::slab_distances`] chooses it.
///
/// Made once per query, so it holds only what the node test reads, computed without branches.
#[derive(Clone, Copy, Debug)]
pub struct NodeRay {
    /// The ray's origin.
    pub origin: [f32; 3],
    /// Its inverse direction (`+inf` for zero components).
    pub inv_dir: [f32; 3],
    /// The inverse direction times [`FAR_SCALE`]: the far planes' factor, rounded once per ray
    /// instead of once per node (see [`child_entry_scalar`]).
    pub inv_far: [f32; 3],
    /// The ray's `t_min`.
    pub t_min: f32,
    /// Byte offset of the near row of each axis in [`WideNode::bounds`], for kernels that load
    /// rows without an index check; the far row is the axis's other one, at `near ^ ROW_BYTES`
    /// (rows `2a` and `2a + 1` differ in that bit alone), so that a query makes three offsets
    /// rather than six. Private, so that only [`NodeRay::new`] makes them, always below
    /// `ROWS * WIDTH * 4`.
    ///
    /// Each a `usize`, not a `u32`: the walk loads them one by one, and the compiler has been
    /// seen to join the loads of two adjacent `u32`s into one, which then spans two of the
    /// stores that made them and cannot take its value from them (a store-forwarding stall at
    /// the start of every query).
    row_bytes: [usize; 3],
}

/// The far planes' factor over the inverse direction, `1 + 2^-19` (exact in `f32`): more than
/// the `1 + 2 gamma(3)` that Ize's bound asks of the slab test ([`ROBUST_FAR_SCALE`]), so that the
/// fused node test can make its far constant from the same factor ([`super::fused`]). A box's
/// exit is then put at most 2^-19 of its distance further, which changes no traversal measurably.
pub const FAR_SCALE: f32 = 1.0 + 1.0 / (1 << 19) as f32;
const _: () = assert!(FAR_SCALE >= ROBUST_FAR_SCALE);

/// Bytes of one row of [`WideNode::bounds`].
const ROW_BYTES: usize = WIDTH * 4;
const _: () = assert!(ROW_BYTES.is_power_of_two(), "the far row is found by flipping one bit");

impl NodeRay {
    /// Prepares `ray`.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let inv = ray.inv_dir();
        // Bit `a` set if the ray goes down axis `a` (`!(inv >= 0)`, as the scalar slab test
        // decides it; the inverse of a zero component is `+inf`, never `-inf`).
        let down = inv.cmplt(glam::Vec3::ZERO).bitmask();
        let near = |a: usize| (2 * a + ((down as usize >> a) & 1)) * ROW_BYTES;
        NodeRay {
            origin: ray.origin().to_array(),
            inv_dir: inv.to_array(),
            inv_far: (inv * FAR_SCALE).to_array(),
            t_min: ray.t_min,
            row_bytes: [near(0), near(1), near(2)],
        }
    }

    /// Byte offset of the near (`side` 0) or far (`side` 1) row of `axis` (only the lowest bit of
    /// `side` counts, so that the offset stays within `bounds` whatever it is).
    #[inline(always)]
    fn row_offset(&self, axis: usize, side: usize) -> usize {
        self.row_bytes[axis] ^ ((side & 1) * ROW_BYTES)
    }

    /// Row of the near (`side` 0) or far (`side` 1) plane of `axis` in [`WideNode::bounds`].
    #[inline(always)]
    pub fn row_index(&self, axis: usize, side: usize) -> usize {
        self.row_offset(axis, side) / ROW_BYTES
    }
}

impl NodeRay {
    /// The near (`side` 0) or far (`side` 1) row of `axis` of `node`, without an index check.
    #[inline(always)]
    pub fn row<'a>(&self, node: &'a WideNode, axis: usize, side: usize) -> &'a [f32; WIDTH] {
        debug_assert!(axis < 3 && side < 2);
        let offset = self.row_offset(axis, side);
        // SAFETY: `NodeRay::new`, the only maker of `row_bytes`, gives each the start of a row of
        // `bounds` (row < ROWS), a multiple of a row's size, and `row_offset` at most flips it to
        // the other row of the same axis; rows are arrays of WIDTH floats.
        unsafe { &*((node.bounds.as_ptr() as *const u8).add(offset) as *const [f32; WIDTH]) }
    }
}

/// How far along the ray a box may begin and still be entered, when the closest hit so far is at
/// `t_max`: a little beyond it, by the rounding bound of the slab test, as the binary traversal
/// does (see [`crate::accel::bvh::ordered`]): a primitive of lower index hit at exactly `t_max`
/// on the face of a box entered there must still win the tie.
#[inline(always)]
pub fn reach(t_max: f32) -> f32 {
    t_max + t_max.abs() * (ROBUST_FAR_SCALE - 1.0)
}

/// Whether `ray` may enter `bounds` within `t_min..=limit`: a slab test of one box, done with
/// three-lane vectors before any per-query state is prepared, so that a query whose ray passes
/// beside the whole tree costs a few instructions. It computes each plane's distance as the node
/// test does (the same numbers: the node test's differences and factors are negated, which
/// changes at most the sign of a zero), so for a box inside `bounds` it never says no where the
/// node test would say yes: rounding is monotonic, so the outer box's entry is no later and its
/// exit no earlier. A NaN distance (an origin on the plane of a parallel ray)
/// constrains nothing, as in the node test.
#[inline(always)]
pub fn may_enter(bounds: &Aabb, ray: &Ray, limit: f32) -> bool {
    use glam::Vec3A;
    let o = Vec3A::from(ray.origin());
    let inv = Vec3A::from(ray.inv_dir());
    let down = inv.cmplt(Vec3A::ZERO);
    let (lo, hi) = (Vec3A::from(bounds.min) - o, Vec3A::from(bounds.max) - o);
    let near = Vec3A::select(down, hi, lo) * inv;
    let far = Vec3A::select(down, lo, hi) * (inv * FAR_SCALE);
    let near = Vec3A::select(near.is_nan_mask(), Vec3A::NEG_INFINITY, near);
    let far = Vec3A::select(far.is_nan_mask(), Vec3A::INFINITY, far);
    let enter = near.max_element();
    let exit = far.min_element();
    (if enter > ray.t_min { enter } else { ray.t_min }) <= (if exit < limit { exit } else { limit })
}

/// The slab test of one child, one plane at a time: the reference every SIMD kernel must match bit
/// for bit. Returns the entry distance if the ray enters the box within `t_min..=limit`.
///
/// It is [`Aabb::slab_distances`]'s robust test (Ize 2013) with the far scale folded into the
/// inverse direction: `(far - o) * (inv * s)` instead of `(far - o) * inv * s`. Both round four
/// times between the exact `(far - o) / d` and the result (the reciprocal, the difference and two
/// products), each by at most half an ulp, so Ize's bound, and with it the guarantee that a box the
/// ray meets is never missed, holds for both; the folded form saves a product per axis per node.
///
/// Each distance is written `(o - plane) * -inv`, not `(plane - o) * inv`: the same number
/// (rounding to nearest is symmetric, so `o - plane` is exactly `-(plane - o)`), but for the sign
/// of a zero where the plane passes through the origin, which no comparison sees. In that order
/// an x86 kernel subtracts the plane straight from memory (the second operand of `vsubps` may be
/// a memory operand, the first may not): one instruction fewer per plane, six per node.
#[inline(always)]
pub fn child_entry_scalar(node: &WideNode, slot: usize, ray: &NodeRay, limit: f32) -> Option<f32> {
    let (mut enter, mut exit) = (ray.t_min, limit);
    for a in 0..3 {
        let t_near = (ray.origin[a] - node.bounds[ray.row_index(a, 0)][slot]) * -ray.inv_dir[a];
        let t_far = (ray.origin[a] - node.bounds[ray.row_index(a, 1)][slot]) * -ray.inv_far[a];
        enter = if t_near > enter { t_near } else { enter };
        exit = if t_far < exit { t_far } else { exit };
    }
    (enter <= exit).then_some(enter)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    #[test]
    fn empty_slots_are_never_entered() {
        let node = WideNode::EMPTY_NODE;
        for dir in [Vec3::X, -Vec3::Y, Vec3::new(0.0, -0.0, 1.0), Vec3::new(-1.0, 2.0, -3.0)] {
            for (t_min, t_max) in [(0.0, f32::INFINITY), (f32::NEG_INFINITY, f32::INFINITY), (-1.0, 1.0)] {
                let ray = Ray::segment(Vec3::new(0.5, -2.0, 3.0), dir, t_min, t_max);
                let r = NodeRay::new(&ray);
                for slot in 0..WIDTH {
                    assert_eq!(child_entry_scalar(&node, slot, &r, reach(t_max)), None);
                }
            }
        }
    }

    #[test]
    fn the_scalar_child_test_is_the_box_test() {
        let b = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(1.0, 0.5, 3.0));
        let mut node = WideNode::EMPTY_NODE;
        node.set_child(3, &b, 7, 0);
        assert_eq!(node.child_bounds(3), b);
        assert_eq!(node.child_count(), 1);
        for (o, d) in [(Vec3::ZERO, Vec3::Z), (Vec3::new(0.0, 0.25, 10.0), -Vec3::Z), (Vec3::ZERO, Vec3::X)] {
            let ray = Ray::new(o, d);
            let expected = b.intersect(&ray).map(|(t, _)| t);
            assert_eq!(child_entry_scalar(&node, 3, &NodeRay::new(&ray), f32::INFINITY), expected);
        }
    }

    #[test]
    fn the_outer_box_test_never_refuses_a_ray_a_child_takes() {
        use rand::{RngExt, SeedableRng};
        // Integer planes and axis-parallel directions of both signs, so that origins on planes
        // (NaN distances), rays in faces and flat boxes all occur.
        let mut rng = rand_pcg::Pcg32::seed_from_u64(0x5eed_0b0c);
        let values = [-2.0f32, -1.0, -0.0, 0.0, 0.5, 1.0, 2.0];
        let dirs = [-1.0f32, -0.0, 0.0, 0.3, 1.0];
        let mut pick = |v: &[f32]| v[rng.random_range(0..v.len())];
        let (mut entered, mut refused) = (0, 0);
        for i in 0..50_000 {
            let mut node = WideNode::EMPTY_NODE;
            let mut outer = Aabb::EMPTY;
            for slot in 0..1 + i % WIDTH {
                let a = Vec3::new(pick(&values), pick(&values), pick(&values));
                let b = Vec3::new(pick(&values), pick(&values), pick(&values));
                let child = Aabb::new(a.min(b), a.max(b));
                node.set_child(slot, &child, slot as u32, 0);
                outer = outer.union(&child);
            }
            let origin = Vec3::new(pick(&values), pick(&values), pick(&values)) * 1.5;
            let dir = Vec3::new(pick(&dirs), pick(&dirs), pick(&dirs));
            let t_max = [f32::INFINITY, 1.0, 2.5][i % 3];
            let ray = Ray::segment(origin, dir, 0.0, t_max);
            if !ray.is_valid() {
                continue;
            }
            let r = NodeRay::new(&ray);
            let limit = reach(t_max);
            let any_child = (0..WIDTH).any(|slot| child_entry_scalar(&node, slot, &r, limit).is_some());
            let may = may_enter(&outer, &ray, limit);
            assert!(may || !any_child, "{ray:?} enters a child of {node:?} but not {outer:?}");
            entered += any_child as u32;
            refused += !may as u32;
        }
        // Both outcomes occur often enough for the test to mean something.
        assert!(entered > 5_000 && refused > 5_000, "{entered} entered, {refused} refused");
    }

    #[test]
    fn near_rows_follow_the_direction_signs() {
        let r = NodeRay::new(&Ray::new(Vec3::ZERO, Vec3::new(-1.0, 0.0, -0.0)));
        let rows = |side| [0, 1, 2].map(|a| r.row_index(a, side));
        assert_eq!((rows(0), rows(1)), ([1, 2, 4], [0, 3, 5]));
        let r = NodeRay::new(&Ray::new(Vec3::ZERO, Vec3::new(0.5, -2.0, -1.0)));
        assert_eq!([0, 1, 2].map(|a| r.row_index(a, 0)), [0, 3, 5]);
    }
}
