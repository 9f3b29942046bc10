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
pub mod tree;

pub use tree::{KdNode, KdTree, KdTreeParams, MAX_DEPTH, MAX_NODES};

use super::{Accel, Counters, Hit, StructureStats};
use crate::PrimHit;
use crate::accel::ClipFn;
use crate::{Aabb, Ray};

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
