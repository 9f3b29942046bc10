//! The SAH kd-tree: a binary space partition by axis-aligned planes, each primitive referenced
//! from every leaf cell it overlaps, built with the surface area heuristic.
//!
//! * [`events`]: the split candidates ("events") of Wald and Havran (2006), "On building fast
//!   kd-trees for ray tracing, and on doing that in O(N log N)" (IEEE Symposium on Interactive Ray
//!   Tracing): the planes where a primitive's clipped box starts, ends or lies.
//! * [`build`]: their O(N log N) builder: one sort, then a sweep per node over events kept sorted
//!   by splitting and merging, split clipping, the empty space bonus, depth and leaf-size limits.
//! * [`traverse`]: front-to-back traversal with early exit (the algorithm of pbrt-v3's
//!   `KdTreeAccel`, Pharr, Jakob and Humphreys, "Physically Based Rendering", 3rd ed. 2016,
//!   section 4.4.4), robust for rays lying in a split plane, with mailboxing.
//! * [`stats`]: size, depth, SAH cost, and the invariants of a built tree, checked.
//!
//! The layout is pbrt's: 8-byte nodes in one array, the child below the plane stored right after
//! its parent, the parent holding the index of the child above. A leaf holds the offset of its
//! list in [`KdTree::leaf_lists`]: the count, then the primitive indices; every empty leaf shares
//! the empty list at offset 0.

pub mod build;
pub mod events;
pub mod stats;
pub mod traverse;

use super::{Accel, Counters, Hit, StructureStats};
use crate::PrimHit;
use crate::accel::ClipFn;
use crate::{Aabb, Ray};

/// Deepest tree built, whatever the parameters say: it bounds the traversal stack.
pub const MAX_DEPTH: u32 = 64;

/// Build parameters. The defaults are those the measurements of `docs/accelerators.md` use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KdTreeParams {
    /// SAH cost of traversing one interior node, relative to [`KdTreeParams::intersection_cost`].
    /// A node step here is a subtraction, a multiplication and two comparisons, an exact test a
    /// watertight triangle test: the default ratio of 1 to 20 is Wald and Havran's 15 to 20 moved
    /// towards pbrt's 1 to 80, where the exact tests per ray on real meshes stop improving (see
    /// `docs/accelerators.md`).
    pub traversal_cost: f32,
    /// SAH cost of one exact primitive test.
    pub intersection_cost: f32,
    /// Fraction of a split's cost forgiven when one side holds no primitive (Wald and Havran's
    /// `1 - lambda`): it favours cutting off empty space, which rays then cross for free.
    pub empty_bonus: f32,
    /// Deepest leaf; `None` for `8 + 1.3 log2(N)` (pbrt's rule). At most [`MAX_DEPTH`].
    pub max_depth: Option<u32>,
    /// Nodes with this many primitives or fewer become leaves without looking for a split. The
    /// default, 0, leaves it to the SAH, which goes on cutting empty space off a single primitive's
    /// cell while that pays (pbrt's 1 stops at one primitive in whatever cell it has).
    pub leaf_size: u32,
    /// Skip primitives a query has already tested in an earlier leaf (see
    /// [`crate::accel::mailbox`]); off only to measure what it saves.
    pub mailbox: bool,
}

impl Default for KdTreeParams {
    fn default() -> Self {
        KdTreeParams {
            traversal_cost: 1.0,
            intersection_cost: 20.0,
            empty_bonus: 0.2,
            max_depth: None,
            leaf_size: 0,
            mailbox: true,
        }
    }
}

impl KdTreeParams {
    /// The depth limit for `n` primitives.
    pub fn depth_limit(&self, n: usize) -> u32 {
        let automatic = || (8.0 + 1.3 * (n.max(1) as f64).log2()).round() as u32;
        self.max_depth.unwrap_or_else(automatic).min(MAX_DEPTH)
    }
}

/// One node of a [`KdTree`]: 8 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct KdNode {
    /// Interior node: the split position's bits. Leaf: offset of its list in
    /// [`KdTree::leaf_lists`].
    data: u32,
    /// Low two bits: the split axis (0 to 2), or 3 for a leaf. Interior nodes: the index of the
    /// child above the plane in the other 30.
    bits: u32,
}

const _: () = assert!(std::mem::size_of::<KdNode>() == 8);

