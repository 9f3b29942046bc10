//! The binned surface area heuristic (SAH) builder: Wald (2007), "On fast Construction of
//! SAH-based Bounding Volume Hierarchies" (IEEE Symposium on Interactive Ray Tracing), as pbrt-v4's
//! `BVHAggregate` builds with buckets (Pharr, Jakob and Humphreys, "Physically Based Rendering",
//! 4th ed. 2023, section 7.3.2).
//!
//! At each node the centroids' box is cut into [`BinnedSah::bins`] equal slabs along each axis
//! (fewer in small nodes, as Embree's binner cuts them: Wald, Woop, Benthin, Johnson and Ernst
//! 2014, "Embree: A Kernel Framework for Efficient CPU Ray Tracing"),
//! every primitive is dropped into the slab of its centroid (one pass for all three axes), and the
//! planes between slabs are scored with the SAH from the slabs' boxes and counts, swept once from
//! each side. The best plane of the three axes is taken if it costs less than a leaf (or if the
//! node holds more than [`BinnedSah::max_leaf`] primitives, which it must then split). Costs use
//! [`crate::accel::bvh::SAH_INTERSECTION_COST`] and, by default,
//! [`crate::accel::bvh::SAH_TRAVERSAL_COST`], the constants [`crate::accel::bvh::Bvh::sah_cost`]
//! measures with (a build may price its nodes otherwise: [`BinnedSah::traversal_cost`]): a split
//! costs `C_t + C_i * (A_left * N_left + A_right * N_right) / A_node`, a leaf `C_i * N`. When the
//! centroids coincide, no plane separates them and the shared top-down driver
//! ([`super::top_down`]) splits by count. Large subtrees are built in parallel.

use glam::{BVec4A, IVec4, Vec3A, Vec4};

use super::parallel;
use super::top_down::{self, PIECE, PIECES_MIN, PrimRef, Splitter, partition, partition_large, split_beats_leaf};
use crate::Aabb;
use crate::accel::bvh::{BuildTree, Bvh, SAH_TRAVERSAL_COST};

/// Most bins per axis.
pub const MAX_BINS: usize = 32;
// A bin index is masked with `MAX_BINS - 1` to spare bounds checks.
const _: () = assert!(MAX_BINS.is_power_of_two());
/// Most primitives [`BinnedSah::block`] counts as one test.
const MAX_BLOCK: usize = 64;
/// Default most primitives per leaf of the SAH builders.
pub const DEFAULT_MAX_LEAF: usize = 8;

/// The binned SAH builder. `BinnedSah::default()` uses 32 bins and leaves of at most 8 primitives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BinnedSah {
    /// Most bins per axis, 2 to [`MAX_BINS`] (values outside are clamped); a node over `n`
    /// primitives uses at most `4 + n / 20` of them. More bins find better planes at the same
    /// linear cost per node.
    pub bins: usize,
    /// Most primitives per leaf (at least 1).
    pub max_leaf: usize,
    /// Nodes over at most this many primitives become leaves without a split search (0 by
    /// default: every node is searched). For leaves whose primitives are tested several at once,
    /// as the triangle blocks of [`crate::TriangleBvh`] are, where splitting them gains nothing.
    pub small_leaf: usize,
    /// Primitives a leaf tests at once (1 by default: one at a time; rounded up to a power of
    /// two, at most 64). The SAH then counts a side's tests rather than its primitives, `ceil(n / block)`,
    /// as Embree's builders count the blocks of four triangles of their leaves: a leaf of four
    /// costs what a leaf of one does, so the tree stops splitting where a split would only empty
    /// blocks. For [`crate::TriangleBvh`], whose leaves hold blocks of four: 15 % fewer wide
    /// nodes on the ogre and the Sponza, the same node visits per ray (docs/performance.md).
    pub block: usize,
    /// Partitions ranges of [`PIECES_MIN`] references or more piece by piece, in parallel
    /// (false by default). The sides are the same; the references' order within a side differs
    /// from one pass's, which only the order within leaves (and so which primitive an any-hit
    /// query tests first) and the count splits of coincident centroids see. The bounds and the
    /// bins of large ranges are computed in pieces either way: their results are the same.
    pub parallel_partition: bool,
    /// The SAH cost of a split's node, `C_t`, relative to one exact test
    /// ([`crate::accel::bvh::SAH_TRAVERSAL_COST`] by default, the cost the trees' SAH is measured
    /// with). Higher, the tree stops splitting sooner, into fewer nodes and larger leaves: what
    /// [`crate::TriangleBvh`] builds, whose walk waits on each node test in turn while the
    /// blocks of one leaf are tested side by side.
    pub traversal_cost: f32,
}

