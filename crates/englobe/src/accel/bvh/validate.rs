//! The invariants of a [`Bvh`], checked, and its quality, measured.
//!
//! [`validate_bvh`] walks the tree from the root with an explicit stack (so degenerate trees are
//! fine) and checks that:
//!
//! * the layout is sound: child and leaf indices are in range, every leaf holds at least one
//!   primitive, interior nodes' flags name an axis, the first child follows its parent and the
//!   second comes after it;
//! * every node is reached exactly once from the root (no orphans, no sharing);
//! * every primitive is referenced exactly once, and only primitives that exist;
//! * every child box lies inside its parent's, and every leaf box holds its primitives' boxes;
//! * the recorded depth is the real one.
//!
//! On success it returns [`BvhQuality`]: counts, depth, leaf sizes, SAH cost (see
//! [`crate::accel::bvh::stats`]) and whether every box is the tightest possible.

use super::{Bvh, INTERIOR, SECOND_IS_LOWER};
use crate::Aabb;
use crate::accel::{ClipFn, InvalidStructure, LEAF_SIZE_BUCKETS, StructureStats, Validate};

/// A broken invariant, naming the node or primitive at fault.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BvhError {
    /// No node, but primitives to hold (or nodes but no primitive).
    #[error("the tree has {nodes} nodes for {prims} primitives")]
    EmptyMismatch {
        /// Nodes in the tree.
        nodes: usize,
        /// Primitives it should hold.
        prims: usize,
    },
    /// A child index outside the node array, or not after its parent.
    #[error("node {node}: child index {child} is not a node after it (the tree has {len} nodes)")]
    BadChild {
        /// The parent.
        node: usize,
        /// The bad index.
        child: usize,
        /// Number of nodes.
        len: usize,
    },
    /// A leaf range outside `prim_indices`.
    #[error("leaf {node}: references {start}..{end} are outside the {len} stored")]
    BadLeafRange {
        /// The leaf.
        node: usize,
        /// Range start.
        start: usize,
        /// Range end.
        end: usize,
        /// Length of `prim_indices`.
        len: usize,
    },
    /// A leaf without primitives.
    #[error("leaf {node} holds no primitive")]
    EmptyLeaf {
        /// The leaf.
        node: usize,
    },
    /// An interior node whose flags are not an axis and the lower-child flag.
    #[error("interior node {node} has malformed flags {count:#x}")]
    BadFlags {
        /// The node.
        node: usize,
        /// Its `count` field.
        count: u32,
    },
    /// A node reached twice from the root.
    #[error("node {node} is reached more than once")]
    SharedNode {
        /// The node.
        node: usize,
    },
    /// A node never reached from the root.
    #[error("node {node} is not reachable from the root")]
    Orphan {
        /// The node.
        node: usize,
    },
    /// A reference to a primitive that does not exist.
    #[error("leaf {node} references primitive {prim}, but there are only {prims}")]
    UnknownPrimitive {
        /// The leaf.
        node: usize,
        /// The reference.
        prim: u32,
        /// Number of primitives.
        prims: usize,
    },
    /// A primitive referenced zero times or more than once.
    #[error("primitive {prim} is referenced {times} times, expected once")]
    PrimitiveCount {
        /// The primitive.
        prim: usize,
        /// How often it is referenced.
        times: usize,
    },
    /// `prim_indices` holds references that no leaf covers.
    #[error("{stored} primitive references are stored but leaves cover {covered}")]
    StrayReferences {
        /// Length of `prim_indices`.
        stored: usize,
        /// References covered by leaves.
        covered: usize,
    },
    /// A child box sticks out of its parent's.
    #[error("node {child}'s box {child_box:?} is not inside its parent {parent}'s box {parent_box:?}")]
    ChildOutsideParent {
        /// The parent.
        parent: usize,
        /// The child.
        child: usize,
        /// Parent box.
        parent_box: Aabb,
        /// Child box.
        child_box: Aabb,
    },
    /// A primitive's box sticks out of its leaf's.
    #[error("primitive {prim}'s box is not inside leaf {node}'s box")]
    PrimitiveOutsideLeaf {
        /// The leaf.
        node: usize,
        /// The primitive.
        prim: u32,
    },
    /// The recorded depth is not the tree's.
    #[error("the tree records depth {recorded} but is {actual} deep")]
    WrongDepth {
        /// What the tree says.
        recorded: u32,
        /// What it is.
        actual: u32,
    },
}

