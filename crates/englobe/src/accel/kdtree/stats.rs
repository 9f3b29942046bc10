//! Size and quality of a [`KdTree`], and its invariants, checked.
//!
//! The SAH cost is that of [`crate::accel::bvh::stats`] (Goldsmith and Salmon 1987, in the form
//! of MacDonald and Booth 1990, "Heuristics for Ray Tracing Using Space Subdivision"), over cells
//! instead of boxes, with the same unit costs, so that the figures of both kinds of structure can
//! be set side by side: a cell is reached with probability `area(cell) / area(root)`, an interior
//! node costs [`SAH_TRAVERSAL_COST`], a leaf [`SAH_INTERSECTION_COST`] per reference.
//!
//! [`validate_kdtree`] walks the tree from the root with its cells and checks that the layout is
//! sound (indices in range, the child below right after its parent, every node reached once), that
//! every split lies strictly inside its cell, that every leaf's list is well formed and only
//! references primitives whose boxes meet the leaf's cell, that every primitive with a box is
//! referenced, and that the recorded depth is the real one.

use super::{KdTree, MAX_DEPTH};
use crate::Aabb;
use crate::accel::bvh::{SAH_INTERSECTION_COST, SAH_TRAVERSAL_COST};
use crate::accel::{ClipFn, InvalidStructure, LEAF_SIZE_BUCKETS, StructureStats, Validate};

/// A broken invariant of a kd-tree.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum KdTreeError {
    /// Nodes without primitives, or primitives without nodes.
    #[error("the tree has {nodes} nodes for {prims} primitives with a box")]
    EmptyMismatch {
        /// Nodes.
        nodes: usize,
        /// Primitives that should be held.
        prims: usize,
    },
    /// A child index out of range or not after its parent.
    #[error("node {node}: child {child} is not a node after it")]
    BadChild {
        /// The parent.
        node: usize,
        /// The child index.
        child: usize,
    },
    /// A node reached twice, or never.
    #[error("node {node} is reached {times} times from the root")]
    Reached {
        /// The node.
        node: usize,
        /// How often.
        times: usize,
    },
    /// A split plane on or outside its cell's boundary.
    #[error("node {node}: split {split} on axis {axis} is not strictly inside its cell {cell:?}")]
    SplitOutside {
        /// The node.
        node: usize,
        /// Axis.
        axis: usize,
        /// Position.
        split: f32,
        /// The node's cell.
        cell: Aabb,
    },
    /// A leaf list out of range, unsorted, or naming a primitive that does not exist.
    #[error("leaf {node}: bad list at {offset}: {why}")]
    BadList {
        /// The leaf.
        node: usize,
        /// Its offset.
        offset: usize,
        /// What is wrong.
        why: String,
    },
    /// A primitive referenced by a leaf whose cell its box does not meet.
    #[error("leaf {node} references primitive {prim}, whose box {prim_box:?} misses the cell {cell:?}")]
    StrayReference {
        /// The leaf.
        node: usize,
        /// The primitive.
        prim: u32,
        /// Its box.
        prim_box: Aabb,
        /// The leaf's cell.
        cell: Aabb,
    },
    /// A primitive with a box referenced by no leaf.
    #[error("primitive {prim} is referenced by no leaf")]
    Unreferenced {
        /// The primitive.
        prim: usize,
    },
    /// The recorded depth is not the real one, or over the limit.
    #[error("the tree records depth {recorded} but is {actual} deep (limit {MAX_DEPTH})")]
    WrongDepth {
        /// Recorded.
        recorded: u32,
        /// Real.
        actual: u32,
    },
}

/// Shape and quality of a valid kd-tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KdTreeQuality {
    /// Interior nodes.
    pub interior: usize,
    /// Leaves, empty ones included.
    pub leaves: usize,
    /// Leaves with no primitive.
    pub empty_leaves: usize,
    /// Edges on the longest root-to-leaf path.
    pub depth: u32,
    /// References stored in leaves.
    pub prim_refs: usize,
    /// References per primitive with a box (1 would mean no primitive is split).
    pub refs_per_prim: f64,
    /// Largest leaf.
    pub max_leaf: usize,
    /// SAH cost (see [`KdTree::sah_cost`]).
    pub sah_cost: f32,
}

