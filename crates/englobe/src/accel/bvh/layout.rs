//! From a builder's tree to the flat layout of [`Bvh`].
//!
//! Builders work on whatever tree suits them (bottom-up pairing, top-down splits) and hand over a
//! [`BuildTree`]: an arena of nodes, each a leaf over a range of the builder's primitive order or
//! an interior node with two children. [`BuildTree::into_bvh`] lays it out depth-first with the
//! first child right after its parent, as pbrt's `flattenBVH` does (Pharr, Jakob and Humphreys,
//! "Physically Based Rendering", 3rd ed. 2016, section 4.3.4), and records the depth. The walk uses
//! an explicit stack, so a degenerate tree (a chain as deep as it has primitives) is laid out
//! without exhausting the call stack. Each interior node records the axis along which its
//! children lie most apart, and which child is lower along it ([`order_axis`]).

use super::{Bvh, BvhNode};
use crate::Aabb;

/// What a node of a [`BuildTree`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BuildKind {
    /// A leaf over `prims[first..first + count]` of its tree (`count >= 1`).
    Leaf {
        /// First entry in [`BuildTree::prims`].
        first: u32,
        /// Number of entries.
        count: u32,
    },
    /// An interior node; the children are indices into [`BuildTree::nodes`].
    Interior {
        /// The first and second child.
        children: [u32; 2],
        /// Primitive references under the node: the sum of its children's (what the conversion
        /// to wide nodes reads to decide where leaves go, without counting them first).
        count: u32,
    },
}

impl BuildNode {
    /// Primitive references under the node: a leaf's count, an interior node's recorded count.
    pub fn prims_under(&self) -> u32 {
        match self.kind {
            BuildKind::Leaf { count, .. } | BuildKind::Interior { count, .. } => count,
        }
    }
}

/// A node of a [`BuildTree`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildNode {
    /// The node's box.
    pub bounds: Aabb,
    /// Leaf or interior node.
    pub kind: BuildKind,
}

/// A binary tree as a builder makes it, before layout: nodes in any order, a root, and the
/// primitive references its leaves point into.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BuildTree {
    /// Every node, in the builder's order.
    pub nodes: Vec<BuildNode>,
    /// Primitive indices; leaves hold ranges of this list.
    pub prims: Vec<u32>,
    /// Index of the root in `nodes` (ignored when `nodes` is empty).
    pub root: u32,
}

impl BuildTree {
    /// Lays the tree out depth-first: each interior node is followed by its first child's subtree,
    /// then its second child's; leaves' references are copied in the same order.
    ///
    /// The tree is trusted to be a tree (every node reachable once from the root, each interior
    /// node's count the sum of its children's); builders guarantee it and the validator checks
    /// the result.
    pub fn into_bvh(self) -> Bvh {
        if self.nodes.is_empty() {
            return Bvh::empty();
        }
        let mut nodes = Vec::with_capacity(self.nodes.len());
        let mut prim_indices = Vec::with_capacity(self.prims.len());
        // Queries read both at random: on huge pages, a large tree's reads need far fewer
        // address translations (see `crate::geom::huge_pages`). Only the pages written become
        // resident, so the slots reserved beyond the nodes cost at most one huge page.
        crate::geom::huge_pages::advise_vec(&nodes);
        crate::geom::huge_pages::advise_vec(&prim_indices);
        let mut depth = 0u32;
        // (build node, flat node whose second-child index must point here, depth of the node)
        let mut stack: Vec<(u32, Option<usize>, u32)> = vec![(self.root, None, 0)];
        while let Some((id, patch, level)) = stack.pop() {
            let here = nodes.len();
            if let Some(parent) = patch {
                let parent: &mut BvhNode = &mut nodes[parent];
                parent.index = here as u32;
            }
            depth = depth.max(level);
            let node = &self.nodes[id as usize];
            match node.kind {
                BuildKind::Leaf { first, count } => {
                    let range = first as usize..first as usize + count as usize;
                    nodes.push(BvhNode::leaf(node.bounds, prim_indices.len() as u32, count));
                    prim_indices.extend_from_slice(&self.prims[range]);
                }
                BuildKind::Interior { children: [first, second], .. } => {
                    let (axis, second_is_lower) =
                        order_axis(&self.nodes[first as usize].bounds, &self.nodes[second as usize].bounds);
                    // The second child's index is patched in when it is laid out.
                    nodes.push(BvhNode::interior(node.bounds, 0, axis, second_is_lower));
                    stack.push((second, Some(here), level + 1));
                    stack.push((first, None, level + 1));
                }
            }
        }
        Bvh::from_parts(nodes, prim_indices, depth)
    }
}