/// Shape and quality of a valid tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhQuality {
    /// All nodes.
    pub nodes: usize,
    /// Interior nodes.
    pub interior: usize,
    /// Leaves.
    pub leaves: usize,
    /// Primitives held.
    pub prims: usize,
    /// Edges on the longest root-to-leaf path.
    pub depth: u32,
    /// Smallest leaf (primitives); 0 for an empty tree.
    pub min_leaf: usize,
    /// Largest leaf.
    pub max_leaf: usize,
    /// Mean primitives per leaf.
    pub mean_leaf: f64,
    /// Leaves by number of primitives (see [`crate::accel::StructureStats::leaf_sizes`]).
    pub leaf_sizes: [usize; LEAF_SIZE_BUCKETS],
    /// SAH cost (see [`Bvh::sah_cost`]).
    pub sah_cost: f32,
    /// True if every leaf box is exactly the union of its primitives' boxes and every interior box
    /// the union of its children's.
    pub tight: bool,
}

/// Checks every invariant of `bvh` built over `prim_boxes` (primitive `i` has box
/// `prim_boxes[i]`), and measures it.
pub fn validate_bvh(bvh: &Bvh, prim_boxes: &[Aabb]) -> Result<BvhQuality, BvhError> {
    let nodes = bvh.nodes();
    let refs = bvh.prim_indices();
    let prims = prim_boxes.len();
    if nodes.is_empty() || prims == 0 {
        if nodes.is_empty() && prims == 0 && refs.is_empty() {
            return Ok(BvhQuality {
                nodes: 0,
                interior: 0,
                leaves: 0,
                prims: 0,
                depth: 0,
                min_leaf: 0,
                max_leaf: 0,
                mean_leaf: 0.0,
                leaf_sizes: [0; LEAF_SIZE_BUCKETS],
                sah_cost: 0.0,
                tight: true,
            });
        }
        return Err(BvhError::EmptyMismatch { nodes: nodes.len(), prims });
    }

    let mut reached = vec![false; nodes.len()];
    let mut times = vec![0usize; prims];
    let (mut leaves, mut covered, mut depth) = (0usize, 0usize, 0u32);
    let (mut min_leaf, mut max_leaf) = (usize::MAX, 0usize);
    let mut tight = true;
    // (node, its parent, its depth)
    let mut stack: Vec<(usize, Option<usize>, u32)> = vec![(0, None, 0)];
    while let Some((index, parent, level)) = stack.pop() {
        if std::mem::replace(&mut reached[index], true) {
            return Err(BvhError::SharedNode { node: index });
        }
        depth = depth.max(level);
        let node = &nodes[index];
        let bounds = node.bounds();
        if let Some(parent) = parent {
            let parent_box = nodes[parent].bounds();
            if !parent_box.contains_box(&bounds) {
                return Err(BvhError::ChildOutsideParent { parent, child: index, parent_box, child_box: bounds });
            }
        }
        if node.is_leaf() {
            let range = node.prim_range();
            if range.is_empty() {
                return Err(BvhError::EmptyLeaf { node: index });
            }
            if range.end > refs.len() {
                return Err(BvhError::BadLeafRange {
                    node: index,
                    start: range.start,
                    end: range.end,
                    len: refs.len(),
                });
            }
            leaves += 1;
            covered += range.len();
            min_leaf = min_leaf.min(range.len());
            max_leaf = max_leaf.max(range.len());
            let mut union = Aabb::EMPTY;
            for &prim in &refs[range] {
                let Some(prim_box) = prim_boxes.get(prim as usize) else {
                    return Err(BvhError::UnknownPrimitive { node: index, prim, prims });
                };
                times[prim as usize] += 1;
                if !bounds.contains_box(prim_box) {
                    return Err(BvhError::PrimitiveOutsideLeaf { node: index, prim });
                }
                union = union.union(prim_box);
            }
            tight &= union == bounds;
        } else {
            if node.count & !(INTERIOR | 3 | SECOND_IS_LOWER) != 0 || node.axis() > 2 {
                return Err(BvhError::BadFlags { node: index, count: node.count });
            }
            let (first, second) = (index + 1, node.index as usize);
            for child in [first, second] {
                if child >= nodes.len() || child <= index {
                    return Err(BvhError::BadChild { node: index, child, len: nodes.len() });
                }
            }
            if second == first {
                return Err(BvhError::BadChild { node: index, child: second, len: nodes.len() });
            }
            tight &= nodes[first].bounds().union(&nodes[second].bounds()) == bounds;
            stack.push((second, Some(index), level + 1));
            stack.push((first, Some(index), level + 1));
        }
    }
    if let Some(orphan) = reached.iter().position(|&r| !r) {
        return Err(BvhError::Orphan { node: orphan });
    }
    if let Some((prim, &t)) = times.iter().enumerate().find(|&(_, &t)| t != 1) {
        return Err(BvhError::PrimitiveCount { prim, times: t });
    }
    if covered != refs.len() {
        return Err(BvhError::StrayReferences { stored: refs.len(), covered });
    }
    if depth != bvh.depth() {
        return Err(BvhError::WrongDepth { recorded: bvh.depth(), actual: depth });
    }
    Ok(BvhQuality {
        nodes: nodes.len(),
        interior: nodes.len() - leaves,
        leaves,
        prims,
        depth,
        min_leaf,
        max_leaf,
        mean_leaf: covered as f64 / leaves as f64,
        leaf_sizes: bvh.leaf_sizes(),
        sah_cost: bvh.sah_cost(),
        tight,
    })
}