impl Default for BinnedSah {
    fn default() -> Self {
        BinnedSah {
            bins: MAX_BINS,
            max_leaf: DEFAULT_MAX_LEAF,
            small_leaf: 0,
            block: 1,
            parallel_partition: false,
            traversal_cost: SAH_TRAVERSAL_COST,
        }
    }
}

impl BinnedSah {
    /// Builds the tree over the primitives' boxes (primitive `i` has box `boxes[i]`).
    pub fn build(&self, boxes: &[Aabb]) -> Bvh {
        self.build_tree(boxes).into_bvh()
    }

    /// The tree before layout.
    pub fn build_tree(&self, boxes: &[Aabb]) -> BuildTree {
        top_down::build_tree(self, boxes)
    }
}

/// One slab of one axis: the box of the primitives whose centroids fall in it (as SIMD vectors:
/// the sweep is the builder's hot loop). Their number is kept apart, in [`Bins::counts`].
#[derive(Clone, Copy, Debug)]
struct Bin {
    min: Vec3A,
    max: Vec3A,
}

const EMPTY_BIN: Bin = Bin { min: Vec3A::INFINITY, max: Vec3A::NEG_INFINITY };

/// The bins of the three axes, kept by each thread from node to node: a node clears only the
/// bins it uses (4 to 7 of the 32 in nodes under 80 references) instead of copying a fresh
/// 3.5 KiB array.
#[derive(Clone, Debug)]
pub struct Bins {
    boxes: [[Bin; MAX_BINS]; 3],
    /// `counts[i]`: the primitives in bin `i` of each axis, lane `a` for axis `a`: the sweep adds
    /// the three axes' counts with one vector addition. Counts fit: a node holds at most
    /// [`crate::accel::MAX_PRIMITIVES`] (2^31 - 1) references.
    counts: [IVec4; MAX_BINS],
}

impl Default for Bins {
    fn default() -> Self {
        Bins { boxes: [[EMPTY_BIN; MAX_BINS]; 3], counts: [IVec4::ZERO; MAX_BINS] }
    }
}

impl Bin {
    #[inline(always)]
    fn add(&mut self, min: Vec3A, max: Vec3A) {
        self.min = self.min.min(min);
        self.max = self.max.max(max);
    }

    #[inline(always)]
    fn merge(&mut self, other: &Bin) {
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
    }

    /// Surface area times `count` ([`Aabb::surface_area`]'s formula): the one-box form that
    /// [`weighted_areas`] is tested against.
    #[cfg(test)]
    fn weighted_area(&self, count: u32) -> f32 {
        let e = self.max - self.min;
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x) * count as f32
    }
}

/// Ranges of at least this many references are binned into two sets of bins (see
/// [`Placement::bin`]); below it a second set costs more to clear and merge than it saves.
const TWO_SETS_MIN: usize = 512;

/// Where a node's references go: the first of its `k` bins per axis starts at `min`, and `scale`
/// bins fit in a unit (0 for an axis the centroids do not spread along); `last` is `k - 1`.
#[derive(Clone, Copy)]
struct Placement {
    min: Vec3A,
    scale: Vec3A,
    last: Vec3A,
    k: usize,
}

