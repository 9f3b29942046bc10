//! Top-down construction, shared by the surface area heuristic (SAH) builders: a node over a range
//! of primitive references is either made a leaf or split in two by a [`Splitter`], and its
//! children are built the same way.
//!
//! This is the recursive scheme of Goldsmith and Salmon (1987), "Automatic Creation of Object
//! Hierarchies for Ray Tracing", as pbrt's `BVHAggregate::buildRecursive` runs it (Pharr, Jakob and
//! Humphreys, "Physically Based Rendering", 4th ed. 2023, section 7.3), with two guarantees added:
//!
//! * **No deep recursion.** The top levels, while a subtree is large, run as a bounded recursion
//!   whose two halves are built in parallel (each writes a disjoint part of the arrays); everything
//!   below runs from an explicit work stack. A tree as deep as it has primitives (primitives spaced
//!   geometrically along a line peel off one by one under the SAH) is therefore built without
//!   touching the call stack's limit.
//! * **No giant leaf, no endless split.** A range larger than the maximum leaf size that the
//!   splitter cannot split (all centroids at one point, so no plane separates them) is split in
//!   the middle by count, which bounds the depth of that part by its logarithm.
//!
//! A subtree over `m` references gets exactly `2m - 1` node slots: its root, then the left
//! child's `2 m_left - 1`, then the right child's. Halves can thus be built independently and the
//! tree comes out in depth-first order; slots left over (where a leaf holds several primitives)
//! are never reached from the root and are dropped by the layout.

use glam::{Vec3A, Vec4};

use super::parallel;
use crate::Aabb;
use crate::accel::bvh::layout::{BuildKind, BuildNode, BuildTree};
use crate::accel::bvh::stats::SAH_INTERSECTION_COST;

/// A primitive as the top-down builders move it around: its box and its index, in two aligned
/// four-float vectors (32 bytes, Embree's `PrimRef` layout: the index rides in the fourth lane of
/// the lower corner), so that the builders' passes over millions of them read half a cache line
/// each and bin them with vector operations. Builders reorder these in place; the final order
/// becomes the leaves' primitive references.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct PrimRef {
    /// The box's lower corner; the fourth lane holds the index's bits, bit 30 flipped (see
    /// [`INDEX_BITS`]).
    lo: Vec4,
    /// The box's upper corner; the fourth lane is the caller's (see [`PrimRef::with_spare`]).
    hi: Vec4,
}

/// Flipped in the index's bits before they are stored as a float: the vector operations on a
/// reference's corners also run on the fourth lane, and a small index's bits as they are would
/// be a subnormal number, which x86 processors add and multiply in slow microcode (about a
/// hundred cycles). Flipped, every index below 2^30 is a normal number, an infinity or a NaN.
const INDEX_BITS: u32 = 1 << 30;

impl PrimRef {
    /// The reference of primitive `index`, whose box is `bounds`.
    #[inline]
    pub fn new(bounds: &Aabb, index: u32) -> Self {
        Self::with_spare(bounds, index, 1.0)
    }

    /// The reference of primitive `index` with a number of the caller's about it, `spare`, in
    /// the upper corner's fourth lane, which no builder reads: the triangle build keeps there the
    /// area a triangle's box wastes, which the presplit needs, so that the one pass over the
    /// triangles makes the references, with no second array (hundreds of megabytes on a scene of
    /// millions of triangles).
    #[inline]
    pub fn with_spare(bounds: &Aabb, index: u32, spare: f32) -> Self {
        PrimRef { lo: bounds.min.extend(f32::from_bits(index ^ INDEX_BITS)), hi: bounds.max.extend(spare) }
    }

    /// The number given to [`PrimRef::with_spare`] (1.0 for a reference made by [`PrimRef::new`]).
    #[inline(always)]
    pub fn spare(&self) -> f32 {
        self.hi.w
    }

    /// The box's lower corner.
    #[inline(always)]
    pub fn min(&self) -> Vec3A {
        Vec3A::from_vec4(self.lo)
    }

    /// The box's upper corner.
    #[inline(always)]
    pub fn max(&self) -> Vec3A {
        Vec3A::from_vec4(self.hi)
    }

    /// The primitive's box.
    #[inline(always)]
    pub fn bounds(&self) -> Aabb {
        Aabb::new(self.min().into(), self.max().into())
    }

    /// The box's centre, computed as [`Aabb::center`] computes it.
    #[inline(always)]
    pub fn centroid(&self) -> Vec3A {
        (self.min() + self.max()) * 0.5
    }

