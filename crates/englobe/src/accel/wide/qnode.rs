//! The compressed wide node: the eight children's planes as bytes on a grid of the node's own box
//! (Ylitie, Karras and Laine 2017, "Efficient Incoherent Ray Traversal on GPUs Through Compressed
//! Wide BVHs", High-Performance Graphics), 128 bytes, two cache lines, against the 256 of a
//! [`WideNode`]: what a single ray's walk reads from memory at every node halved.
//!
//! A plane is decoded as `origin + q * scale` per axis, `q` a byte and `scale` a power of two,
//! so that `q * scale` is exact and the decoded plane is one rounding of the sum, the same with or
//! without a fused multiply-add. The byte of a lower plane is the largest whose decoded plane is
//! at or below the child's, that of an upper plane the smallest at or above it, each checked on the
//! decoded value itself: the decoded box holds the child's box, so the slab test of the decoded
//! box, robust for any box, never loses a ray that enters the child. Unused slots are left out by
//! a mask of the used ones.

use super::node::{ROWS, WIDTH, WalkNode, WideNode};
use crate::Aabb;

/// Largest byte of a plane.
const Q_MAX: u8 = u8::MAX;

/// One compressed node: see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct QNode {
    /// The children's planes as bytes, rows as in [`WideNode::bounds`].
    pub q: [[u8; WIDTH]; ROWS],
    /// Per axis, the grid's origin: the lower plane of the node's box.
    pub origin: [f32; 3],
    /// Per axis, the grid's step: a power of two.
    pub scale: [f32; 3],
    /// The children, as in [`WideNode::children`].
    pub children: [u32; WIDTH],
    /// Items of each leaf child, as in [`WideNode::counts`].
    pub counts: [u8; WIDTH],
    /// Bit `i` set if slot `i` holds a child.
    pub used: u8,
}

const _: () = assert!(std::mem::size_of::<QNode>() == 128);

impl WalkNode for QNode {
    #[inline(always)]
    fn in_tree(bvh: &super::TriangleBvh) -> &[Self] {
        &bvh.qnodes
    }

    #[inline(always)]
    fn child(&self, slot: usize) -> u32 {
        self.children[slot]
    }

    #[inline(always)]
    fn count(&self, slot: usize) -> u32 {
        self.counts[slot] as u32
    }
}

/// The plane that byte `q` decodes to on the grid `origin`, `scale`.
#[inline(always)]
pub fn decode(q: u8, origin: f32, scale: f32) -> f32 {
    origin + q as f32 * scale
}

/// The grid step of an axis from `lo` to `hi`: the smallest power of two, a normal float, whose
/// 255 steps from `lo` reach `hi` once decoded; `None` if none does (a box near the largest float).
fn step(lo: f32, hi: f32) -> Option<f32> {
    let mut scale = f32::MIN_POSITIVE;
    let needed = (hi - lo) / Q_MAX as f32;
    if needed.is_finite() && needed > scale {
        scale = 2f32.powi(needed.log2().ceil() as i32).max(f32::MIN_POSITIVE);
    }
    while decode(Q_MAX, lo, scale) < hi {
        scale *= 2.0;
        if !scale.is_finite() || !decode(Q_MAX, lo, scale).is_finite() {
            return None;
        }
    }
    Some(scale)
}

impl QNode {
    /// The compressed form of `node`, or `None` if some axis of its box has no grid (see [`step`]).
    pub fn new(node: &WideNode) -> Option<QNode> {
        let mut used = 0u8;
        let mut bounds = Aabb::EMPTY;
        for slot in 0..WIDTH {
            if node.children[slot] != super::node::EMPTY {
                used |= 1 << slot;
                bounds = bounds.union(&node.child_bounds(slot));
            }
        }
        let mut q = QNode {
            q: [[0; WIDTH]; ROWS],
            origin: [0.0; 3],
            scale: [1.0; 3],
            children: node.children,
            counts: node.counts,
            used,
        };
        if used == 0 {
            return Some(q);
        }
        for a in 0..3 {
            let (lo, hi) = (bounds.min[a], bounds.max[a]);
            let scale = step(lo, hi)?;
            q.origin[a] = lo;
            q.scale[a] = scale;
            for slot in 0..WIDTH {
                if used & (1 << slot) == 0 {
                    // Never entered (the mask leaves the slot out): the empty grid box.
                    q.q[2 * a][slot] = Q_MAX;
                    q.q[2 * a + 1][slot] = 0;
                    continue;
                }
                let (cmin, cmax) = (node.bounds[2 * a][slot], node.bounds[2 * a + 1][slot]);
                q.q[2 * a][slot] = below(cmin, lo, scale);
                q.q[2 * a + 1][slot] = above(cmax, lo, scale);
            }
        }
        Some(q)
    }