/// The axis along which two sibling boxes lie most apart, and whether the second lies below the
/// first along it: the axis of the largest gap between them (the least overlap, when they
/// overlap along every axis), measured as the distance between their centres less their half
/// extents. A traversal that enters the lower child first when the ray goes up that axis then
/// enters the nearer one first as often as ordering by entry distance would (see
/// [`super::ordered`] for what was measured).
pub fn order_axis(first: &Aabb, second: &Aabb) -> (usize, bool) {
    let (a, b) = (first.center(), second.center());
    let gap = (b - a).abs() - (first.extent() + second.extent()) * 0.5;
    let axis = if gap.x >= gap.y && gap.x >= gap.z {
        0
    } else if gap.y >= gap.z {
        1
    } else {
        2
    };
    (axis, b[axis] < a[axis])
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn unit_at(x: f32) -> Aabb {
        Aabb::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 1.0, 1.0))
    }

    #[test]
    fn lays_out_depth_first_with_the_first_child_next() {
        // root(4) = [n3 = [leaf0, leaf1], leaf2], built bottom-up (root last).
        let tree = BuildTree {
            nodes: vec![
                BuildNode { bounds: unit_at(0.0), kind: BuildKind::Leaf { first: 0, count: 1 } },
                BuildNode { bounds: unit_at(1.0), kind: BuildKind::Leaf { first: 1, count: 1 } },
                BuildNode { bounds: unit_at(2.0), kind: BuildKind::Leaf { first: 2, count: 2 } },
                BuildNode {
                    bounds: unit_at(0.0).union(&unit_at(1.0)),
                    kind: BuildKind::Interior { children: [0, 1], count: 2 },
                },
                BuildNode {
                    bounds: unit_at(0.0).union(&unit_at(2.0)),
                    kind: BuildKind::Interior { children: [3, 2], count: 4 },
                },
            ],
            prims: vec![7, 5, 6, 4],
            root: 4,
        };
        let bvh = tree.into_bvh();
        let n = bvh.nodes();
        assert_eq!(n.len(), 5);
        assert_eq!(bvh.depth(), 2);
        assert!(!n[0].is_leaf() && n[0].index == 4, "root's second child is the last leaf");
        assert!(!n[1].is_leaf() && n[1].index == 3);
        assert_eq!((n[2].index, n[2].count), (0, 1));
        assert_eq!((n[3].index, n[3].count), (1, 1));
        assert_eq!((n[4].index, n[4].count), (2, 2));
        assert_eq!(bvh.prim_indices(), &[7, 5, 6, 4]);
    }

    #[test]
    fn a_deep_chain_is_laid_out_without_recursion() {
        // A chain 100 000 deep: interior i has children (leaf i, interior i + 1).
        let n = 100_000u32;
        let mut nodes = Vec::new();
        for i in 0..n {
            nodes.push(BuildNode { bounds: unit_at(0.0), kind: BuildKind::Leaf { first: i, count: 1 } });
        }
        for i in 0..n - 1 {
            let next = if i + 1 == n - 1 { n - 1 } else { n + i + 1 };
            nodes.push(BuildNode {
                bounds: unit_at(0.0),
                kind: BuildKind::Interior { children: [next, i], count: n - i },
            });
        }
        let tree = BuildTree { nodes, prims: (0..n).collect(), root: n };
        let bvh = tree.into_bvh();
        assert_eq!(bvh.nodes().len(), 2 * n as usize - 1);
        assert_eq!(bvh.depth(), n - 1);
    }

    #[test]
    fn the_order_axis_is_where_the_children_overlap_least() {
        // Apart along x by a gap of 1; their centres lie farther apart along y.
        let a = Aabb::new(Vec3::ZERO, Vec3::new(1.0, 10.0, 1.0));
        let b = Aabb::new(Vec3::new(2.0, 5.0, 0.0), Vec3::new(3.0, 16.0, 1.0));
        assert_eq!(order_axis(&a, &b), (0, false));
        assert_eq!(order_axis(&b, &a), (0, true));
        // Overlapping along every axis: the axis of least overlap.
        let c = Aabb::new(Vec3::ZERO, Vec3::splat(2.0));
        let d = Aabb::new(Vec3::new(0.5, -1.5, 0.5), Vec3::new(2.5, 0.5, 2.5));
        assert_eq!(order_axis(&c, &d), (1, true));
        let bvh = BuildTree {
            nodes: vec![
                BuildNode { bounds: b, kind: BuildKind::Leaf { first: 0, count: 1 } },
                BuildNode { bounds: a, kind: BuildKind::Leaf { first: 1, count: 1 } },
                BuildNode { bounds: a.union(&b), kind: BuildKind::Interior { children: [0, 1], count: 2 } },
            ],
            prims: vec![0, 1],
            root: 2,
        }
        .into_bvh();
        assert_eq!((bvh.nodes()[0].axis(), bvh.nodes()[0].count & super::super::SECOND_IS_LOWER != 0), (0, true));
    }

    #[test]
    fn empty_tree_has_no_node() {
        let bvh = BuildTree::default().into_bvh();
        assert!(bvh.nodes().is_empty() && bvh.prim_indices().is_empty());
        assert_eq!(bvh.depth(), 0);
        assert!(bvh.bounds().is_empty());
    }
}
