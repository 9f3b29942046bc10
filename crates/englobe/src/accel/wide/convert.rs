//! From a binary tree (the canonical [`crate::accel::bvh::Bvh`], or a builder's tree) to wide nodes.
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
//! The binary tree is read through [`BinaryTree`] (the laid-out `Bvh` of any builder, or the
//! top-down builders' `BuildTree` as it comes out of the build). A large tree's subtrees are
//! converted in parallel (see [`convert`]).

pub use super::binary::BinaryTree;
use super::node::{LEAF, MAX_LEAF_ITEMS, WIDTH, WideNode};
pub use super::output::{LeafSink, WideLayout};
use super::pieces::{Pieces, Store};
use crate::Aabb;
use crate::accel::bvh::build::parallel::collect_indexed;

/// How binary nodes become wide nodes and leaves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ConvertOptions {
    /// Binary subtrees over at most this many primitives become one leaf (0 keeps the binary
    /// tree's leaves as they are).
    pub collapse: usize,
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

/// Subtrees over at least this many primitives convert their children's subtrees in parallel.
pub(super) const PARALLEL_MIN: u32 = 1 << 14;

/// Wide levels below which subtrees are converted in parallel (up to 8^4 subtrees: plenty of work
/// for every core).
pub(super) const PARALLEL_LEVELS: u32 = 4;

/// Converts `tree` into wide nodes, its leaves stored through `sink`.
///
/// A large tree is converted in parallel, subtree by subtree (`Walker::convert`). The tree is the
/// one a single walk makes; only the order in which nodes and items are stored differs (each large
/// subtree's together).
pub fn convert<T, S>(tree: &T, options: ConvertOptions, sink: &mut S) -> WideLayout
where
    T: BinaryTree + Sync,
    S: LeafSink + Send + Sync,
{
    let Some(root) = tree.root() else {
        return WideLayout::default();
    };
    Walker::new(tree, options, sink.max_prims()).convert(Part::Node(root), sink, PARALLEL_LEVELS)
}

/// The conversion's view of a binary tree: its primitive counts and leaf limits.
struct Walker<'a, T> {
    tree: &'a T,
    /// Primitives under each binary node, counted first if the tree does not record them (empty
    /// if it does).
    counted: Vec<u32>,
    /// Most primitives per leaf.
    max_prims: usize,
    /// Subtrees over at most this many primitives become one leaf.
    limit: usize,
}

impl<'a, T: BinaryTree> Walker<'a, T> {
    fn new(tree: &'a T, options: ConvertOptions, max_prims: usize) -> Self {
        let max_prims = max_prims.clamp(1, MAX_LEAF_ITEMS);
        let limit = options.collapse.min(max_prims);
        if tree.root().is_some_and(|root| tree.prims_under(root).is_some()) {
            return Walker { tree, counted: Vec::new(), max_prims, limit };
        }
        // Primitives under each node: the nodes in depth-first order, then counted from the last
        // (every node's children come after it in that order). A walk of the whole tree that
        // misses the caches at nearly every node, which is why trees record their counts.
        let mut order = Vec::with_capacity(tree.slots());
        let mut stack: Vec<u32> = tree.root().into_iter().collect();
        while let Some(i) = stack.pop() {
            order.push(i);
            if let Some([first, second]) = tree.children(i) {
                stack.push(second);
                stack.push(first);
            }
        }
        let mut counted = vec![0u32; tree.slots()];
        for &i in order.iter().rev() {
            counted[i as usize] = match tree.children(i) {
                Some([first, second]) => counted[first as usize] + counted[second as usize],
                None => tree.leaf_range(i).len() as u32,
            };
        }
        Walker { tree, counted, max_prims, limit }
    }

    /// Primitives under binary node `i`.
    fn count(&self, i: u32) -> u32 {
        match self.tree.prims_under(i) {
            Some(n) => n,
            None => self.counted[i as usize],
        }
    }

    fn bounds_of(&self, p: &Part) -> Aabb {
        match *p {
            Part::Node(i) => self.tree.bounds(i),
            Part::Range { bounds, .. } => bounds,
        }
    }

    fn prims_in(&self, p: &Part) -> u32 {
        match *p {
            Part::Node(i) => self.count(i),
            Part::Range { len, .. } => len,
        }
    }

    /// Whether a part is a leaf (it holds few enough primitives) rather than an interior node.
    fn terminal(&self, p: &Part) -> bool {
        match *p {
            Part::Node(i) => {
                let n = self.count(i) as usize;
                (self.tree.children(i).is_none() && n <= self.max_prims) || n <= self.limit
            }
            Part::Range { len, .. } => len as usize <= self.max_prims,
        }
    }