impl KdTree {
    /// Visits every node with its cell and depth, depth first.
    fn for_each_cell(&self, mut visit: impl FnMut(usize, &Aabb, u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![(0usize, self.bounds, 0u32)];
        while let Some((index, cell, depth)) = stack.pop() {
            visit(index, &cell, depth);
            let node = &self.nodes[index];
            if !node.is_leaf() {
                let (below, above) = KdTree::split_cell(&cell, node.axis(), node.split());
                stack.push((node.above_child(), above, depth + 1));
                stack.push((index + 1, below, depth + 1));
            }
        }
    }

    /// Leaves, empty ones included.
    pub fn leaf_count(&self) -> usize {
        self.nodes.iter().filter(|n| n.is_leaf()).count()
    }

    /// Non-empty leaves by number of primitives (see [`StructureStats::leaf_sizes`]); empty leaves
    /// are not counted.
    pub fn leaf_sizes(&self) -> [usize; LEAF_SIZE_BUCKETS] {
        let mut sizes = [0; LEAF_SIZE_BUCKETS];
        for n in self.nodes.iter().filter(|n| n.is_leaf()) {
            let len = self.leaf_prims(n).len();
            if len > 0 {
                sizes[len.min(LEAF_SIZE_BUCKETS) - 1] += 1;
            }
        }
        sizes
    }

    /// References stored in leaves.
    pub fn prim_refs(&self) -> usize {
        self.nodes.iter().filter(|n| n.is_leaf()).map(|n| self.leaf_prims(n).len()).sum()
    }

    /// Bytes held: the struct, its nodes and its leaf lists.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + std::mem::size_of_val(self.nodes.as_slice())
            + std::mem::size_of_val(self.leaf_lists.as_slice())
    }

    /// The SAH cost with the BVH's unit costs; 0 for an empty tree. If the root cell has no area,
    /// every node counts as reached.
    pub fn sah_cost(&self) -> f32 {
        let root_area = self.bounds.surface_area() as f64;
        let mut cost = 0.0f64;
        self.for_each_cell(|index, cell, _| {
            let p = if root_area > 0.0 { cell.surface_area() as f64 / root_area } else { 1.0 };
            let node = &self.nodes[index];
            cost += p * if node.is_leaf() {
                SAH_INTERSECTION_COST as f64 * self.leaf_prims(node).len() as f64
            } else {
                SAH_TRAVERSAL_COST as f64
            };
        });
        cost as f32
    }

    /// The statistics every structure reports.
    pub fn structure_stats(&self) -> StructureStats {
        let leaves = self.leaf_count();
        StructureStats {
            nodes: self.nodes.len() - leaves,
            leaves,
            depth: self.depth as usize,
            prim_refs: self.prim_refs(),
            memory_bytes: self.memory_bytes(),
            sah_cost: Some(self.sah_cost()),
            leaf_sizes: self.leaf_sizes(),
        }
    }
}

/// Checks every invariant of `tree` built over `prim_boxes`, and measures it.
pub fn validate_kdtree(tree: &KdTree, prim_boxes: &[Aabb]) -> Result<KdTreeQuality, KdTreeError> {
    let nodes = tree.nodes();
    let lists = tree.leaf_lists();
    let has_box = |b: &Aabb| !b.is_empty() && b.is_finite();
    let with_box = prim_boxes.iter().filter(|b| has_box(b)).count();
    if nodes.is_empty() != (with_box == 0) || tree.prim_count() != prim_boxes.len() {
        return Err(KdTreeError::EmptyMismatch { nodes: nodes.len(), prims: with_box });
    }
    if lists.first() != Some(&0) {
        return Err(KdTreeError::BadList { node: 0, offset: 0, why: "the shared empty list is missing".into() });
    }
    let mut reached = vec![0usize; nodes.len()];
    let mut referenced = vec![false; prim_boxes.len()];
    let (mut depth, mut prim_refs, mut max_leaf, mut empty_leaves) = (0u32, 0usize, 0usize, 0usize);
    let mut error = None;
    // The walk below trusts child indices, so they are checked first.
    for (i, n) in nodes.iter().enumerate() {
        if !n.is_leaf() && (i + 1 >= nodes.len() || n.above_child() <= i + 1 || n.above_child() >= nodes.len()) {
            return Err(KdTreeError::BadChild { node: i, child: n.above_child() });
        }
    }
    tree.for_each_cell(|index, cell, level| {
        reached[index] += 1;
        depth = depth.max(level);
        if error.is_some() || reached[index] > 1 {
            return;
        }
        let node = &nodes[index];
        if !node.is_leaf() {
            let (axis, split) = (node.axis(), node.split());
            if !(split > cell.min[axis] && split < cell.max[axis]) {
                error = Some(KdTreeError::SplitOutside { node: index, axis, split, cell: *cell });
            }
            return;
        }
        let offset = node.leaf_offset();
        let Some(&count) = lists.get(offset) else {
            error = Some(KdTreeError::BadList { node: index, offset, why: "offset out of range".into() });
            return;
        };
        let Some(prims) = lists.get(offset + 1..offset + 1 + count as usize) else {
            error = Some(KdTreeError::BadList { node: index, offset, why: format!("{count} entries overrun") });
            return;
        };
        if prims.windows(2).any(|w| w[0] >= w[1]) {
            error = Some(KdTreeError::BadList { node: index, offset, why: "not strictly increasing".into() });
            return;
        }
        prim_refs += prims.len();
        max_leaf = max_leaf.max(prims.len());
        empty_leaves += prims.is_empty() as usize;
        for &prim in prims {
            let Some(b) = prim_boxes.get(prim as usize) else {
                error = Some(KdTreeError::BadList { node: index, offset, why: format!("primitive {prim}") });
                return;
            };
            if !has_box(b) || b.intersection(cell).is_empty() {
                error = Some(KdTreeError::StrayReference { node: index, prim, prim_box: *b, cell: *cell });
                return;
            }
            referenced[prim as usize] = true;
        }
    });
    if let Some(e) = error {
        return Err(e);
    }
    if let Some((node, &times)) = reached.iter().enumerate().find(|&(_, &t)| t != 1) {
        return Err(KdTreeError::Reached { node, times });
    }
    if let Some(prim) = (0..prim_boxes.len()).find(|&p| has_box(&prim_boxes[p]) && !referenced[p]) {
        return Err(KdTreeError::Unreferenced { prim });
    }
    if depth != tree.depth() || depth > MAX_DEPTH {
        return Err(KdTreeError::WrongDepth { recorded: tree.depth(), actual: depth });
    }
    let leaves = tree.leaf_count();
    Ok(KdTreeQuality {
        interior: nodes.len() - leaves,
        leaves,
        empty_leaves,
        depth,
        prim_refs,
        refs_per_prim: if with_box == 0 { 0.0 } else { prim_refs as f64 / with_box as f64 },
        max_leaf,
        sah_cost: tree.sah_cost(),
    })
}

