//! From the canonical binary [`Bvh`] to wide nodes.
//!
//! Each wide node takes the place of a binary node and of as many of its descendants as fit in
//! eight slots: starting from the node's two children, the child with the largest surface area is
//! repeatedly replaced by its own two children, until eight slots are used or only leaves are
//! left. Pulling up the largest boxes first is what keeps the expected number of nodes a ray
//! visits low (the surface area heuristic): it is the greedy collapse of Wald, Benthin and Boulos
//! (2008), "Getting Rid of Packets", as tinybvh's `BVH8_CPU::ConvertFrom` and Embree's wide
//! builders do it (Embree opens the largest child of a node's split candidates the same way).
//!
//! Leaves: a binary subtree over at most [`ConvertOptions::collapse`] primitives becomes one leaf
//! (triangle leaves are tested several triangles at once, so a leaf of four costs about what a
//! leaf of one does), and a binary leaf over more primitives than one leaf reference can hold is
//! split into several. What a leaf stores is up to the caller ([`LeafSink`]): primitive references
//! for the general structure, blocks of triangles for the triangle one.
//!
//! The walk uses an explicit stack (degenerate trees as deep as they have primitives are fine), and
//! the interior children of a node are stored next to one another, in slot order.
//!
//! The binary tree is read through [`BinaryTree`]: the laid-out [`Bvh`] of any builder, or the
//! top-down builders' [`BuildTree`] as it comes out of the build, which spares the triangle
//! structure the layout pass (and its per-node child ordering) that only the binary traversal
//! needs.

use super::node::{LEAF, MAX_LEAF_ITEMS, WIDTH, WideNode};
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
            BuildKind::Interior { children } => Some(children),
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
}

/// Where the leaves of a conversion go.
pub trait LeafSink {
    /// Most primitives one leaf may hold (at least 1); its items must then number at most
    /// [`MAX_LEAF_ITEMS`].
    fn max_prims(&self) -> usize;
    /// Stores a leaf over the primitives `prims` (at most [`LeafSink::max_prims`]); returns the
    /// index of its first item and its number of items.
    fn leaf(&mut self, prims: &[u32]) -> (u32, u8);
}

/// How binary nodes become wide nodes and leaves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ConvertOptions {
    /// Binary subtrees over at most this many primitives become one leaf (0 keeps the binary
    /// tree's leaves as they are).
    pub collapse: usize,
}

/// Wide nodes (the root is node 0; none for an empty tree) and the depth: wide nodes on the
/// longest path from the root (0 for an empty tree).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WideLayout {
    /// The nodes.
    pub nodes: Vec<WideNode>,
    /// Wide nodes on the longest path from the root to a leaf.
    pub depth: u32,
}

/// A child being placed: a binary node, or a piece of a binary leaf too large for one reference.
#[derive(Clone, Copy, Debug)]
enum Part {
    Node(u32),
    /// `prim_indices[start..start + len]`, inside a leaf with box `bounds`.
    Range {
        start: u32,
        len: u32,
        bounds: Aabb,
    },
}