    /// The box's centre in the first three lanes (as [`PrimRef::centroid`]); the fourth is
    /// meaningless.
    #[inline(always)]
    pub fn centroid4(&self) -> Vec4 {
        (self.lo + self.hi) * 0.5
    }

    /// Coordinate `axis` of the box's centre (as [`PrimRef::centroid`], one axis).
    #[inline(always)]
    pub fn centroid_on(&self, axis: usize) -> f32 {
        (self.lo[axis] + self.hi[axis]) * 0.5
    }

    /// The primitive's index.
    #[inline(always)]
    pub fn index(&self) -> u32 {
        self.lo.w.to_bits() ^ INDEX_BITS
    }
}

/// Chooses how to split a node (see [`build_tree`]).
pub trait Splitter: Sync {
    /// Working memory kept from node to node by one thread.
    type Scratch: Default + Send;

    /// Most primitives a leaf may hold (at least 1).
    fn max_leaf(&self) -> usize;

    /// For a node over `refs` (at least two), whose primitives' boxes span `bounds` and whose
    /// centroids span `centroid_bounds`: `Some(mid)` after reordering `refs` so that `refs[..mid]`
    /// go to the first child, or `None` to make a leaf. When `must_split` is true (more references
    /// than a leaf may hold) the splitter returns its best split even if a leaf would cost less,
    /// and `None` only if it finds no split at all; the builder then splits by count. A `mid` of
    /// 0 or `refs.len()` counts as `None`.
    fn split(
        &self,
        refs: &mut [PrimRef],
        bounds: &Aabb,
        centroid_bounds: &Aabb,
        must_split: bool,
        scratch: &mut Self::Scratch,
    ) -> Option<usize>;
}

/// Subtrees at least this large are built in parallel (below it a task costs less than spawning).
pub const PARALLEL_MIN: usize = 4096;
/// Levels of the bounded recursion that builds large subtrees in parallel; below it, or below
/// [`PARALLEL_MIN`] references, the explicit work stack takes over.
const PARALLEL_DEPTH: u32 = 40;

/// Ranges of at least this many references are bounded and binned in pieces of [`PIECE`]
/// references, the pieces in parallel, and partitioned in pieces where the splitter asks for it
/// ([`partition_large`]; `BinnedSah::parallel_partition`). Above it the two halves of a node
/// cannot keep the cores busy on their own: the root's passes would run on one core, and so
/// would each node along a chain of uneven splits, whose passes add up to several times the
/// root's.
pub const PIECES_MIN: usize = 1 << 15;
/// References per piece of a large range (see [`PIECES_MIN`]): a fixed size, so that the pieces,
/// and hence the partition's order, never depend on the threads.
pub const PIECE: usize = 1 << 13;

/// Builds the tree over `boxes` (primitive `i` has box `boxes[i]`) with `splitter`.
pub fn build_tree<S: Splitter>(splitter: &S, boxes: &[Aabb]) -> BuildTree {
    let n = boxes.len();
    if n == 0 {
        return BuildTree::default();
    }
    // Both on huge pages: hundreds of megabytes on a large scene, read again at every level, a
    // page fault per 4 KiB otherwise (see `crate::geom::huge_pages`).
    let mut refs = parallel::collect_indexed_huge(n, 1 << 14, |i| PrimRef::new(&boxes[i], i as u32));
    let unused = BuildNode { bounds: Aabb::EMPTY, kind: BuildKind::Leaf { first: 0, count: 0 } };
    let mut nodes = parallel::collect_indexed_huge(2 * n - 1, 1 << 14, |_| unused);
    build_parallel(splitter, &mut nodes, 0, &mut refs, 0, 0);
    let prims = parallel::collect_indexed(n, 1 << 14, |i| refs[i].index());
    BuildTree { nodes, prims, root: 0 }
}

/// The union of the references' boxes and the box around their centroids (in pieces, in
/// parallel, for a large range: see [`PIECES_MIN`]).
pub fn range_bounds(refs: &[PrimRef]) -> (Aabb, Aabb) {
    if refs.len() < PIECES_MIN {
        return piece_bounds(refs);
    }
    let pieces = parallel::map_chunks(refs, PIECE, piece_bounds);
    pieces.into_iter().fold((Aabb::EMPTY, Aabb::EMPTY), |(b, c), (pb, pc)| (b.union(&pb), c.union(&pc)))
}

