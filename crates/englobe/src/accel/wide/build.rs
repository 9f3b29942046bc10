//! Wide nodes built straight from the primitives' boxes, top-down, with no binary tree in between.
//!
//! The tree is the one a top-down binary build ([`crate::accel::bvh::build::top_down`]) followed
//! by the greedy conversion ([`super::convert()`]) gives: a wide node is made from a range of
//! references by splitting it with the binary builder's [`Splitter`], then splitting again the
//! part with the largest box, until eight parts or only leaves are left. Each range is split
//! once, when it is made, exactly as the binary build splits it; what is saved is the binary
//! tree itself (two node slots per reference, written and read back from memory once the caches
//! have long lost them) and the conversion's walk over it. Embree builds its eight-wide BVHs this
//! way (Wald, Woop, Benthin, Johnson and Ernst 2014, "Embree: A Kernel Framework for Efficient
//! CPU Ray Tracing": the binned SAH builder's branching factor).
//!
//! The nodes and leaf items come out in the conversion's order too (large subtrees in parallel,
//! appended in slot order: see [`super::convert()`]), so the structure is the same one, node for
//! node, whenever the splitter leaves ranges of at most [`ConvertOptions::collapse`] references
//! alone (a leaf's references may otherwise come in another order).

use super::convert::{
    ConvertOptions, PARALLEL_LEVELS, PARALLEL_MIN as SUBTREES_PARALLEL_MIN, greedy_slots, walk_stack,
};
use super::node::{LEAF, MAX_LEAF_ITEMS, WideNode};
use super::output::{LeafSink, WideLayout};
use super::pieces::{Pieces, Store};
use crate::Aabb;
use crate::accel::bvh::build::parallel::{self, collect_indexed_huge};
use crate::accel::bvh::build::top_down::{PARALLEL_MIN, PrimRef, Splitter, decide, range_bounds};

/// Builds the wide tree over `boxes` (primitive `i` has box `boxes[i]`), splitting ranges with
/// `splitter` and storing leaves through `sink`; returns the nodes and the box around everything.
pub fn build_wide<S, K>(splitter: &S, boxes: &[Aabb], options: ConvertOptions, sink: &mut K) -> (WideLayout, Aabb)
where
    S: Splitter,
    K: LeafSink + Send + Sync,
{
    let refs = collect_indexed_huge(boxes.len(), 1 << 14, |i| PrimRef::new(&boxes[i], i as u32));
    build_wide_refs(splitter, refs, options, sink)
}

/// [`build_wide`] over references the caller made (primitive `r.index()` has box `r.bounds()`):
/// the builder reorders them in place.
pub fn build_wide_refs<S, K>(
    splitter: &S,
    mut refs: Vec<PrimRef>,
    options: ConvertOptions,
    sink: &mut K,
) -> (WideLayout, Aabb)
where
    S: Splitter,
    K: LeafSink + Send + Sync,
{
    if refs.is_empty() {
        return (WideLayout::default(), Aabb::EMPTY);
    }
    let max_prims = sink.max_prims().clamp(1, MAX_LEAF_ITEMS);
    let builder = Builder { splitter, max_prims, limit: options.collapse.min(max_prims) };
    let root = builder.part(&mut refs, 0, &mut S::Scratch::default());
    (builder.build(&mut refs, 0, root, sink, PARALLEL_LEVELS), root.bounds)
}

/// A range of references on its way into a wide node.
#[derive(Clone, Copy, Debug)]
struct Part {
    /// The range, in the whole list of references.
    start: u32,
    end: u32,
    /// The box around the range's references (for a piece: around the whole leaf's).
    bounds: Aabb,
    kind: Kind,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    /// The splitter cut the range at `mid` (in the whole list; its references are reordered).
    Split(u32),
    /// The splitter made it a leaf.
    Leaf,
    /// A piece of a leaf too large for one wide leaf, cut in two by count.
    Piece,
}