impl Validate for KdTree {
    fn validate(&self, prim_boxes: &[Aabb], _clip: Option<ClipFn<'_>>) -> Result<StructureStats, InvalidStructure> {
        validate_kdtree(self, prim_boxes).map_err(|e| InvalidStructure::new("kd-tree", e))?;
        Ok(self.structure_stats())
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn scattered(n: usize) -> Vec<Aabb> {
        (0..n)
            .map(|i| {
                let c = Vec3::new((i * 7 % 13) as f32, (i * 5 % 11) as f32, (i * 3 % 7) as f32);
                Aabb::new(c, c + Vec3::splat(0.8 + (i % 3) as f32))
            })
            .collect()
    }

    #[test]
    fn built_trees_are_valid() {
        for n in [0, 1, 2, 5, 40, 300] {
            let boxes = scattered(n);
            let tree = KdTree::build(&boxes);
            let q = validate_kdtree(&tree, &boxes).unwrap_or_else(|e| panic!("n = {n}: {e}"));
            assert_eq!(q.prim_refs, tree.prim_refs());
            if n > 0 {
                assert!(q.refs_per_prim >= 1.0);
                let s = tree.structure_stats();
                assert_eq!((s.nodes, s.leaves, s.depth), (q.interior, q.leaves, q.depth as usize));
                assert!(s.sah_cost.unwrap() > 0.0 && s.memory_bytes > 8 * tree.nodes().len());
            }
        }
    }

    #[test]
    fn the_sah_cost_of_one_split() {
        // Two unit cubes 2 apart: one plane between them (or two cutting off the gap).
        let boxes = [Aabb::new(Vec3::ZERO, Vec3::ONE), Aabb::new(Vec3::new(3.0, 0.0, 0.0), Vec3::new(4.0, 1.0, 1.0))];
        let tree = KdTree::build(&boxes);
        validate_kdtree(&tree, &boxes).unwrap();
        assert_eq!(tree.prim_refs(), 2);
        // Root 4x1x1, area 18; whatever the planes, the two leaves holding a cube have area 6.
        let leaf_part = 12.0 / 18.0;
        let at_least = SAH_TRAVERSAL_COST + SAH_INTERSECTION_COST * leaf_part;
        assert!(tree.sah_cost() >= at_least - 1e-6, "{} < {at_least}", tree.sah_cost());
    }

    #[test]
    fn broken_trees_are_caught() {
        let boxes = scattered(60);
        let tree = KdTree::build(&boxes);
        // A primitive the tree was not built over.
        let mut fewer = boxes.clone();
        fewer.pop();
        assert!(validate_kdtree(&tree, &fewer).is_err());
        // A primitive's box moved away from the cells that reference it.
        let mut moved = boxes.clone();
        moved[3] = Aabb::new(Vec3::splat(500.0), Vec3::splat(501.0));
        assert!(matches!(validate_kdtree(&tree, &moved), Err(KdTreeError::StrayReference { prim: 3, .. })));
        // A bad child index.
        let mut bad = tree.clone();
        let i = bad.nodes.iter().position(|n| !n.is_leaf()).unwrap();
        bad.nodes[i] = super::super::KdNode::interior(0, 1.0, 0);
        assert!(matches!(validate_kdtree(&bad, &boxes), Err(KdTreeError::BadChild { .. })));
        // A wrong depth.
        let mut deep = tree.clone();
        deep.depth += 1;
        assert!(matches!(validate_kdtree(&deep, &boxes), Err(KdTreeError::WrongDepth { .. })));
        // An unreferenced primitive.
        let mut extra = boxes.clone();
        extra.push(Aabb::new(Vec3::ZERO, Vec3::ONE));
        let mut short = tree.clone();
        short.prim_count += 1;
        assert!(matches!(validate_kdtree(&short, &extra), Err(KdTreeError::Unreferenced { prim: 60 })));
    }
}