    /// A part's two halves: a node's children, or a leaf's primitives cut in two.
    fn open(&self, p: &Part) -> [Part; 2] {
        match *p {
            Part::Node(i) => match self.tree.children(i) {
                Some([first, second]) => {
                    debug_assert_eq!(self.count(i), self.count(first) + self.count(second), "node {i}'s count");
                    [Part::Node(first), Part::Node(second)]
                }
                None => {
                    let r = self.tree.leaf_range(i);
                    let half = (r.len() / 2) as u32;
                    let (start, len, bounds) = (r.start as u32, r.len() as u32, self.tree.bounds(i));
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
    }

    /// The children of the wide node standing for `part`: its halves, the widest non-leaf one
    /// opened in turn until eight slots are used or only leaves are left.
    fn fill_slots(&self, part: Part, slots: &mut Vec<Part>) {
        greedy_slots(
            part,
            slots,
            |p| self.terminal(p),
            |p| (self.bounds_of(p).surface_area(), self.prims_in(p)),
            |p| self.open(p),
        );
    }

    /// The wide node standing for `part`: its leaf children stored through `sink`, its interior
    /// children given the references `interior(slot, part)` returns.
    fn node(
        &self,
        part: Part,
        sink: &mut impl LeafSink,
        scratch: &mut Scratch,
        mut interior: impl FnMut(usize, Part) -> u32,
    ) -> WideNode {
        self.fill_slots(part, &mut scratch.slots);
        let mut node = WideNode::EMPTY_NODE;
        for (slot, p) in scratch.slots.iter().enumerate() {
            let bounds = self.bounds_of(p);
            if self.terminal(p) {
                scratch.prims.clear();
                gather(self.tree, p, &mut scratch.prims, &mut scratch.pending);
                let (first, items) = sink.leaf(&scratch.prims);
                node.set_child(slot, &bounds, LEAF | first, items);
            } else {
                node.set_child(slot, &bounds, interior(slot, *p), 0);
            }
        }
        node
    }

    /// The wide subtree standing for `part` (its root is node 0), its leaves stored through
    /// `sink`. A part over [`PARALLEL_MIN`] primitives or more has its node made first; the
    /// subtrees of its interior children are then converted in parallel, each the same way into
    /// nodes and items of its own, and appended in slot order (their references moved past the
    /// nodes and items before them), down to `levels` wide levels. Recursing, rather than
    /// splitting at the root alone, keeps the cores busy when the root's subtrees are uneven; the
    /// bound keeps a degenerate tree (a chain as deep as it has primitives) off the call stack.
    fn convert<S: LeafSink + Send + Sync>(&self, part: Part, sink: &mut S, levels: u32) -> WideLayout
    where
        T: Sync,
    {
        if levels == 0 || self.prims_in(&part) < PARALLEL_MIN {
            return self.walk(part, sink);
        }
        let store = Store::for_prims(self.prims_in(&part) as usize);
        self.pieces(part, &*sink, &store, levels).assemble(store, sink)
    }

    /// [`Walker::convert`]'s subtree as pieces, each with leaf items of its own (made by
    /// `template`'s [`LeafSink::split`]), their nodes and items kept in `store` until they are
    /// stored together at the end.
    fn pieces<S: LeafSink + Send + Sync>(&self, part: Part, template: &S, store: &Store<S>, levels: u32) -> Pieces<S>
    where
        T: Sync,
    {
        let mut items = template.split();
        if levels == 0 || self.prims_in(&part) < PARALLEL_MIN {
            let layout = self.walk(part, &mut items);
            return Pieces::walked(layout, items, store);
        }
        let mut scratch = Scratch::default();
        // The interior children are placed once their subtrees are converted.
        let mut subtrees = Vec::new();
        let node = self.node(part, &mut items, &mut scratch, |slot, p| {
            subtrees.push((slot, p));
            0
        });
        let converted = collect_indexed(subtrees.len(), 1, |i| {
            (subtrees[i].0, self.pieces(subtrees[i].1, template, store, levels - 1))
        });
        Pieces::joined(node, items, converted)
    }

    /// The wide subtree standing for `part` (its root is node 0), in one walk.
    fn walk(&self, part: Part, sink: &mut impl LeafSink) -> WideLayout {
        let mut scratch = Scratch::default();
        walk_stack(part, |p, interior| self.node(p, sink, &mut scratch, interior))
    }
}

/// The children of a wide node standing for `part`, in `slots`: `part` itself if it is
/// `terminal`, else its two halves (`open`), the widest one that is not terminal opened in turn
/// until eight slots are used or only terminal parts are left. `size` gives a part's surface
/// area and primitives: of equal boxes (pieces of one large leaf) the one with the most
/// primitives is opened, which keeps the pieces balanced instead of peeling them off one by one.
pub(super) fn greedy_slots<P>(
    part: P,
    slots: &mut Vec<P>,
    terminal: impl Fn(&P) -> bool,
    size: impl Fn(&P) -> (f32, u32),
    mut open: impl FnMut(&P) -> [P; 2],
) {
    slots.clear();
    if terminal(&part) {
        slots.push(part);
    } else {
        slots.extend(open(&part));
    }
    while slots.len() < WIDTH {
        let widest = slots
            .iter()
            .enumerate()
            .filter(|(_, p)| !terminal(p))
            .max_by(|(_, a), (_, b)| {
                let ((area_a, n_a), (area_b, n_b)) = (size(a), size(b));
                area_a.total_cmp(&area_b).then(n_a.cmp(&n_b))
            })
            .map(|(i, _)| i);
        let Some(i) = widest else { break };
        let [first, second] = open(&slots[i]);
        slots[i] = first;
        slots.insert(i + 1, second);
    }
}

/// The wide subtree standing for `part` (its root is node 0), from an explicit work stack (any
/// depth): `node(part, interior)` makes the wide node standing for a part, giving each interior
/// child the index `interior(slot, child)` returns; the children are made after, last slot
/// first.
pub(super) fn walk_stack<P>(
    part: P,
    mut node: impl FnMut(P, &mut dyn FnMut(usize, P) -> u32) -> WideNode,
) -> WideLayout {
    let mut nodes = vec![WideNode::EMPTY_NODE];
    let mut depth = 1;
    // (wide node to fill, the part it stands for, its level from 1)
    let mut stack: Vec<(usize, P, u32)> = vec![(0, part, 1)];
    while let Some((here, part, level)) = stack.pop() {
        depth = depth.max(level);
        nodes[here] = node(part, &mut |_, p| {
            let child = nodes.len();
            nodes.push(WideNode::EMPTY_NODE);
            stack.push((child, p, level + 1));
            child as u32
        });
    }
    WideLayout { nodes, depth }
}

/// Working lists kept from node to node (a build converts tens of thousands of nodes).
#[derive(Default)]
struct Scratch {
    slots: Vec<Part>,
    prims: Vec<u32>,
    pending: Vec<u32>,
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
pub(super) mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::bvh::{BinnedSah, BuildKind, BuildNode, BuildTree, Bvh};
    use crate::accel::wide::node::{EMPTY, index_of, is_leaf};
    use crate::accel::wide::output::tests::Refs;

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
            nodes.push(BuildNode { bounds: all, kind: BuildKind::Interior { children: [i, next], count: n - i } });
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

    /// Each leaf's primitives, sorted, from the root down in slot order: the tree's shape,
    /// whatever order its nodes and items are stored in.
    fn shape(layout: &WideLayout, refs: &[u32]) -> Vec<Vec<u32>> {
        let mut leaves = Vec::new();
        let mut stack = vec![0u32];
        while let Some(i) = stack.pop() {
            let node = &layout.nodes[i as usize];
            for slot in (0..WIDTH).rev().filter(|&s| node.children[s] != EMPTY) {
                let c = node.children[slot];
                if is_leaf(c) {
                    let first = index_of(c) as usize;
                    let mut prims = refs[first..first + node.counts[slot] as usize].to_vec();
                    prims.sort_unstable();
                    leaves.push(prims);
                } else {
                    stack.push(c);
                }
            }
        }
        leaves
    }

    #[test]
    fn large_trees_convert_their_subtrees_in_parallel_into_the_same_tree() {
        // The root has at most eight children, so one of them is over `n / 8`, above
        // `PARALLEL_MIN`: its own subtrees are converted in parallel too.
        let n = 10 * PARALLEL_MIN as usize;
        let boxes = grid(n);
        let tree = BinnedSah::default().build_tree(&boxes);
        for collapse in [0, 4] {
            let options = ConvertOptions { collapse };
            let walker = Walker::new(&tree, options, 8);
            let mut slots = Vec::new();
            walker.fill_slots(Part::Node(tree.root), &mut slots);
            assert!(slots.iter().any(|p| !walker.terminal(p) && walker.prims_in(p) >= PARALLEL_MIN));
            let mut sink = Refs { max: 8, refs: Vec::new() };
            let layout = convert(&tree, options, &mut sink);
            assert_eq!(check(&layout, &sink.refs, &boxes), layout.depth);
            // One walk over the whole tree: the same nodes, depth and leaves.
            let mut alone = Refs { max: 8, refs: Vec::new() };
            let walked = walker.walk(Part::Node(tree.root), &mut alone);
            assert_eq!((layout.nodes.len(), layout.depth), (walked.nodes.len(), walked.depth));
            assert_eq!(shape(&layout, &sink.refs), shape(&walked, &alone.refs));
            assert!(layout.nodes[0].children.iter().filter(|&&c| c != EMPTY && !is_leaf(c)).count() > 1);
            // Parents before children, as the refit's single reverse pass needs.
            for (i, node) in layout.nodes.iter().enumerate() {
                assert!(node.children.iter().all(|&c| c == EMPTY || is_leaf(c) || c as usize > i), "node {i}");
            }
        }
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