impl Placement {
    /// Empties the first `k` bins of `bins`.
    fn clear(&self, bins: &mut Bins) {
        for axis in bins.boxes.iter_mut() {
            axis[..self.k].fill(EMPTY_BIN);
        }
        bins.counts[..self.k].fill(IVec4::ZERO);
    }

    /// Empties the first `k` bins of `bins`, then drops each reference of `refs` into its bin
    /// of each axis ([`bin_vector`]).
    ///
    /// A long range is binned into two sets of bins, references taken in turn, then merged:
    /// neighbouring triangles of a mesh mostly fall into the same bins, and with one set each
    /// reference's update of a bin waits for the previous one's store to be read back; two
    /// independent chains keep the processor busy (builds 3-8 % faster on the bunny, the ogre
    /// and the Sponza; docs/performance.md). The bins are the same either way: unions and sums,
    /// exact in any order.
    #[inline(always)]
    fn bin(&self, refs: &[PrimRef], bins: &mut Bins) {
        self.clear(bins);
        if refs.len() < TWO_SETS_MIN {
            for r in refs {
                self.add(r, bins);
            }
            return;
        }
        let mut odd = Bins::default();
        let pairs = refs.chunks_exact(2);
        for r in pairs.remainder() {
            self.add(r, bins);
        }
        for pair in pairs {
            self.add(&pair[0], bins);
            self.add(&pair[1], &mut odd);
        }
        bins.merge(&odd, self.k);
    }

    /// Drops reference `r` into its bin of each axis.
    #[inline(always)]
    fn add(&self, r: &PrimRef, bins: &mut Bins) {
        let (lo, hi) = (r.min(), r.max());
        let slot = bin_vector(r.centroid(), self.min, self.scale, self.last);
        // `slot` is below `k` already; the mask only spares the bounds checks.
        let slot = slot.map(|i| i as usize & (MAX_BINS - 1));
        for (axis, boxes) in bins.boxes.iter_mut().enumerate() {
            boxes[slot[axis]].add(lo, hi);
            bins.counts[slot[axis]][axis] += 1;
        }
    }
}

impl Bins {
    /// Adds `other`'s first `k` bins of each axis to this one's.
    fn merge(&mut self, other: &Bins, k: usize) {
        for (mine, theirs) in self.boxes.iter_mut().zip(&other.boxes) {
            for (a, b) in mine[..k].iter_mut().zip(&theirs[..k]) {
                a.merge(b);
            }
        }
        for (a, b) in self.counts[..k].iter_mut().zip(&other.counts[..k]) {
            *a += *b;
        }
    }
}

/// The bin of coordinate `c` among `bins` bins starting at `min`, `scale` bins per unit; a NaN or
/// an out of range value saturates into the first or last bin. The rule the builder's two fast
/// forms ([`bin_vector`], which places primitives, and [`before_plane`], which partitions them)
/// are tested against, so that placement and partition always agree.
#[cfg(test)]
fn bin_of(c: f32, min: f32, scale: f32, bins: usize) -> usize {
    (((c - min) * scale) as usize).min(bins - 1)
}

/// Which coordinates of `c` fall in a bin at or past `plane` (bit `a` of the result set when
/// `bin_of(c[a], min[a], scale[a], bins) >= plane`, for any `plane` in `1..bins`), one comparison
/// per lane: the bin is the integer part of the product (0 for a negative product or NaN), so it
/// reaches the integer `plane` exactly when the product does. All lanes at once, so that the
/// partition reads no lane chosen at run time.
#[inline(always)]
fn past_plane(c: Vec4, min: Vec4, scale: Vec4, plane: Vec4) -> u32 {
    ((c - min) * scale).cmpge(plane).bitmask()
}