/// [`range_bounds`] in one pass.
fn piece_bounds(refs: &[PrimRef]) -> (Aabb, Aabb) {
    let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    let (mut c_lo, mut c_hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    for r in refs {
        let c = r.centroid();
        (lo, hi) = (lo.min(r.min()), hi.max(r.max()));
        (c_lo, c_hi) = (c_lo.min(c), c_hi.max(c));
    }
    (Aabb::new(lo.into(), hi.into()), Aabb::new(c_lo.into(), c_hi.into()))
}

/// Where to split `refs`: `Some(mid)` with `0 < mid < len`, or `None` for a leaf.
pub fn decide<S: Splitter>(
    splitter: &S,
    refs: &mut [PrimRef],
    bounds: &Aabb,
    centroid_bounds: &Aabb,
    scratch: &mut S::Scratch,
) -> Option<usize> {
    let n = refs.len();
    if n <= 1 {
        return None;
    }
    let must_split = n > splitter.max_leaf().max(1);
    match splitter.split(refs, bounds, centroid_bounds, must_split, scratch) {
        Some(mid) if mid > 0 && mid < n => Some(mid),
        // Nothing separates the centroids: split by count, which keeps this part's depth
        // logarithmic.
        _ if must_split => Some(n / 2),
        _ => None,
    }
}

/// Builds the subtree over `refs` into `nodes` (its `2 * refs.len() - 1` slots; global index of
/// the first: `node_base`); its references are `ref_base..` of the final order. Large subtrees
/// build their halves in parallel, for at most [`PARALLEL_DEPTH`] levels.
fn build_parallel<S: Splitter>(
    splitter: &S,
    nodes: &mut [BuildNode],
    node_base: u32,
    refs: &mut [PrimRef],
    ref_base: u32,
    level: u32,
) {
    if refs.len() < PARALLEL_MIN || level >= PARALLEL_DEPTH {
        build_sequential(splitter, nodes, node_base, refs, ref_base, &mut S::Scratch::default());
        return;
    }
    let (bounds, centroid_bounds) = range_bounds(refs);
    let mut scratch = S::Scratch::default();
    let Some(mid) = decide(splitter, refs, &bounds, &centroid_bounds, &mut scratch) else {
        nodes[0] = BuildNode { bounds, kind: BuildKind::Leaf { first: ref_base, count: refs.len() as u32 } };
        return;
    };
    drop(scratch);
    let right = node_base + 2 * mid as u32;
    nodes[0] =
        BuildNode { bounds, kind: BuildKind::Interior { children: [node_base + 1, right], count: refs.len() as u32 } };
    let (left_nodes, right_nodes) = nodes[1..].split_at_mut(2 * mid - 1);
    let (left_refs, right_refs) = refs.split_at_mut(mid);
    parallel::join(
        || build_parallel(splitter, left_nodes, node_base + 1, left_refs, ref_base, level + 1),
        || build_parallel(splitter, right_nodes, right, right_refs, ref_base + mid as u32, level + 1),
    );
}

/// Builds the subtree over `refs` into `nodes` (as [`build_parallel`]) from an explicit work
/// stack, whatever its depth.
fn build_sequential<S: Splitter>(
    splitter: &S,
    nodes: &mut [BuildNode],
    node_base: u32,
    refs: &mut [PrimRef],
    ref_base: u32,
    scratch: &mut S::Scratch,
) {
    // (slot in `nodes`, range in `refs`)
    let mut stack: Vec<(usize, usize, usize)> = vec![(0, 0, refs.len())];
    while let Some((slot, start, end)) = stack.pop() {
        let range = &mut refs[start..end];
        let (bounds, centroid_bounds) = range_bounds(range);
        nodes[slot] = match decide(splitter, range, &bounds, &centroid_bounds, scratch) {
            None => BuildNode {
                bounds,
                kind: BuildKind::Leaf { first: ref_base + start as u32, count: (end - start) as u32 },
            },
            Some(mid) => {
                let (left, right) = (slot + 1, slot + 2 * mid);
                stack.push((right, start + mid, end));
                stack.push((left, start, start + mid));
                BuildNode {
                    bounds,
                    kind: BuildKind::Interior {
                        children: [node_base + left as u32, node_base + right as u32],
                        count: (end - start) as u32,
                    },
                }
            }
        };
    }
}

/// Whether splitting a node of surface area `area` over `n` primitives beats making it a leaf,
/// when the children's boxes' areas times their counts add up to `weighted`: a split costs
/// `C_t + C_i * weighted / area`, a leaf `C_i * n`, `n` being the leaf's exact tests, `C_t` being
/// `traversal` (usually [`crate::accel::bvh::SAH_TRAVERSAL_COST`]; see
/// [`super::BinnedSah::traversal_cost`]) and `C_i` [`SAH_INTERSECTION_COST`] (see
/// [`super::BinnedSah::block`] for tests of several primitives). A node without area (all its
/// primitives on one point or segment) gains nothing by a split.
pub fn split_beats_leaf(weighted: f32, area: f32, n: usize, traversal: f32) -> bool {
    area > 0.0 && traversal + SAH_INTERSECTION_COST * weighted / area < SAH_INTERSECTION_COST * n as f32
}

/// Reorders `refs` so that those for which `left` holds come first; returns how many they are.
///
/// Lomuto's scheme without a branch on the outcome (Edelkamp and Weiß (2016), "BlockQuicksort:
/// How Branch Mispredictions don't affect Quicksort", whose analysis this follows; Alexandrescu's
/// "Lomuto's Comeback" gives this loop): every reference is swapped with the first one not chosen,
/// and the boundary advances by the outcome. Which side a reference goes to follows no pattern, so
/// the branches of Hoare's two-pointer scheme would mispredict about once per reference; this
/// loop moves more bytes and mispredicts never. Linear, in place, not stable, deterministic.
pub fn partition(refs: &mut [PrimRef], mut left: impl FnMut(&PrimRef) -> bool) -> usize {
    let mut first = 0;
    for i in 0..refs.len() {
        let r = refs[i];
        let goes_left = left(&r);
        // `refs[first..i]` are all on the right: swapping `r` in at `first` keeps them there,
        // and the boundary moves past `r` if it goes left.
        refs[i] = refs[first];
        refs[first] = r;
        first += goes_left as usize;
    }
    first
}

/// [`partition`] for a range of any size: a large one (see [`PIECES_MIN`]) is partitioned piece by
/// piece, in parallel, and the references left on the wrong side of the boundary are then swapped
/// pairwise, in order.
pub fn partition_large(refs: &mut [PrimRef], left: impl Fn(&PrimRef) -> bool + Sync) -> usize {
    if refs.len() < PIECES_MIN {
        return partition(refs, left);
    }
    let firsts = parallel::map_chunks_mut(refs, PIECE, |piece| partition(piece, &left));
    let mid: usize = firsts.iter().sum();
    // Piece `j` starts at `j * PIECE` with its `firsts[j]` chosen references. The pieces' second
    // sides before `mid` and their first sides from `mid` on hold as many references.
    let (mut early, mut late) = (Vec::new(), Vec::new());
    for (j, &first) in firsts.iter().enumerate() {
        let start = j * PIECE;
        let (split, end) = (start + first, (start + PIECE).min(refs.len()));
        if split < mid {
            early.push(split..end.min(mid));
        }
        if split > mid {
            late.push(start.max(mid)..split);
        }
    }
    for (a, b) in early.into_iter().flatten().zip(late.into_iter().flatten()) {
        refs.swap(a, b);
    }
    mid
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::bvh::validate::validate_bvh;

    /// Never splits: every range larger than a leaf is split by count.
    struct NoSplit(usize);

    impl Splitter for NoSplit {
        type Scratch = ();
        fn max_leaf(&self) -> usize {
            self.0
        }
        fn split(&self, _: &mut [PrimRef], _: &Aabb, _: &Aabb, _: bool, _: &mut ()) -> Option<usize> {
            None
        }
    }

    /// Splits off the first reference: the deepest tree there is.
    struct PeelOne;

    impl Splitter for PeelOne {
        type Scratch = ();
        fn max_leaf(&self) -> usize {
            1
        }
        fn split(&self, _: &mut [PrimRef], _: &Aabb, _: &Aabb, _: bool, _: &mut ()) -> Option<usize> {
            Some(1)
        }
    }

    fn boxes(n: usize) -> Vec<Aabb> {
        (0..n).map(|i| Aabb::new(Vec3::new(i as f32, 0.0, 0.0), Vec3::new(i as f32 + 1.0, 1.0, 1.0))).collect()
    }

    #[test]
    fn count_splits_give_small_leaves_and_logarithmic_depth() {
        for n in [1usize, 2, 3, 4, 5, 17, 100, 10_000] {
            let b = boxes(n);
            let bvh = build_tree(&NoSplit(4), &b).into_bvh();
            let q = validate_bvh(&bvh, &b).unwrap();
            assert!(q.max_leaf <= 4, "n = {n}: {q:?}");
            assert!(q.depth <= (n as f64).log2().ceil() as u32, "n = {n}: {q:?}");
        }
    }

    #[test]
    fn a_chain_as_deep_as_its_primitives_is_built_without_recursion() {
        // Each level scans its range, so this is quadratic: kept small enough to stay fast, deep
        // enough that one call frame per level would be a risk on a thread's small stack.
        let n = 20_000;
        let b = boxes(n);
        let bvh = build_tree(&PeelOne, &b).into_bvh();
        assert_eq!(bvh.depth() as usize, n - 1);
        assert_eq!(validate_bvh(&bvh, &b).unwrap().leaves, n);
    }

    #[test]
    fn a_reference_keeps_its_box_and_any_index() {
        let b = Aabb::new(Vec3::new(-1.5, 0.0, 2.0), Vec3::new(-0.5, 3.0, 2.0));
        // Whatever float an index is stored as (normal, subnormal, an infinity, a quiet or a
        // signalling NaN), it comes back unchanged.
        let stored_as = [0x3f80_0000, 0x3f80_0001, 0x3fc0_0000, 0xbfc0_0001, 0x4000_0001, 0x4000_0000];
        for index in [0, 1, 12_345, 0x7fff_ffff, u32::MAX].into_iter().chain(stored_as) {
            let r = PrimRef::new(&b, index);
            assert_eq!((r.index(), r.bounds()), (index, b));
            assert_eq!(Vec3::from(r.centroid()), b.center());
        }
    }

    #[test]
    fn partition_puts_the_chosen_first() {
        let b = boxes(11);
        let mut refs: Vec<PrimRef> = b.iter().enumerate().map(|(i, b)| PrimRef::new(b, i as u32)).collect();
        let mid = partition(&mut refs, |r| r.index() % 3 == 0);
        assert_eq!(mid, 4);
        assert!(refs[..mid].iter().all(|r| r.index() % 3 == 0));
        assert!(refs[mid..].iter().all(|r| r.index() % 3 != 0));
        // A permutation: every reference once, with its box.
        let mut seen: Vec<u32> = refs.iter().map(|r| r.index()).collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..11).collect::<Vec<_>>());
        assert!(refs.iter().all(|r| r.bounds() == b[r.index() as usize]));
        assert_eq!(partition(&mut refs, |_| true), 11);
        assert_eq!(partition(&mut refs, |_| false), 0);
        assert_eq!(partition(&mut [], |_| true), 0);
    }

    #[test]
    fn a_large_range_is_partitioned_in_pieces_as_a_whole() {
        let n = 3 * PIECE + PIECES_MIN + 17;
        let b = boxes(n);
        let fresh = || -> Vec<PrimRef> { b.iter().enumerate().map(|(i, b)| PrimRef::new(b, i as u32)).collect() };
        // Chosen in runs and at random, none, all: whatever lands where, the chosen come first.
        let runs = |i: u32| (i / 5000) % 3 == 1;
        let scattered = |i: u32| i.wrapping_mul(2_654_435_761) >> 28 < 5;
        let choices: [&(dyn Fn(u32) -> bool + Sync); 4] = [&runs, &scattered, &|_| false, &|_| true];
        for choose in choices {
            let mut refs = fresh();
            let mid = partition_large(&mut refs, |r| choose(r.index()));
            assert_eq!(mid, (0..n as u32).filter(|&i| choose(i)).count());
            assert!(refs[..mid].iter().all(|r| choose(r.index())));
            assert!(refs[mid..].iter().all(|r| !choose(r.index())));
            let mut seen: Vec<u32> = refs.iter().map(|r| r.index()).collect();
            seen.sort_unstable();
            assert!(seen.iter().copied().eq(0..n as u32));
            assert!(refs.iter().all(|r| r.bounds() == b[r.index() as usize]));
            // The same order every time, whatever the threads did.
            let mut again = fresh();
            partition_large(&mut again, |r| choose(r.index()));
            assert!(refs.iter().zip(&again).all(|(a, b)| a.index() == b.index()));
        }
        // The bounds in pieces are the bounds in one pass.
        let refs = fresh();
        assert_eq!(range_bounds(&refs), piece_bounds(&refs));
    }
}