impl Part {
    fn len(&self) -> usize {
        (self.end - self.start) as usize
    }
}

struct Builder<'a, S> {
    splitter: &'a S,
    /// Most references per leaf.
    max_prims: usize,
    /// Ranges of at most this many references become one leaf.
    limit: usize,
}

impl<S: Splitter> Builder<'_, S> {
    /// The part over `refs` (which start at `start` in the whole list): bounded, and split if
    /// it is not small enough to be a leaf anyway.
    fn part(&self, refs: &mut [PrimRef], start: u32, scratch: &mut S::Scratch) -> Part {
        let (bounds, centroid_bounds) = range_bounds(refs);
        let end = start + refs.len() as u32;
        let kind = if refs.len() <= self.limit {
            Kind::Leaf
        } else {
            match decide(self.splitter, refs, &bounds, &centroid_bounds, scratch) {
                Some(mid) => Kind::Split(start + mid as u32),
                None => Kind::Leaf,
            }
        };
        Part { start, end, bounds, kind }
    }

    /// Whether a part is a leaf of the wide tree rather than an interior node: a range the
    /// splitter cut never is (ranges of at most `limit` references are never cut, see
    /// [`Builder::part`]); a leaf or a piece is, if one wide leaf holds it.
    fn terminal(&self, p: &Part) -> bool {
        match p.kind {
            Kind::Split(_) => false,
            Kind::Leaf | Kind::Piece => p.len() <= self.max_prims,
        }
    }

    /// A part's two halves: where the splitter cut it, or by count for a leaf too large.
    /// `refs` starts at `base` in the whole list.
    fn open(&self, refs: &mut [PrimRef], base: u32, p: &Part, scratch: &mut S::Scratch) -> [Part; 2] {
        match p.kind {
            Kind::Split(mid) => {
                let range = &mut refs[(p.start - base) as usize..(p.end - base) as usize];
                let (left, right) = range.split_at_mut((mid - p.start) as usize);
                // Halves as large as the binary build's parallel subtrees are made in parallel too.
                if left.len().min(right.len()) >= PARALLEL_MIN {
                    let (a, b) = parallel::join(
                        || self.part(left, p.start, &mut S::Scratch::default()),
                        || self.part(right, mid, &mut S::Scratch::default()),
                    );
                    [a, b]
                } else {
                    [self.part(left, p.start, scratch), self.part(right, mid, scratch)]
                }
            }
            Kind::Leaf | Kind::Piece => {
                let mid = p.start + (p.len() / 2) as u32;
                [
                    Part { start: p.start, end: mid, bounds: p.bounds, kind: Kind::Piece },
                    Part { start: mid, end: p.end, bounds: p.bounds, kind: Kind::Piece },
                ]
            }
        }
    }

    /// The children of the wide node standing for `part`: its halves, the widest non-leaf one
    /// opened in turn until eight slots are used or only leaves are left (the conversion's
    /// `fill_slots`, choice for choice).
    fn fill_slots(&self, refs: &mut [PrimRef], base: u32, part: Part, slots: &mut Vec<Part>, scratch: &mut S::Scratch) {
        greedy_slots(
            part,
            slots,
            |p| self.terminal(p),
            |p| (p.bounds.surface_area(), p.len() as u32),
            |p| self.open(refs, base, p, scratch),
        );
    }

    /// The wide node standing for `part`: its leaf children stored through `sink`, its interior
    /// children given the references `interior(slot, part)` returns.
    fn node(
        &self,
        refs: &mut [PrimRef],
        base: u32,
        part: Part,
        sink: &mut impl LeafSink,
        scratch: &mut Scratch<S>,
        mut interior: impl FnMut(usize, Part) -> u32,
    ) -> WideNode {
        self.fill_slots(refs, base, part, &mut scratch.slots, &mut scratch.splitter);
        let mut node = WideNode::EMPTY_NODE;
        for (slot, p) in scratch.slots.iter().enumerate() {
            if self.terminal(p) {
                let range = &refs[(p.start - base) as usize..(p.end - base) as usize];
                scratch.prims.clear();
                scratch.prims.extend(range.iter().map(PrimRef::index));
                let (first, items) = sink.leaf(&scratch.prims);
                node.set_child(slot, &p.bounds, LEAF | first, items);
            } else {
                node.set_child(slot, &p.bounds, interior(slot, *p), 0);
            }
        }
        node
    }

    /// The wide subtree standing for `part` (its root is node 0), over `refs` (which start at
    /// `base` in the whole list). A part over `SUBTREES_PARALLEL_MIN` references or more has its
    /// node made first, then its interior children's subtrees built in parallel and appended in
    /// slot order, down to `levels` wide levels, as the conversion does.
    fn build<K: LeafSink + Send + Sync>(
        &self,
        refs: &mut [PrimRef],
        base: u32,
        part: Part,
        sink: &mut K,
        levels: u32,
    ) -> WideLayout {
        if levels == 0 || (part.len() as u32) < SUBTREES_PARALLEL_MIN {
            return self.walk(refs, base, part, sink);
        }
        let store = Store::for_prims(part.len());
        self.pieces(refs, base, part, &*sink, &store, levels).assemble(store, sink)
    }

    /// [`Builder::build`]'s subtree as pieces, each with leaf items of its own (made by
    /// `template`'s [`LeafSink::split`]), their nodes and items kept in `store` until they are
    /// stored together at the end.
    #[allow(clippy::too_many_arguments)]
    fn pieces<K: LeafSink + Send + Sync>(
        &self,
        refs: &mut [PrimRef],
        base: u32,
        part: Part,
        template: &K,
        store: &Store<K>,
        levels: u32,
    ) -> Pieces<K> {
        let mut items = template.split();
        if levels == 0 || (part.len() as u32) < SUBTREES_PARALLEL_MIN {
            let layout = self.walk(refs, base, part, &mut items);
            return Pieces::walked(layout, items, store);
        }
        let mut scratch = Scratch::default();
        let mut subtrees = Vec::new();
        let node = self.node(refs, base, part, &mut items, &mut scratch, |slot, p| {
            subtrees.push((slot, p));
            0
        });
        // The interior children's ranges, in slot order, are disjoint and in the order of the
        // references: each subtree gets its own.
        let mut jobs = Vec::with_capacity(subtrees.len());
        let (mut rest, mut at) = (refs, base);
        for &(slot, p) in &subtrees {
            let (_, tail) = std::mem::take(&mut rest).split_at_mut((p.start - at) as usize);
            let (mine, tail) = tail.split_at_mut(p.len());
            jobs.push((slot, p, mine));
            (rest, at) = (tail, p.end);
        }
        let built = parallel::map_each(jobs, |(slot, p, mine)| {
            (slot, self.pieces(mine, p.start, p, template, store, levels - 1))
        });
        Pieces::joined(node, items, built)
    }

    /// The wide subtree standing for `part` (its root is node 0), from an explicit work stack.
    fn walk(&self, refs: &mut [PrimRef], base: u32, part: Part, sink: &mut impl LeafSink) -> WideLayout {
        let mut scratch = Scratch::default();
        walk_stack(part, |p, interior| self.node(refs, base, p, sink, &mut scratch, interior))
    }
}