/// [`bin_of`] on the three coordinates of `c` at once, `last` being `bins - 1` in each lane: the
/// same products, then the same saturation (a NaN goes to the first bin, as the integer
/// conversion sends it: x86's `max` returns its second operand, zero, for a NaN, and elsewhere
/// the saturating conversion below maps a NaN that went through to zero).
#[inline(always)]
pub(crate) fn bin_vector(c: Vec3A, min: Vec3A, scale: Vec3A, last: Vec3A) -> [u32; 3] {
    let clamped = ((c - min) * scale).max(Vec3A::ZERO).min(last);
    // In range already: a plain truncation, without the saturating conversion's branches.
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: SSE2 is part of x86-64's baseline; any 128 bits are four valid `u32`s.
        let i: [u32; 4] = unsafe { std::mem::transmute(std::arch::x86_64::_mm_cvttps_epi32(clamped.into())) };
        [i[0], i[1], i[2]]
    }
    #[cfg(not(target_arch = "x86_64"))]
    clamped.as_uvec3().to_array()
}

/// The weighted areas ([`Bin::weighted_area`], computed as it computes them) of three boxes, lane
/// `a` the box of axis `a`'s bins, and their counts (`counts`, lane `a` axis `a`'s) as floats.
#[inline(always)]
fn weighted_areas(sides: &[Bin; 3], counts: IVec4) -> (Vec4, Vec4) {
    let e = sides.map(|b| b.max - b.min);
    let lanes = |f: fn(Vec3A) -> f32| Vec4::new(f(e[0]), f(e[1]), f(e[2]), 0.0);
    let (ex, ey, ez) = (lanes(|v| v.x), lanes(|v| v.y), lanes(|v| v.z));
    // A count below 2^31 converts to the same float from an `i32` as from the `u32` it would
    // otherwise be (rounded alike above 2^24).
    let count = counts.as_vec4();
    (Vec4::splat(2.0) * (ex * ey + ey * ez + ez * ex) * count, count)
}

/// `count` primitives tested `2^shift` at a time: `ceil(count / 2^shift)` tests per lane, for counts
/// from 0 to `i32::MAX` (written so that nothing overflows: `(count - 1) >> shift` is -1 for none).
#[inline(always)]
fn tests_of(count: IVec4, shift: u32) -> IVec4 {
    ((count - IVec4::ONE) >> shift) + IVec4::ONE
}

/// The best plane among the first `k` bins of each axis that `splittable` allows: (area-weighted
/// count of both sides, axis, first bin of the second side), each side's count being its blocks
/// of `2^shift` primitives (see [`BinnedSah::block`]). The three axes are swept at once,
/// one per vector lane (as Embree's binner does); each lane keeps the first plane of least cost,
/// and the axes are then compared in order, so the plane is the one a sweep of axis 0, then 1,
/// then 2 would keep (the first of least cost).
fn best_plane(bins: &Bins, k: usize, splittable: [bool; 3], shift: u32) -> Option<(f32, usize, usize)> {
    // right[i]: area times count of bins i.. of each axis (for the planes before bin i, i in
    // 1..k), NaN where they are empty.
    let mut right = [Vec4::NAN; MAX_BINS];
    let (mut side, mut side_count) = ([EMPTY_BIN; 3], IVec4::ZERO);
    for i in (1..k).rev() {
        for (s, axis) in side.iter_mut().zip(&bins.boxes) {
            s.merge(&axis[i]);
        }
        side_count += bins.counts[i];
        let (weighted, count) = weighted_areas(&side, tests_of(side_count, shift));
        right[i] = Vec4::select(count.cmpeq(Vec4::ZERO), Vec4::NAN, weighted);
    }
    let allowed = BVec4A::new(splittable[0], splittable[1], splittable[2], false);
    let (mut cost, mut plane, mut found) = (Vec4::ZERO, Vec4::ZERO, BVec4A::splat(false));
    let (mut side, mut side_count) = ([EMPTY_BIN; 3], IVec4::ZERO);
    for i in 1..k {
        for (s, axis) in side.iter_mut().zip(&bins.boxes) {
            s.merge(&axis[i - 1]);
        }
        side_count += bins.counts[i - 1];
        let (weighted, count) = weighted_areas(&side, tests_of(side_count, shift));
        let valid = allowed & count.cmpne(Vec4::ZERO) & !right[i].is_nan_mask();
        let here = weighted + right[i];
        let better = valid & (!found | here.cmplt(cost));
        cost = Vec4::select(better, here, cost);
        plane = Vec4::select(better, Vec4::splat(i as f32), plane);
        found |= valid;
    }
    let mut best: Option<(f32, usize, usize)> = None;
    for axis in (0..3).filter(|&a| found.test(a)) {
        if best.is_none_or(|(c, _, _)| cost[axis] < c) {
            best = Some((cost[axis], axis, plane[axis] as usize));
        }
    }
    best
}