/// Converts `tree` into wide nodes, its leaves stored through `sink`.
pub fn convert(tree: &impl BinaryTree, options: ConvertOptions, sink: &mut impl LeafSink) -> WideLayout {
    let Some(root) = tree.root() else {
        return WideLayout::default();
    };
    let max_prims = sink.max_prims().clamp(1, MAX_LEAF_ITEMS);
    // Primitives under each node: the nodes in depth-first order, then counted from the last
    // (every node's children come after it in that order).
    let mut order = Vec::with_capacity(tree.slots());
    let mut stack = vec![root];
    while let Some(i) = stack.pop() {
        order.push(i);
        if let Some([first, second]) = tree.children(i) {
            stack.push(second);
            stack.push(first);
        }
    }
    let mut count = vec![0u32; tree.slots()];
    for &i in order.iter().rev() {
        count[i as usize] = match tree.children(i) {
            Some([first, second]) => count[first as usize] + count[second as usize],
            None => tree.leaf_range(i).len() as u32,
        };
    }
    drop(order);
    let limit = options.collapse.min(max_prims);
    let bounds_of = |p: &Part| match *p {
        Part::Node(i) => tree.bounds(i),
        Part::Range { bounds, .. } => bounds,
    };
    let prims_in = |p: &Part| match *p {
        Part::Node(i) => count[i as usize],
        Part::Range { len, .. } => len,
    };
    // A part is a leaf if it holds few enough primitives, an interior node otherwise.
    let terminal = |p: &Part| match *p {
        Part::Node(i) => {
            (tree.children(i).is_none() && count[i as usize] as usize <= max_prims)
                || count[i as usize] as usize <= limit
        }
        Part::Range { len, .. } => len as usize <= max_prims,
    };
    let open = |p: &Part| -> [Part; 2] {
        match *p {
            Part::Node(i) => match tree.children(i) {
                Some([first, second]) => [Part::Node(first), Part::Node(second)],
                None => {
                    let r = tree.leaf_range(i);
                    let half = (r.len() / 2) as u32;
                    let (start, len, bounds) = (r.start as u32, r.len() as u32, tree.bounds(i));
                    [
                        Part::Range { start, len: half, bounds },
                        Part::Range { start: start + half, len: len - half, bounds },
                    ]
                }
            },
            Part::Range { start, len, bounds } => {
                let half = len / 2;
                [Part::Range { start, len: half, bounds }, Part::Range { start: start + half, len: len - half, bounds }]
            }
        }
    };

    let mut nodes = vec![WideNode::EMPTY_NODE];
    let mut depth = 1;
    // Working lists kept from node to node (a build converts tens of thousands of nodes).
    let (mut prims, mut pending) = (Vec::new(), Vec::new());
    let mut slots: Vec<Part> = Vec::with_capacity(WIDTH);
    // (wide node to fill, the part it stands for, its level from 1)
    let mut stack: Vec<(usize, Part, u32)> = vec![(0, Part::Node(root), 1)];
    while let Some((here, part, level)) = stack.pop() {
        depth = depth.max(level);
        slots.clear();
        if terminal(&part) {
            slots.push(part);
        } else {
            slots.extend(open(&part));
        }
        while slots.len() < WIDTH {
            // Of equal boxes (pieces of one large leaf), the one with the most primitives: halving
            // the largest keeps the pieces balanced instead of peeling them off one by one.
            let widest = slots
                .iter()
                .enumerate()
                .filter(|(_, p)| !terminal(p))
                .max_by(|(_, a), (_, b)| {
                    let area = bounds_of(a).surface_area().total_cmp(&bounds_of(b).surface_area());
                    area.then(prims_in(a).cmp(&prims_in(b)))
                })
                .map(|(i, _)| i);
            let Some(i) = widest else { break };
            let [first, second] = open(&slots[i]);
            slots[i] = first;
            slots.insert(i + 1, second);
        }
        let mut node = WideNode::EMPTY_NODE;
        for (slot, p) in slots.iter().enumerate() {
            let bounds = bounds_of(p);
            if terminal(p) {
                prims.clear();
                gather(tree, p, &mut prims, &mut pending);
                let (first, items) = sink.leaf(&prims);
                node.set_child(slot, &bounds, LEAF | first, items);
            } else {
                let child = nodes.len();
                nodes.push(WideNode::EMPTY_NODE);
                node.set_child(slot, &bounds, child as u32, 0);
                stack.push((child, *p, level + 1));
            }
        }
        nodes[here] = node;
    }
    WideLayout { nodes, depth }
}