    /// The decoded box of slot `slot` (meaningful for used slots only).
    pub fn child_bounds(&self, slot: usize) -> Aabb {
        let p = |row: usize| decode(self.q[row][slot], self.origin[row / 2], self.scale[row / 2]);
        Aabb::new(glam::Vec3::new(p(0), p(2), p(4)), glam::Vec3::new(p(1), p(3), p(5)))
    }
}

/// The largest byte whose plane is at or below `x` (0 if none is: the grid starts at or below
/// every child's lower plane).
fn below(x: f32, origin: f32, scale: f32) -> u8 {
    let guess = ((x - origin) / scale).floor().clamp(0.0, Q_MAX as f32) as u8;
    let mut q = guess;
    while q > 0 && decode(q, origin, scale) > x {
        q -= 1;
    }
    while q < Q_MAX && decode(q + 1, origin, scale) <= x {
        q += 1;
    }
    q
}

/// The smallest byte whose plane is at or above `x` ([`Q_MAX`] reaches every child's upper plane).
fn above(x: f32, origin: f32, scale: f32) -> u8 {
    let guess = ((x - origin) / scale).ceil().clamp(0.0, Q_MAX as f32) as u8;
    let mut q = guess;
    while q < Q_MAX && decode(q, origin, scale) < x {
        q += 1;
    }
    while q > 0 && decode(q - 1, origin, scale) >= x {
        q -= 1;
    }
    q
}

/// The compressed forms of `nodes`, or an empty list if one of them has none.
pub fn compress(nodes: &[WideNode]) -> Vec<QNode> {
    nodes.iter().map(QNode::new).collect::<Option<Vec<_>>>().unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg32;

    use super::*;

    #[test]
    fn decoded_boxes_hold_their_children_at_every_scale() {
        let mut rng = Pcg32::seed_from_u64(0x9_0de);
        for scale in [1e-30f32, 1e-3, 1.0, 7.5, 1e6, 1e20] {
            for _ in 0..2_000 {
                let mut node = WideNode::EMPTY_NODE;
                let offset = Vec3::splat(rng.random_range(-1e3f32..1e3) * scale);
                let slots = rng.random_range(1..=WIDTH);
                for slot in 0..slots {
                    let a = Vec3::new(rng.random(), rng.random(), rng.random()) * scale + offset;
                    let b = a + Vec3::new(rng.random(), rng.random(), rng.random()) * scale * 0.1;
                    node.set_child(slot, &Aabb::new(a, b), slot as u32, 1);
                }
                let q = QNode::new(&node).expect("a grid");
                assert_eq!(q.used.count_ones() as usize, slots);
                for slot in 0..slots {
                    let (inner, outer) = (node.child_bounds(slot), q.child_bounds(slot));
                    assert!(
                        outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all(),
                        "{inner:?} {outer:?}"
                    );
                    // Tight: one step out at most on each side (with the origin's rounding).
                    let extent = (outer.max - outer.min) - (inner.max - inner.min);
                    let steps = Vec3::from_array(q.scale) * 3.0;
                    assert!(extent.cmple(steps).all(), "{inner:?} {outer:?} {:?}", q.scale);
                }
            }
        }
    }

    #[test]
    fn flat_children_and_a_box_near_the_largest_float() {
        let mut node = WideNode::EMPTY_NODE;
        node.set_child(0, &Aabb::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(1.0, 2.0, 4.0)), 0, 1);
        let q = QNode::new(&node).expect("a grid");
        let b = q.child_bounds(0);
        assert!(b.min.cmple(Vec3::new(1.0, 2.0, 3.0)).all() && b.max.cmpge(Vec3::new(1.0, 2.0, 4.0)).all());
        node.set_child(1, &Aabb::new(Vec3::splat(-3e38), Vec3::splat(3e38)), 1, 1);
        assert_eq!(QNode::new(&node), None);
        assert!(compress(&[node]).is_empty());
    }
}