/// Most nodes: interior nodes keep a child's index in 30 bits.
pub const MAX_NODES: usize = 1 << 30;

impl KdNode {
    const LEAF: u32 = 3;

    /// An interior node splitting `axis` at `split`, whose child above the plane is node `above`
    /// (below `MAX_NODES`).
    pub fn interior(axis: usize, split: f32, above: u32) -> Self {
        debug_assert!(axis < 3 && (above as usize) < MAX_NODES);
        KdNode { data: split.to_bits(), bits: (above << 2) | axis as u32 }
    }

    /// A leaf whose list starts at `offset` of [`KdTree::leaf_lists`].
    pub fn leaf(offset: u32) -> Self {
        KdNode { data: offset, bits: Self::LEAF }
    }

    /// True for a leaf.
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.bits & 3 == Self::LEAF
    }

    /// The split axis of an interior node.
    #[inline(always)]
    pub fn axis(&self) -> usize {
        (self.bits & 3) as usize
    }

    /// The split position of an interior node.
    #[inline(always)]
    pub fn split(&self) -> f32 {
        f32::from_bits(self.data)
    }

    /// The child above the plane of an interior node (the one below is the next node).
    #[inline(always)]
    pub fn above_child(&self) -> usize {
        (self.bits >> 2) as usize
    }

    /// A leaf's offset in [`KdTree::leaf_lists`].
    #[inline(always)]
    pub fn leaf_offset(&self) -> usize {
        self.data as usize
    }
}

/// An SAH kd-tree over primitives' boxes (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct KdTree {
    nodes: Vec<KdNode>,
    /// Leaf lists: a count, then that many primitive indices. Entry 0 is the empty list.
    leaf_lists: Vec<u32>,
    bounds: Aabb,
    depth: u32,
    /// Primitives the tree was built over (the length of the box list).
    prim_count: usize,
    mailbox: bool,
}

impl KdTree {
    /// Builds the tree over the primitives' boxes, clipping a primitive to a cell by intersecting
    /// its box with the cell, with the default parameters.
    pub fn build(boxes: &[Aabb]) -> Self {
        Self::build_with_clipper(boxes, &|prim, cell| boxes[prim as usize].intersection(cell), KdTreeParams::default())
    }

    /// Builds the tree; `clip(prim, cell)` gives the box of the part of primitive `prim` inside
    /// `cell` (empty if none), which may be much smaller than `boxes[prim] ∩ cell` (a triangle
    /// crossing a cell's corner diagonally). Primitives with an empty or non-finite box are left
    /// out: no ray can be said to hit them.
    pub fn build_with_clipper(boxes: &[Aabb], clip: ClipFn<'_>, params: KdTreeParams) -> Self {
        build::build(boxes, clip, params)
    }

    /// The nodes; the root is node 0 (none for an empty tree).
    pub fn nodes(&self) -> &[KdNode] {
        &self.nodes
    }

    /// The primitives of leaf `node`, in increasing order.
    #[inline(always)]
    pub fn leaf_prims(&self, node: &KdNode) -> &[u32] {
        let at = node.leaf_offset();
        let count = self.leaf_lists[at] as usize;
        &self.leaf_lists[at + 1..at + 1 + count]
    }

    /// All leaf lists, as stored.
    pub fn leaf_lists(&self) -> &[u32] {
        &self.leaf_lists
    }

    /// Edges on the longest path from the root to a leaf.
    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// The root cell: the box around every primitive.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Number of primitives the tree was built over.
    pub fn prim_count(&self) -> usize {
        self.prim_count
    }

    /// The two cells a node's plane cuts `cell` into: below, above.
    pub fn split_cell(cell: &Aabb, axis: usize, split: f32) -> (Aabb, Aabb) {
        let (mut below, mut above) = (*cell, *cell);
        below.max[axis] = split;
        above.min[axis] = split;
        (below, above)
    }
}

impl Accel for KdTree {
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    #[inline]
    fn closest_hit<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        intersect: impl FnMut(u32, &Ray) -> Option<PrimHit>,
    ) -> Option<Hit> {
        self.closest_hit_front_to_back(ray, counters, intersect)
    }

    #[inline]
    fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C, occludes: impl FnMut(u32, &Ray) -> bool) -> bool {
        self.any_hit_front_to_back(ray, counters, occludes)
    }

    fn stats(&self) -> StructureStats {
        self.structure_stats()
    }
}