impl Splitter for BinnedSah {
    type Scratch = Bins;

    fn max_leaf(&self) -> usize {
        self.max_leaf
    }

    fn split(
        &self,
        refs: &mut [PrimRef],
        bounds: &Aabb,
        centroid_bounds: &Aabb,
        must_split: bool,
        scratch: &mut Bins,
    ) -> Option<usize> {
        // A node over `n` primitives gets at most `4 + n / 20` bins, as Embree's binner gives
        // them (`BinMapping`): in small nodes the sweep over the bins, not the binning, is the
        // cost, and fewer bins there lose little (on the bunny and the Sponza, 8-9 % fewer
        // instructions per triangle built, within 1 % more per ray; docs/performance.md).
        if !must_split && refs.len() <= self.small_leaf {
            return None;
        }
        let k = self.bins.clamp(2, MAX_BINS).min(4 + refs.len() / 20);
        let extent = centroid_bounds.extent();
        // Axes along which the centroids spread; the others cannot be split by a plane.
        let scale = extent.to_array().map(|e| if e > 0.0 { k as f32 / e } else { 0.0 });
        if scale == [0.0; 3] {
            return None;
        }
        let min = centroid_bounds.min;
        // All three axes' bins at once, each coordinate as `bin_of` places it (an axis that
        // cannot be split fills its first bin, which no plane reads).
        let (c_min, c_scale) = (Vec3A::from(min), Vec3A::from_array(scale));
        let place = Placement { min: c_min, scale: c_scale, last: Vec3A::splat((k - 1) as f32), k };
        if refs.len() < PIECES_MIN {
            place.bin(refs, scratch);
        } else {
            // Large ranges in pieces, in parallel; merged, their bins are the ones one pass
            // would fill (unions and sums, exact in any order).
            let pieces = parallel::map_chunks(refs, PIECE, |piece| {
                let mut bins = Box::<Bins>::default();
                place.bin(piece, &mut bins);
                bins
            });
            place.clear(scratch);
            for piece in &pieces {
                scratch.merge(piece, k);
            }
        }

        let shift = self.block.clamp(1, MAX_BLOCK).next_power_of_two().trailing_zeros();
        let (weighted, axis, plane) = best_plane(scratch, k, scale.map(|s| s > 0.0), shift)?;
        let tests = refs.len().div_ceil(1 << shift);
        if !must_split && !split_beats_leaf(weighted, bounds.surface_area(), tests, self.traversal_cost) {
            return None;
        }
        let plane = plane as f32;
        let (c_min, c_scale, c_plane) = (Vec4::from((c_min, 0.0)), Vec4::from((c_scale, 0.0)), Vec4::splat(plane));
        let left = |r: &PrimRef| past_plane(r.centroid4(), c_min, c_scale, c_plane) >> axis & 1 == 0;
        Some(if self.parallel_partition { partition_large(refs, left) } else { partition(refs, left) })
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::bvh::validate::validate_bvh;

    fn cube(c: Vec3, r: f32) -> Aabb {
        Aabb::new(c - Vec3::splat(r), c + Vec3::splat(r))
    }

    #[test]
    fn two_far_clusters_are_split_between_them() {
        // Four small cubes near x = 0, four near x = 100: the root's plane separates the clusters.
        let mut boxes: Vec<Aabb> = (0..4).map(|i| cube(Vec3::new(i as f32 * 0.1, 0.0, 0.0), 0.01)).collect();
        boxes.extend((0..4).map(|i| cube(Vec3::new(100.0 + i as f32 * 0.1, 0.0, 0.0), 0.01)));
        let bvh = BinnedSah::default().build(&boxes);
        validate_bvh(&bvh, &boxes).unwrap();
        let n = bvh.nodes();
        let (left, right) = (n[1].bounds(), n[n[0].index as usize].bounds());
        assert!(left.max.x < 1.0 && right.min.x > 99.0, "{left:?} {right:?}");
    }

    #[test]
    fn small_scattered_primitives_get_leaves_of_their_own() {
        // Tiny boxes far apart: any leaf of two costs more than a split, so every leaf has one.
        let boxes: Vec<Aabb> =
            (0..64).map(|i| cube(Vec3::new((i % 4) as f32, (i / 4 % 4) as f32, (i / 16) as f32) * 10.0, 0.1)).collect();
        let bvh = BinnedSah::default().build(&boxes);
        let q = validate_bvh(&bvh, &boxes).unwrap();
        assert_eq!((q.leaves, q.max_leaf), (64, 1));
    }

    #[test]
    fn overlapping_primitives_share_a_leaf() {
        // Eight equal boxes, centroids slightly apart: splitting cannot shrink the boxes, so a
        // leaf is cheaper than any split.
        let boxes: Vec<Aabb> = (0..8).map(|i| cube(Vec3::new(i as f32 * 1e-3, 0.0, 0.0), 1.0)).collect();
        let q = validate_bvh(&BinnedSah::default().build(&boxes), &boxes).unwrap();
        assert_eq!((q.leaves, q.max_leaf), (1, 8));
        // More than a leaf may hold: split anyway, into leaves no larger than allowed.
        let builder = BinnedSah { bins: 8, max_leaf: 3, ..BinnedSah::default() };
        let q = validate_bvh(&builder.build(&boxes), &boxes).unwrap();
        assert!(q.max_leaf <= 3 && q.leaves >= 3, "{q:?}");
    }

    #[test]
    fn tests_are_counted_in_blocks_without_overflow() {
        for shift in 0..=6u32 {
            for n in [0, 1, 2, 3, 4, 5, 63, 64, 65, 1 << 20, i32::MAX - 64, i32::MAX] {
                let expected = (n as u32).div_ceil(1 << shift) as i32;
                assert_eq!(tests_of(IVec4::splat(n), shift), IVec4::splat(expected), "{n} in blocks of 2^{shift}");
            }
        }
    }

    /// Eight unit cubes a tenth apart along x (box area 8.8; each half's 7.2).
    fn eight_cubes() -> Vec<Aabb> {
        (0..8).map(|i| cube(Vec3::new(i as f32 * 0.1, 0.0, 0.0), 0.5)).collect()
    }

    #[test]
    fn blocks_keep_a_leaf_that_single_tests_would_split() {
        // One test per primitive: a split costs 0.5 + (7.2 * 4 + 7.2 * 4) / 8.8 = 7.05, under a
        // leaf's 8. In blocks of four: 0.5 + (7.2 + 7.2) / 8.8 = 2.14, over a leaf's two blocks.
        let boxes = eight_cubes();
        let one = validate_bvh(&BinnedSah::default().build(&boxes), &boxes).unwrap();
        assert_eq!((one.leaves, one.max_leaf), (2, 4));
        let blocks = BinnedSah { block: 4, ..BinnedSah::default() };
        let q = validate_bvh(&blocks.build(&boxes), &boxes).unwrap();
        assert_eq!((q.leaves, q.max_leaf), (1, 8));
        // A block of three is counted as one of four; a block of none, as one of one.
        assert_eq!(validate_bvh(&BinnedSah { block: 3, ..blocks }.build(&boxes), &boxes).unwrap(), q);
        assert_eq!(validate_bvh(&BinnedSah { block: 0, ..blocks }.build(&boxes), &boxes).unwrap(), one);
    }

    #[test]
    fn a_dearer_node_keeps_a_leaf_that_the_default_cost_splits() {
        // One test per primitive: a split costs C_t + 57.6 / 8.8 = C_t + 6.55 against a leaf's 8,
        // so it is taken at the default 0.5 and refused at 1.5.
        let boxes = eight_cubes();
        let leaves = |c_t: f32| {
            let q = validate_bvh(&BinnedSah { traversal_cost: c_t, ..BinnedSah::default() }.build(&boxes), &boxes);
            q.map(|q| (q.leaves, q.max_leaf)).unwrap()
        };
        assert_eq!(leaves(0.5), (2, 4));
        assert_eq!(leaves(1.5), (1, 8));
    }

    #[test]
    fn coincident_centroids_are_split_by_count() {
        let boxes: Vec<Aabb> = (1..=1000).map(|i| cube(Vec3::ONE, i as f32)).collect();
        let q = validate_bvh(&BinnedSah::default().build(&boxes), &boxes).unwrap();
        assert!(q.max_leaf <= DEFAULT_MAX_LEAF && q.depth <= 8, "{q:?}");
    }

    #[test]
    fn bins_out_of_range_are_clamped() {
        let boxes: Vec<Aabb> = (0..100).map(|i| cube(Vec3::new(i as f32, 0.0, 0.0), 0.4)).collect();
        for bins in [0, 1, 2, 1000] {
            validate_bvh(&BinnedSah { bins, max_leaf: 4, ..BinnedSah::default() }.build(&boxes), &boxes).unwrap();
        }
        assert_eq!(bin_of(f32::NAN, 0.0, 1.0, 8), 0);
        assert_eq!(bin_of(f32::INFINITY, 0.0, 1.0, 8), 7);
        assert_eq!(bin_of(-1.0, 0.0, 1.0, 8), 0);
        // The three-lane placement is the one-lane one, whatever the value.
        let odd = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, -0.0, 0.0, 0.99, 1.0, 6.5, 7.0, 7.99, 8.0, 1e30];
        let (min, scale) = (Vec3A::new(0.0, 0.5, -2.0), Vec3A::new(1.0, 2.0, 0.25));
        for (i, &x) in odd.iter().enumerate() {
            let (y, z) = (odd[(i + 3) % odd.len()], odd[(i + 7) % odd.len()]);
            let got = bin_vector(Vec3A::new(x, y, z), min, scale, Vec3A::splat(7.0));
            let expected =
                [x, y, z].iter().enumerate().map(|(a, &c)| bin_of(c, min[a], scale[a], 8) as u32).collect::<Vec<_>>();
            assert_eq!(got.to_vec(), expected, "{x} {y} {z}");
            // The partition's comparison is the placement's, at every plane.
            let c = Vec4::new(x, y, z, f32::NAN);
            for plane in 1..8 {
                let past = past_plane(c, min.extend(0.0), scale.extend(0.0), Vec4::splat(plane as f32));
                for (a, &c) in [x, y, z].iter().enumerate() {
                    let expected = bin_of(c, min[a], scale[a], 8) >= plane;
                    assert_eq!(past >> a & 1 == 1, expected, "{c} on axis {a} at plane {plane}");
                }
            }
        }
    }

