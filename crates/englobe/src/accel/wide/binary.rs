//! The binary trees the conversion to wide nodes reads ([`super::convert()`]): the laid-out
//! [`Bvh`] of any builder, and the top-down builders' [`BuildTree`] as the build leaves it, so that
//! a structure that keeps only the wide form skips the binary layout pass.

use std::ops::Range;

use crate::Aabb;
use crate::accel::bvh::{BuildKind, BuildTree, Bvh};

/// A binary tree as the conversion reads it.
pub trait BinaryTree {
    /// The root, or `None` for a tree without nodes.
    fn root(&self) -> Option<u32>;
    /// Slots of node indices (every node index is below it).
    fn slots(&self) -> usize;
    /// A node's box.
    fn bounds(&self, node: u32) -> Aabb;
    /// An interior node's first and second child; `None` for a leaf.
    fn children(&self, node: u32) -> Option<[u32; 2]>;
    /// A leaf's range in [`BinaryTree::prims`] (empty for an interior node).
    fn leaf_range(&self, node: u32) -> Range<usize>;
    /// The primitive references the leaves' ranges index.
    fn prims(&self) -> &[u32];
    /// Primitive references under a node, if the tree records them; otherwise the conversion
    /// counts them in a walk of its own first.
    fn prims_under(&self, node: u32) -> Option<u32>;
}

impl BinaryTree for Bvh {
    fn root(&self) -> Option<u32> {
        (!self.nodes().is_empty()).then_some(0)
    }
    fn slots(&self) -> usize {
        self.nodes().len()
    }
    fn bounds(&self, node: u32) -> Aabb {
        self.nodes()[node as usize].bounds()
    }
    fn children(&self, node: u32) -> Option<[u32; 2]> {
        let n = &self.nodes()[node as usize];
        (!n.is_leaf()).then_some([node + 1, n.index])
    }
    fn leaf_range(&self, node: u32) -> Range<usize> {
        self.nodes()[node as usize].prim_range()
    }
    fn prims(&self) -> &[u32] {
        self.prim_indices()
    }
    fn prims_under(&self, _: u32) -> Option<u32> {
        None
    }
}

impl BinaryTree for BuildTree {
    fn root(&self) -> Option<u32> {
        (!self.nodes.is_empty()).then_some(self.root)
    }
    fn slots(&self) -> usize {
        self.nodes.len()
    }
    fn bounds(&self, node: u32) -> Aabb {
        self.nodes[node as usize].bounds
    }
    fn children(&self, node: u32) -> Option<[u32; 2]> {
        match self.nodes[node as usize].kind {
            BuildKind::Interior { children, .. } => Some(children),
            BuildKind::Leaf { .. } => None,
        }
    }
    fn leaf_range(&self, node: u32) -> Range<usize> {
        match self.nodes[node as usize].kind {
            BuildKind::Leaf { first, count } => first as usize..(first + count) as usize,
            BuildKind::Interior { .. } => 0..0,
        }
    }
    fn prims(&self) -> &[u32] {
        &self.prims
    }
    fn prims_under(&self, node: u32) -> Option<u32> {
        Some(self.nodes[node as usize].prims_under())
    }
}