/// Working memory kept from node to node.
struct Scratch<S: Splitter> {
    slots: Vec<Part>,
    prims: Vec<u32>,
    splitter: S::Scratch,
}

impl<S: Splitter> Default for Scratch<S> {
    fn default() -> Self {
        Scratch { slots: Vec::new(), prims: Vec::new(), splitter: S::Scratch::default() }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::bvh::BinnedSah;
    use crate::accel::wide::binary::BinaryTree;
    use crate::accel::wide::convert::convert;
    use crate::accel::wide::node::{EMPTY, WIDTH, index_of, is_leaf};
    use crate::accel::wide::output::tests::Refs;

    /// Boxes of assorted sizes, scattered by a hash (and a few identical ones).
    fn scattered(n: usize) -> Vec<Aabb> {
        (0..n as u32)
            .map(|i| {
                let h = |k: u32| (i.wrapping_mul(2_654_435_761).wrapping_add(k.wrapping_mul(40_503)) >> 8) as f32;
                let c = Vec3::new(h(1) % 1000.0, h(2) % 300.0, h(3) % 50.0);
                let size = if i % 97 == 0 { 200.0 } else { 1.0 + h(4) % 5.0 };
                if i % 13 == 0 { Aabb::new(Vec3::ZERO, Vec3::ONE) } else { Aabb::new(c, c + Vec3::splat(size)) }
            })
            .collect()
    }

    /// Each leaf's references sorted (the order a splitter leaves inside a leaf aside).
    fn sorted_leaves(layout: &WideLayout, refs: &[u32]) -> Vec<u32> {
        let mut out = refs.to_vec();
        for node in &layout.nodes {
            for slot in (0..WIDTH).filter(|&s| node.children[s] != EMPTY && is_leaf(node.children[s])) {
                let first = index_of(node.children[slot]) as usize;
                out[first..first + node.counts[slot] as usize].sort_unstable();
            }
        }
        out
    }

    /// Builds both ways; the same nodes and depth, and the same references (in the same order
    /// when `same_order`).
    fn agree(builder: &BinnedSah, boxes: &[Aabb], collapse: usize, max: usize, same_order: bool) {
        let options = ConvertOptions { collapse };
        let tree = builder.build_tree(boxes);
        let mut converted = Refs { max, refs: Vec::new() };
        let expected = convert(&tree, options, &mut converted);
        let mut direct = Refs { max, refs: Vec::new() };
        let (layout, bounds) = build_wide(builder, boxes, options, &mut direct);
        let what = format!("{} boxes, collapse {collapse}, {max} per leaf", boxes.len());
        assert_eq!(layout, expected, "{what}");
        assert_eq!(bounds, tree.root().map_or(Aabb::EMPTY, |r| tree.bounds(r)), "{what}");
        if same_order {
            assert_eq!(direct.refs, converted.refs, "{what}");
        } else {
            assert_eq!(sorted_leaves(&layout, &direct.refs), sorted_leaves(&expected, &converted.refs), "{what}");
        }
    }

    #[test]
    fn the_tree_is_the_binary_build_converted() {
        let triangles = BinnedSah { small_leaf: 4, block: 4, parallel_partition: true, ..BinnedSah::default() };
        for n in [0usize, 1, 2, 4, 5, 7, 9, 100, 5000, 10 * SUBTREES_PARALLEL_MIN as usize] {
            let boxes = scattered(n);
            for max in [8, 16] {
                agree(&triangles, &boxes, 4, max, true);
            }
            // A splitter that cuts small ranges too: the leaves are the same, the order inside
            // them may not be.
            for collapse in [0, 4] {
                agree(&BinnedSah::default(), &boxes, collapse, 8, collapse == 0);
            }
        }
    }

    #[test]
    fn leaves_too_large_are_cut_by_count() {
        // Nothing separates identical boxes: the splitter makes leaves of up to 30, cut in
        // pieces of at most 8.
        let boxes = vec![Aabb::new(Vec3::ZERO, Vec3::ONE); 1000];
        let builder = BinnedSah { max_leaf: 30, ..BinnedSah::default() };
        agree(&builder, &boxes, 4, 8, true);
        let mut sink = Refs { max: 8, refs: Vec::new() };
        let (layout, _) = build_wide(&builder, &boxes, ConvertOptions { collapse: 4 }, &mut sink);
        let mut seen = sink.refs.clone();
        seen.sort_unstable();
        assert!(seen.iter().copied().eq(0..1000));
        assert!(layout.nodes.iter().all(|n| n.counts.iter().all(|&c| c <= 8)));
    }
}
