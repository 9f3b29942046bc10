//! The canonical tree's data: the 32-byte [`BvhNode`] and the [`Bvh`] that holds the nodes and
//! the leaves' primitive references, apart from the code that builds, walks and checks them.

use std::ops::Range;

use glam::Vec3;

use crate::Aabb;

/// One node of a [`Bvh`]: its box, and either its second child (interior node; the first child is
/// the next node of the array) or its range of primitive references (leaf). 32 bytes.
///
/// An interior node also records the axis along which its children lie apart (the axis of the
/// largest distance between their boxes' centres) and which of them lies on the lower side, so
/// that a traversal can enter the nearer child first from the sign of the ray's direction alone.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct BvhNode {
    /// Lower corner of the node's box.
    pub min: [f32; 3],
    /// Interior node: index of the second child. Leaf: offset of its first entry in
    /// [`Bvh::prim_indices`].
    pub index: u32,
    /// Upper corner of the node's box.
    pub max: [f32; 3],
    /// Leaf: its number of primitives (1 to 2^31 - 1). Interior node: [`INTERIOR`], plus the
    /// axis (0, 1 or 2) in the two low bits, plus [`SECOND_IS_LOWER`] if the second child's centre
    /// lies below the first's along that axis.
    pub count: u32,
}

const _: () = assert!(std::mem::size_of::<BvhNode>() == 32);

/// Flag of [`BvhNode::count`] marking an interior node.
pub const INTERIOR: u32 = 1 << 31;

/// Flag of an interior node's [`BvhNode::count`]: its second child lies on the lower side of its
/// axis, so rays going up that axis should enter it first.
pub const SECOND_IS_LOWER: u32 = 1 << 2;

impl BvhNode {
    /// An interior node whose second child is `second_child`, its children lying apart along
    /// `axis` (0, 1 or 2), the second below the first if `second_is_lower`.
    pub fn interior(bounds: Aabb, second_child: u32, axis: usize, second_is_lower: bool) -> Self {
        let count = INTERIOR | (axis as u32 & 3) | if second_is_lower { SECOND_IS_LOWER } else { 0 };
        BvhNode { min: bounds.min.to_array(), index: second_child, max: bounds.max.to_array(), count }
    }

    /// A leaf holding `count` references (1 to 2^31 - 1) starting at `first`.
    pub fn leaf(bounds: Aabb, first: u32, count: u32) -> Self {
        BvhNode { min: bounds.min.to_array(), index: first, max: bounds.max.to_array(), count }
    }

    /// The node's box.
    #[inline(always)]
    pub fn bounds(&self) -> Aabb {
        Aabb::new(Vec3::from_array(self.min), Vec3::from_array(self.max))
    }

    /// True for a leaf.
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.count & INTERIOR == 0
    }

    /// A leaf's number of primitives (0 for an interior node).
    #[inline(always)]
    pub fn prim_count(&self) -> u32 {
        if self.is_leaf() { self.count } else { 0 }
    }

    /// An interior node's axis (meaningless for a leaf).
    #[inline(always)]
    pub fn axis(&self) -> usize {
        (self.count & 3) as usize
    }

    /// A leaf's range in [`Bvh::prim_indices`] (empty for interior nodes).
    #[inline(always)]
    pub fn prim_range(&self) -> Range<usize> {
        if self.is_leaf() { self.index as usize..self.index as usize + self.count as usize } else { 0..0 }
    }
}

/// A binary BVH in the flat depth-first layout. Built by a builder ([`crate::accel::SeedPairing`], ...) from the
/// primitives' boxes; queried with the ordered traversal (see [`super::ordered`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bvh {
    pub(super) nodes: Vec<BvhNode>,
    pub(super) prim_indices: Vec<u32>,
    pub(super) depth: u32,
}

impl Bvh {
    /// The tree over no primitive: no node at all; every query misses.
    pub fn empty() -> Self {
        Bvh::default()
    }

    /// A tree from its parts, unchecked: [`crate::accel::bvh::validate::validate_bvh`] says whether it
    /// is well formed. Queries on a malformed tree give wrong answers or panic, never worse.
    pub(crate) fn from_parts(nodes: Vec<BvhNode>, prim_indices: Vec<u32>, depth: u32) -> Self {
        Bvh { nodes, prim_indices, depth }
    }

    /// The nodes; the root is node 0.
    pub fn nodes(&self) -> &[BvhNode] {
        &self.nodes
    }

    /// The primitive references of all leaves, leaf after leaf.
    pub fn prim_indices(&self) -> &[u32] {
        &self.prim_indices
    }

    /// Edges on the longest path from the root to a leaf (0 for a single leaf or no node).
    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// The root's box (the empty box for an empty tree).
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, BvhNode::bounds)
    }
}