    /// Floats spread over `0..1` from `seed` (a xorshift generator: the tests need no more).
    fn unit_floats(seed: u32) -> impl FnMut() -> f32 {
        let mut state = seed;
        move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state >> 8) as f32 / (1 << 24) as f32
        }
    }

    #[test]
    fn the_three_lane_areas_are_the_one_box_areas_bit_for_bit() {
        let mut unit = unit_floats(0x2545_f491);
        let mut next = move || unit() * 200.0 - 100.0;
        for _ in 0..1000 {
            let sides = [0, 1, 2].map(|_| {
                let (a, b) = (Vec3A::new(next(), next(), next()), Vec3A::new(next(), next(), next()));
                Bin { min: a.min(b), max: a.max(b) }
            });
            // Counts up to the largest a node may hold.
            let counts =
                [0, 1, 2].map(|_| (((next().abs() / 100.0).powi(8) * i32::MAX as f32) as u32).min(i32::MAX as u32));
            let lanes = IVec4::new(counts[0] as i32, counts[1] as i32, counts[2] as i32, 0);
            let (weighted, count) = weighted_areas(&sides, lanes);
            for (axis, side) in sides.iter().enumerate() {
                let expected = side.weighted_area(counts[axis]);
                assert_eq!(weighted[axis].to_bits(), expected.to_bits(), "{side:?} {counts:?}");
                assert_eq!(count[axis], counts[axis] as f32);
            }
        }
    }

    #[test]
    fn a_large_range_binned_in_pieces_fills_the_bins_of_one_pass() {
        let mut unit = unit_floats(0x9e37_79b9);
        let mut next = move || unit() * 100.0;
        let boxes: Vec<Aabb> = (0..PIECES_MIN + 3 * PIECE / 2)
            .map(|_| cube(Vec3::new(next(), next(), next() * 0.1), next() * 0.01))
            .collect();
        let refs: Vec<PrimRef> = boxes.iter().enumerate().map(|(i, b)| PrimRef::new(b, i as u32)).collect();
        let k = 13;
        let place = Placement { min: Vec3A::ZERO, scale: Vec3A::splat(0.13), last: Vec3A::splat(12.0), k };
        let mut whole = Bins::default();
        place.bin(&refs, &mut whole);
        let mut merged = Bins::default();
        place.clear(&mut merged);
        for piece in refs.chunks(PIECE) {
            let mut bins = Bins::default();
            place.bin(piece, &mut bins);
            merged.merge(&bins, k);
        }
        // One set of bins filled reference after reference: what `bin`'s two sets add up to.
        let mut single = Bins::default();
        place.clear(&mut single);
        for r in &refs {
            place.add(r, &mut single);
        }
        for other in [&merged, &single] {
            for i in 0..k {
                assert_eq!(whole.counts[i], other.counts[i]);
                for axis in 0..3 {
                    let (a, b) = (whole.boxes[axis][i], other.boxes[axis][i]);
                    assert_eq!((a.min, a.max), (b.min, b.max), "bin {i} of axis {axis}");
                }
            }
        }
        assert_eq!(whole.counts[..k].iter().map(|c| c.x).sum::<i32>() as usize, refs.len());
        // The trees over them, built with pieces at their top levels, are sound, and the
        // parallel partition's has the one pass's nodes (the same sides, their order aside).
        let one_pass = BinnedSah::default().build(&boxes);
        let q = validate_bvh(&one_pass, &boxes).unwrap();
        assert!(q.max_leaf <= DEFAULT_MAX_LEAF, "{q:?}");
        let pieces = BinnedSah { parallel_partition: true, ..BinnedSah::default() }.build(&boxes);
        assert_eq!(validate_bvh(&pieces, &boxes).unwrap(), q);
        assert_eq!(pieces.sah_cost(), one_pass.sah_cost());
    }

    #[test]
    fn leaf_sizes_are_counted_and_large_ones_pooled() {
        let boxes: Vec<Aabb> = (0..30).map(|_| Aabb::new(glam::Vec3::ZERO, glam::Vec3::ONE)).collect();
        // Identical boxes: leaves of 8, split by count: 30 = 7 + 8 + 7 + 8.
        let bvh = BinnedSah::default().build(&boxes);
        assert_eq!(bvh.leaf_sizes(), [0, 0, 0, 0, 0, 0, 2, 2, 0]);
        let one = BinnedSah { bins: 8, max_leaf: 30, ..BinnedSah::default() }.build(&boxes);
        assert_eq!(one.leaf_sizes(), [0, 0, 0, 0, 0, 0, 0, 0, 1]);
    }
}