/// Appends the primitives under `part` to `out`, in the binary tree's leaf order (`stack` is
/// working memory).
fn gather(tree: &impl BinaryTree, part: &Part, out: &mut Vec<u32>, stack: &mut Vec<u32>) {
    match *part {
        Part::Range { start, len, .. } => out.extend_from_slice(&tree.prims()[start as usize..(start + len) as usize]),
        Part::Node(i) => {
            stack.clear();
            stack.push(i);
            while let Some(i) = stack.pop() {
                match tree.children(i) {
                    Some([first, second]) => {
                        stack.push(second);
                        stack.push(first);
                    }
                    None => out.extend_from_slice(&tree.prims()[tree.leaf_range(i)]),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::bvh::{BinnedSah, BuildKind, BuildNode, BuildTree};
    use crate::accel::wide::node::{EMPTY, index_of, is_leaf};

    /// Stores primitive references, at most `max` per leaf.
    struct Refs {
        max: usize,
        refs: Vec<u32>,
    }

    impl LeafSink for Refs {
        fn max_prims(&self) -> usize {
            self.max
        }
        fn leaf(&mut self, prims: &[u32]) -> (u32, u8) {
            let first = self.refs.len() as u32;
            self.refs.extend_from_slice(prims);
            (first, prims.len() as u8)
        }
    }

    /// Every primitive reached once, every child box inside its node's parent slot box, leaves
    /// around their primitives; returns the depth walked.
    fn check(layout: &WideLayout, refs: &[u32], boxes: &[Aabb]) -> u32 {
        let mut seen = vec![0u32; boxes.len()];
        let mut depth = 0;
        let mut stack = vec![(0u32, Aabb::new(Vec3::splat(-1e30), Vec3::splat(1e30)), 1u32)];
        let mut visited = vec![false; layout.nodes.len()];
        while let Some((i, parent, level)) = stack.pop() {
            assert!(!std::mem::replace(&mut visited[i as usize], true), "node {i} reached twice");
            depth = depth.max(level);
            let node = &layout.nodes[i as usize];
            assert!(node.child_count() >= 1);
            for slot in 0..WIDTH {
                let c = node.children[slot];
                if c == EMPTY {
                    continue;
                }
                let b = node.child_bounds(slot);
                assert!(parent.contains_box(&b), "node {i} slot {slot}");
                if is_leaf(c) {
                    let first = index_of(c) as usize;
                    for &p in &refs[first..first + node.counts[slot] as usize] {
                        assert!(b.contains_box(&boxes[p as usize]));
                        seen[p as usize] += 1;
                    }
                } else {
                    stack.push((c, b, level + 1));
                }
            }
        }
        assert!(visited.iter().all(|&v| v), "orphan nodes");
        assert!(seen.iter().all(|&s| s == 1), "every primitive exactly once");
        depth
    }

    fn grid(n: usize) -> Vec<Aabb> {
        (0..n)
            .map(|i| {
                let c = Vec3::new((i % 17) as f32, (i / 17 % 13) as f32, (i / 221) as f32) * 3.0;
                Aabb::new(c, c + Vec3::splat(1.0 + (i % 3) as f32))
            })
            .collect()
    }

    #[test]
    fn every_primitive_is_in_one_leaf_and_boxes_nest() {
        for n in [1usize, 2, 7, 8, 9, 100, 5000] {
            let boxes = grid(n);
            let bvh = BinnedSah::default().build(&boxes);
            for collapse in [0, 4, 8] {
                let mut sink = Refs { max: 8, refs: Vec::new() };
                let layout = convert(&bvh, ConvertOptions { collapse }, &mut sink);
                assert_eq!(check(&layout, &sink.refs, &boxes), layout.depth, "n = {n}");
                // The greedy collapse fills nodes: a node has eight children unless all of them
                // are leaves.
                for (i, node) in layout.nodes.iter().enumerate() {
                    let interior = node.children.iter().any(|&c| c != EMPTY && !is_leaf(c));
                    assert!(!interior || node.child_count() == WIDTH, "n = {n}, collapse {collapse}: node {i}");
                }
            }
        }
    }

    #[test]
    fn large_leaves_are_split_and_chains_need_no_recursion() {
        // One binary leaf of 1000 primitives with a cap of 8 per leaf.
        let boxes = vec![Aabb::new(Vec3::ZERO, Vec3::ONE); 1000];
        let tree = BuildTree {
            nodes: vec![BuildNode { bounds: boxes[0], kind: BuildKind::Leaf { first: 0, count: 1000 } }],
            prims: (0..1000).collect(),
            root: 0,
        };
        let mut sink = Refs { max: 8, refs: Vec::new() };
        let layout = convert(&tree.into_bvh(), ConvertOptions { collapse: 4 }, &mut sink);
        check(&layout, &sink.refs, &boxes);
        assert!(layout.depth <= 4, "{}", layout.depth);

        // A chain 50 000 deep.
        let n = 50_000u32;
        let mut nodes: Vec<BuildNode> = (0..n)
            .map(|i| BuildNode {
                bounds: Aabb::new(Vec3::splat(i as f32), Vec3::splat(i as f32 + 1.0)),
                kind: BuildKind::Leaf { first: i, count: 1 },
            })
            .collect();
        let all = Aabb::new(Vec3::ZERO, Vec3::splat(n as f32));
        for i in 0..n - 1 {
            let next = if i + 1 == n - 1 { n - 1 } else { n + i + 1 };
            nodes.push(BuildNode { bounds: all, kind: BuildKind::Interior { children: [i, next] } });
        }
        let boxes: Vec<Aabb> = nodes[..n as usize].iter().map(|b| b.bounds).collect();
        let tree = BuildTree { nodes, prims: (0..n).collect(), root: n };
        let mut sink = Refs { max: 8, refs: Vec::new() };
        let layout = convert(&tree.clone().into_bvh(), ConvertOptions { collapse: 0 }, &mut sink);
        assert_eq!(check(&layout, &sink.refs, &boxes), layout.depth);
        // The builder's tree read as it is (its children stored before their parents here): the
        // same conversion.
        let mut direct = Refs { max: 8, refs: Vec::new() };
        assert_eq!(convert(&tree, ConvertOptions { collapse: 0 }, &mut direct), layout);
        assert_eq!(direct.refs, sink.refs);
    }

    #[test]
    fn a_build_tree_converts_as_its_layout_does() {
        for n in [1usize, 2, 9, 100, 5000] {
            let boxes = grid(n);
            let tree = BinnedSah::default().build_tree(&boxes);
            for collapse in [0, 4] {
                let (mut laid_out, mut direct) = (Refs { max: 8, refs: Vec::new() }, Refs { max: 8, refs: Vec::new() });
                let expected = convert(&tree.clone().into_bvh(), ConvertOptions { collapse }, &mut laid_out);
                assert_eq!(convert(&tree, ConvertOptions { collapse }, &mut direct), expected, "n = {n}");
                assert_eq!(direct.refs, laid_out.refs, "n = {n}");
            }
        }
        let mut sink = Refs { max: 8, refs: Vec::new() };
        assert_eq!(convert(&BuildTree::default(), ConvertOptions { collapse: 4 }, &mut sink), WideLayout::default());
    }

    #[test]
    fn an_empty_tree_has_no_node() {
        let mut sink = Refs { max: 8, refs: Vec::new() };
        assert_eq!(convert(&Bvh::empty(), ConvertOptions { collapse: 4 }, &mut sink), WideLayout::default());
    }
}