impl Validate for Bvh {
    fn validate(&self, prim_boxes: &[Aabb], _clip: Option<ClipFn<'_>>) -> Result<StructureStats, InvalidStructure> {
        validate_bvh(self, prim_boxes).map_err(|e| InvalidStructure::new("BVH", e))?;
        Ok(self.structure_stats())
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::SeedPairing;
    use crate::accel::bvh::BvhNode;

    fn boxes(n: usize) -> Vec<Aabb> {
        (0..n).map(|i| Aabb::new(Vec3::splat(i as f32), Vec3::splat(i as f32 + 0.5))).collect()
    }

    /// The seed tree over `n` boxes, taken apart for tampering.
    fn parts(n: usize) -> (Vec<BvhNode>, Vec<u32>, u32) {
        let bvh = SeedPairing::build(&boxes(n));
        (bvh.nodes().to_vec(), bvh.prim_indices().to_vec(), bvh.depth())
    }

    #[test]
    fn the_seed_tree_is_valid_and_tight() {
        for n in [0, 1, 2, 3, 7, 64, 101] {
            let q = validate_bvh(&SeedPairing::build(&boxes(n)), &boxes(n)).unwrap();
            assert_eq!((q.prims, q.leaves, q.nodes), (n, n, (2 * n).saturating_sub(1)), "n = {n}");
            assert!(q.tight);
            if n > 0 {
                assert_eq!((q.min_leaf, q.max_leaf, q.mean_leaf), (1, 1, 1.0));
            }
        }
    }

    #[test]
    fn a_primitive_referenced_twice_is_caught() {
        let (nodes, mut refs, depth) = parts(5);
        refs[1] = refs[0];
        let err = validate_bvh(&Bvh::from_parts(nodes, refs, depth), &boxes(5)).unwrap_err();
        assert!(matches!(err, BvhError::PrimitiveCount { .. } | BvhError::PrimitiveOutsideLeaf { .. }), "{err}");
    }

    #[test]
    fn a_child_outside_its_parent_is_caught() {
        let (mut nodes, refs, depth) = parts(4);
        let last = nodes.len() - 1;
        nodes[last].max[0] += 10.0;
        let err = validate_bvh(&Bvh::from_parts(nodes, refs, depth), &boxes(4)).unwrap_err();
        assert!(matches!(err, BvhError::ChildOutsideParent { child, .. } if child == last), "{err}");
    }

    #[test]
    fn a_leaf_smaller_than_its_primitive_is_caught() {
        let (mut nodes, refs, depth) = parts(4);
        let last = nodes.len() - 1;
        nodes[last].max[1] -= 0.25;
        let err = validate_bvh(&Bvh::from_parts(nodes, refs, depth), &boxes(4)).unwrap_err();
        assert!(matches!(err, BvhError::PrimitiveOutsideLeaf { node, .. } if node == last), "{err}");
    }

    #[test]
    fn a_wrong_depth_is_caught() {
        let (nodes, refs, depth) = parts(8);
        let err = validate_bvh(&Bvh::from_parts(nodes, refs, depth + 1), &boxes(8)).unwrap_err();
        assert_eq!(err, BvhError::WrongDepth { recorded: 4, actual: 3 });
    }

    #[test]
    fn bad_indices_are_caught_not_panicked_on() {
        let (mut nodes, refs, depth) = parts(4);
        nodes[0].index = 99;
        assert!(matches!(
            validate_bvh(&Bvh::from_parts(nodes, refs.clone(), depth), &boxes(4)),
            Err(BvhError::BadChild { child: 99, .. })
        ));
        let (mut nodes, _, _) = parts(4);
        let leaf = nodes.iter().position(BvhNode::is_leaf).unwrap();
        nodes[leaf].index = 3;
        nodes[leaf].count = 2;
        assert!(validate_bvh(&Bvh::from_parts(nodes, refs.clone(), depth), &boxes(4)).is_err());
        let (nodes, _, _) = parts(4);
        assert!(matches!(
            validate_bvh(&Bvh::from_parts(nodes, vec![0, 1, 2, 9], depth), &boxes(4)),
            Err(BvhError::UnknownPrimitive { prim: 9, .. })
        ));
    }

    #[test]
    fn empty_leaves_and_bad_flags_are_caught() {
        let (mut nodes, refs, depth) = parts(4);
        let leaf = nodes.iter().position(BvhNode::is_leaf).unwrap();
        nodes[leaf].count = 0;
        assert_eq!(
            validate_bvh(&Bvh::from_parts(nodes, refs.clone(), depth), &boxes(4)),
            Err(BvhError::EmptyLeaf { node: leaf })
        );
        let (mut nodes, _, _) = parts(4);
        nodes[0].count |= 3;
        assert!(matches!(
            validate_bvh(&Bvh::from_parts(nodes, refs.clone(), depth), &boxes(4)),
            Err(BvhError::BadFlags { node: 0, .. })
        ));
        let (mut nodes, _, _) = parts(4);
        nodes[0].count |= 1 << 8;
        assert!(matches!(
            validate_bvh(&Bvh::from_parts(nodes, refs, depth), &boxes(4)),
            Err(BvhError::BadFlags { node: 0, .. })
        ));
    }

    #[test]
    fn orphans_and_stray_references_are_caught() {
        let (mut nodes, mut refs, depth) = parts(2);
        nodes.push(nodes[1]);
        assert_eq!(
            validate_bvh(&Bvh::from_parts(nodes, refs.clone(), depth), &boxes(2)),
            Err(BvhError::Orphan { node: 3 })
        );
        let (nodes, _, _) = parts(2);
        refs.push(0);
        assert!(validate_bvh(&Bvh::from_parts(nodes, refs, depth), &boxes(2)).is_err());
        assert!(matches!(validate_bvh(&Bvh::empty(), &boxes(3)), Err(BvhError::EmptyMismatch { nodes: 0, prims: 3 })));
    }
}
