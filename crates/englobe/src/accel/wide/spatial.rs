//! Spatial splits in the top levels of the tree, decided before the build: where a large
//! triangle straddles a good split plane, it is cut there, and the build sees its pieces.
//!
//! A BVH bounds whole primitives, so a node split by its primitives' centroids gets two children
//! that overlap wherever a large triangle straddles the plane; a ray through the overlap visits
//! both. Stich, Friedrich and Dietrich (2009), "Spatial Splits in Bounding Volume Hierarchies",
//! let each split choose between the usual object split and a spatial split, which cuts the
//! references straddling its plane in two, by the surface area heuristic (SAH), and then puts a
//! cut reference back whole on one side where that costs less ("reference unsplitting"). The
//! pre-split ([`super::presplit`]) cuts triangles by how much their boxes waste, wherever they lie;
//! spatial splits cut them where the tree's splits are, and only where the SAH gains from it.
//!
//! The wide build is the binned SAH build, unchanged: this module runs the SBVH's choice over the
//! top [`TriangleBvhOptions::spatial_levels`] binary levels of a tree of its own (binned object
//! and spatial splits, Stich et al.'s sections 3 and 4) and hands the build the references it
//! ends with, each a box around its part of a triangle. Below those levels, or in a subtree with
//! no triangle left that may be cut, nothing more is cut and the subtree's references are handed
//! over as they are. A triangle may be cut if its box wastes at least [`MIN_CUT_SHARE`] of the
//! scene box's area; the others go whole to the side of their centroid, as in an object split.
//! The cuts add at most [`MAX_EXTRA`] times as many references as there are triangles, that
//! budget shared down the tree.
//!
//! A cut reference's box is the bounds of the triangle clipped to its side of the plane (in
//! `f64`, rounded outward: [`crate::shapes::clip::clip_triangle`]), so a fragment's box always
//! holds its part of the triangle, and the queries stay exact as they do with the pre-split (each
//! leaf tests the whole triangle). Binning, which only chooses the plane, cuts the reference's
//! box at the bins' planes rather than the triangle: on the Sponza the same tree within a few
//! references (0.1 %), and the pass in less than half the time.
//!
//! Only on a scene with large triangles ([`MIN_LARGE_WASTE`]): on the Sponza it takes the wide
//! nodes visited per random ray from 6.9 to 5.5 (closest hit) and from 3.9 to 2.8 (any hit)
//! against the pre-split, 11-23 % faster rays, for a build that executes 37 % more instructions
//! (see `docs/performance.md`, "Since then: spatial splits in the top levels" and "Since then:
//! the spatial pass's own passes"); the bunny and the ogre would gain nothing from it, and do not
//! run it.
//!
//! [`TriangleBvhOptions::spatial_levels`]: super::triangle_bvh::TriangleBvhOptions::spatial_levels

use glam::{BVec3A, Vec3, Vec3A};

use super::presplit::{Fragments, MIN_WASTE_SHARE, TriangleBox};
use crate::Aabb;
use crate::accel::MAX_PRIMITIVES;
use crate::accel::bvh::build::binned_sah::bin_vector;
use crate::accel::bvh::build::parallel::{self, collect_indexed};
use crate::accel::bvh::build::top_down::PrimRef;
use crate::shapes::clip::{Polygon, clip_triangle};

/// Bins per axis, for object splits and for spatial splits.
const BINS: usize = 32;

/// The least area a triangle's box must waste, as a share of the scene box's surface area, for
/// the triangle to be cut (a box wasting 1/100 000 of the scene's area; the pre-split's floor,
/// 1/2048, left most of the Sponza's useful cuts out: in 8 levels, 1.2 % more references instead
/// of 9 %, 6.2 wide nodes per random closest-hit ray instead of 5.4).
pub const MIN_CUT_SHARE: f32 = 1e-5;

/// Spatial splits are tried only on a scene whose large triangles (those whose box wastes at least
/// [`MIN_WASTE_SHARE`] of the scene box's area, the pre-split's floor) waste together at least
/// this many times the scene box's area. The Sponza's 1 677 large triangles waste 8.5 times it;
/// the bunny has none, the ogre 20 wasting 0.012 times it, and the bunny tiled into millions of
/// triangles none: there the spatial splits cost the build about half again and gained nothing.
pub const MIN_LARGE_WASTE: f32 = 1.0;

/// Triangles per task in the passes over all of them.
const CHUNK: usize = 1 << 14;

/// Nodes with fewer references are not split further here (the build splits them).
const MIN_REFS: usize = 32;

/// Nodes with at least this many references bin in pieces, in parallel.
const PARALLEL_REFS: usize = 1 << 14;

/// A spatial split is looked for only where the best object split's children overlap by at least
/// this share of the scene box's area (Stich et al.'s `alpha`, section 4.3): elsewhere cutting
/// cannot gain much.
const MIN_OVERLAP_SHARE: f32 = 1e-4;

/// Most references the cuts may add, as a share of the triangles: a bound on memory whatever the
/// scene (the SAH alone would stop far below it on real scenes), shared out down the tree in
/// proportion to the references on each side.
pub const MAX_EXTRA: f64 = 0.5;

/// A reference: a box around a triangle or a part of one, its triangle (the caller's index), and
/// in its spare lane 1 if the triangle is large enough to be cut, 0 if not.
type Frag = PrimRef;

fn frag(bounds: &Aabb, owner: u32, large: bool) -> Frag {
    PrimRef::with_spare(bounds, owner, if large { 1.0 } else { 0.0 })
}

fn is_large(f: &Frag) -> bool {
    f.spare() > 0.0
}

/// A box as two vectors, for the passes over references.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    lo: Vec3A,
    hi: Vec3A,
}

impl Bounds {
    const EMPTY: Bounds = Bounds { lo: Vec3A::INFINITY, hi: Vec3A::NEG_INFINITY };

    #[inline(always)]
    fn add(&mut self, lo: Vec3A, hi: Vec3A) {
        self.lo = self.lo.min(lo);
        self.hi = self.hi.max(hi);
    }

    #[inline]
    fn union(self, o: Bounds) -> Bounds {
        Bounds { lo: self.lo.min(o.lo), hi: self.hi.max(o.hi) }
    }

    fn aabb(&self) -> Aabb {
        Aabb::new(self.lo.into(), self.hi.into())
    }

    fn area(&self) -> f32 {
        self.aabb().surface_area()
    }
}

/// One side of a split as it is filled: its references, their bounds, the bounds of their
/// centroids and how many may be cut, gathered as the references come, so that the side's own
/// split starts without a pass over them.
struct Side {
    refs: Vec<Frag>,
    bounds: Bounds,
    centroids: Bounds,
    large: usize,
}

impl Side {
    fn with_capacity(n: usize) -> Self {
        Side { refs: Vec::with_capacity(n), bounds: Bounds::EMPTY, centroids: Bounds::EMPTY, large: 0 }
    }

    #[inline(always)]
    fn push(&mut self, f: Frag) {
        self.bounds.add(f.min(), f.max());
        let c = f.centroid();
        self.centroids.add(c, c);
        self.large += usize::from(is_large(&f));
        self.refs.push(f);
    }

    fn merge(mut self, other: Side) -> Side {
        self.refs.extend(other.refs);
        self.bounds = self.bounds.union(other.bounds);
        self.centroids = self.centroids.union(other.centroids);
        self.large += other.large;
        self
    }
}

/// Cuts the large ones among triangles `triangle(i)`, `i` in `0..count` (each described by
/// `describe(i)`, its box finite and not empty), with spatial splits in the top `levels` levels;
/// `None` when no triangle is cut (the build then takes the triangles' own boxes), and without
/// trying when the scene's triangles are even (see [`MIN_LARGE_WASTE`]). The fragments come out
/// in the same order whatever the threads.
pub fn spatial_cuts(
    count: usize,
    describe: impl Fn(usize) -> TriangleBox + Sync,
    triangle: impl Fn(u32) -> [Vec3; 3] + Sync,
    levels: u32,
) -> Option<Fragments> {
    if levels == 0 || count < MIN_REFS {
        return None;
    }
    // The passes over every triangle go in fixed chunks, in parallel: the sums come out the same
    // whatever the threads.
    let chunks = count.div_ceil(CHUNK);
    let chunk = |c: usize| c * CHUNK..((c + 1) * CHUNK).min(count);
    let scene = collect_indexed(chunks, 1, |c| chunk(c).fold(Aabb::EMPTY, |s, i| s.union(&describe(i).bounds)))
        .into_iter()
        .fold(Aabb::EMPTY, |s, b| s.union(&b));
    if !scene.is_finite() {
        return None;
    }
    let large = scene.surface_area() * MIN_WASTE_SHARE;
    let waste: f64 = collect_indexed(chunks, 1, |c| {
        chunk(c).map(|i| describe(i).waste).filter(|&w| w >= large).map(f64::from).sum::<f64>()
    })
    .into_iter()
    .sum();
    if !(waste >= (MIN_LARGE_WASTE * scene.surface_area()) as f64) {
        return None;
    }
    let floor = scene.surface_area() * MIN_CUT_SHARE;
    let root = collect_indexed(chunks, 1, |c| {
        let mut side = Side::with_capacity(CHUNK);
        for i in chunk(c) {
            let t = describe(i);
            side.push(frag(&t.bounds, i as u32, t.waste >= floor));
        }
        side
    })
    .into_iter()
    .reduce(Side::merge)
    .expect("at least one chunk");
    let splitter = Splits { triangle: &triangle, min_overlap: scene.surface_area() * MIN_OVERLAP_SHARE, levels };
    // References stay within what a build may hold (its bins count them in `i32` lanes), and
    // within a budget of extra ones however many the SAH would like.
    let budget = ((count as f64 * MAX_EXTRA) as usize).min(MAX_PRIMITIVES.saturating_sub(count));
    let parts = splitter.node(root, budget, 0);
    if parts.iter().map(Vec::len).sum::<usize>() == count {
        return None;
    }
    Some(Fragments {
        boxes: parts.iter().flatten().map(PrimRef::bounds).collect(),
        owner: parts.iter().flatten().map(PrimRef::index).collect(),
    })
}

struct Splits<'a, T> {
    triangle: &'a T,
    min_overlap: f32,
    levels: u32,
}

/// What one pass over a node's references gathers, per axis and bin: for object splits, the
/// references whose centroid falls in the bin and their boxes; for spatial splits, the parts of
/// references in the bin, how many references start in it and how many end in it.
struct Bins {
    object: [[Bounds; BINS]; 3],
    counts: [[u32; BINS]; 3],
    spatial: [[Bounds; BINS]; 3],
    enter: [[u32; BINS]; 3],
    exit: [[u32; BINS]; 3],
}

impl Bins {
    fn new() -> Self {
        Bins {
            object: [[Bounds::EMPTY; BINS]; 3],
            counts: [[0; BINS]; 3],
            spatial: [[Bounds::EMPTY; BINS]; 3],
            enter: [[0; BINS]; 3],
            exit: [[0; BINS]; 3],
        }
    }

    fn merge(mut self, other: &Bins) -> Self {
        for a in 0..3 {
            for k in 0..BINS {
                self.object[a][k] = self.object[a][k].union(other.object[a][k]);
                self.counts[a][k] += other.counts[a][k];
                self.spatial[a][k] = self.spatial[a][k].union(other.spatial[a][k]);
                self.enter[a][k] += other.enter[a][k];
                self.exit[a][k] += other.exit[a][k];
            }
        }
        self
    }
}

/// A node's grid of bins: `planes[k]` starts bin `k` on each axis.
#[derive(Clone, Copy)]
struct Grid {
    origin: Vec3A,
    /// Bins per unit of length (zero on a flat axis).
    scale: Vec3A,
    planes: [Vec3A; BINS + 1],
}

/// The lanes of each axis, to replace one coordinate of a corner by a plane's.
const AXIS: [BVec3A; 3] =
    [BVec3A::new(true, false, false), BVec3A::new(false, true, false), BVec3A::new(false, false, true)];

impl Grid {
    fn over(b: &Bounds) -> Self {
        let width = (b.hi - b.lo) / BINS as f32;
        let scale = Vec3A::select(width.cmpgt(Vec3A::ZERO), width.recip(), Vec3A::ZERO);
        let planes = std::array::from_fn(|k| b.lo + k as f32 * width);
        Grid { origin: b.lo, scale, planes }
    }

    /// The bins of `p` on the three axes (anything below the grid, and NaN, in bin 0).
    #[inline(always)]
    fn bins(&self, p: Vec3A) -> [usize; 3] {
        // Below `BINS` already: the mask only spares the bounds checks.
        bin_vector(p, self.origin, self.scale, Vec3A::splat((BINS - 1) as f32)).map(|k| k as usize & (BINS - 1))
    }

    /// Whether `x` on `axis` falls in a bin before `bin` (in `1..BINS`), as [`Grid::bins`] bins
    /// it: the bin is the integer part of the product, saturated, so it is below the integer
    /// `bin` exactly when the product is (or is NaN, which goes to bin 0).
    #[inline(always)]
    fn before(&self, axis: usize, x: f32, bin: usize) -> bool {
        !((x - self.origin[axis]) * self.scale[axis] >= bin as f32)
    }
}

/// The best split found on one axis: its SAH cost (areas times references), the bin it starts the
/// right side at, the two sides' boxes and how many references they hold (for a spatial split, at
/// most that many: a reference across the plane may go whole to one side).
#[derive(Clone, Copy)]
struct Best {
    cost: f32,
    axis: usize,
    bin: usize,
    left: Bounds,
    right: Bounds,
    counts: (usize, usize),
}

/// The best split of a sweep over bins (their boxes, and the references counted on the left and on
/// the right of a plane after them or before them), with at most `max_refs` references on both
/// sides together.
fn sweep(
    axis: usize,
    boxes: &[Bounds; BINS],
    left_counts: &[u32; BINS],
    right_counts: &[u32; BINS],
    max_refs: usize,
    best: &mut Option<Best>,
) {
    let mut right = [(Bounds::EMPTY, 0u32); BINS];
    let mut acc = (Bounds::EMPTY, 0);
    for k in (1..BINS).rev() {
        acc = (acc.0.union(boxes[k]), acc.1 + right_counts[k]);
        right[k] = acc;
    }
    let mut left = (Bounds::EMPTY, 0);
    for k in 1..BINS {
        left = (left.0.union(boxes[k - 1]), left.1 + left_counts[k - 1]);
        let (rb, rn) = right[k];
        if left.1 == 0 || rn == 0 || (left.1 + rn) as usize > max_refs {
            continue;
        }
        let cost = left.0.area() * left.1 as f32 + rb.area() * rn as f32;
        if best.is_none_or(|b| cost < b.cost) {
            let counts = (left.1 as usize, rn as usize);
            *best = Some(Best { cost, axis, bin: k, left: left.0, right: rb, counts });
        }
    }
}

impl<T: Fn(u32) -> [Vec3; 3] + Sync> Splits<'_, T> {
    /// The references of the subtree over `node`, at depth `depth`, cut where its splits say,
    /// adding at most `budget` references: in runs, to be read one after the other.
    fn node(&self, node: Side, budget: usize, depth: u32) -> Vec<Vec<Frag>> {
        if depth >= self.levels || node.refs.len() < MIN_REFS || node.large == 0 {
            return vec![node.refs];
        }
        let n = node.refs.len();
        let Some((left, right)) = self.split(&node, budget) else {
            return vec![node.refs];
        };
        drop(node);
        let (nl, nr) = (left.refs.len(), right.refs.len());
        // What is left of the budget, shared in proportion to each side's references.
        let rest = budget.saturating_sub(nl + nr - n);
        let to_left = (rest as f64 * nl as f64 / (nl + nr) as f64) as usize;
        let (mut l, r) = if nl.min(nr) >= PARALLEL_REFS / 4 {
            parallel::join(|| self.node(left, to_left, depth + 1), || self.node(right, rest - to_left, depth + 1))
        } else {
            (self.node(left, to_left, depth + 1), self.node(right, rest - to_left, depth + 1))
        };
        l.extend(r);
        l
    }

    /// The node's two sides, by the best object or spatial split, or `None` if it has none.
    fn split(&self, node: &Side, budget: usize) -> Option<(Side, Side)> {
        let (refs, bounds, centroids) = (node.refs.as_slice(), node.bounds, node.centroids);
        let (cgrid, sgrid) = (Grid::over(&centroids), Grid::over(&bounds));
        let bins = if refs.len() >= PARALLEL_REFS {
            let parts = parallel::map_chunks(refs, PARALLEL_REFS / 2, |c| bin(c, &cgrid, &sgrid));
            parts.into_iter().reduce(|a, b| a.merge(&b)).expect("at least one piece")
        } else {
            bin(refs, &cgrid, &sgrid)
        };
        let mut object = None;
        for axis in (0..3).filter(|&a| centroids.hi[a] > centroids.lo[a]) {
            sweep(axis, &bins.object[axis], &bins.counts[axis], &bins.counts[axis], usize::MAX, &mut object);
        }
        let overlap = object.map_or(f32::INFINITY, |b| b.left.aabb().intersection(&b.right.aabb()).surface_area());
        let mut spatial = None;
        if overlap >= self.min_overlap {
            for axis in (0..3).filter(|&a| bounds.hi[a] > bounds.lo[a]) {
                let max = refs.len() + budget;
                sweep(axis, &bins.spatial[axis], &bins.enter[axis], &bins.exit[axis], max, &mut spatial);
            }
        }
        match (object, spatial) {
            (o, Some(s)) if o.is_none_or(|o| s.cost < o.cost) => {
                Some(self.cut(refs, s.axis, sgrid.planes[s.bin][s.axis], s.counts))
            }
            (Some(o), _) => {
                let (mut l, mut r) = (Side::with_capacity(o.counts.0), Side::with_capacity(o.counts.1));
                for f in refs {
                    if cgrid.before(o.axis, f.centroid_on(o.axis), o.bin) { l.push(*f) } else { r.push(*f) }
                }
                (!l.refs.is_empty() && !r.refs.is_empty()).then_some((l, r))
            }
            (None, _) => None,
        }
    }

    /// The two sides of a spatial split at `plane` on `axis` (with about `counts` references): the
    /// references on one side go there, a large triangle's reference across the plane is cut in
    /// two, or goes whole to the side where that costs less (Stich et al.'s unsplitting), any
    /// other across it goes by its centroid, as binned.
    fn cut(&self, refs: &[Frag], axis: usize, plane: f32, counts: (usize, usize)) -> (Side, Side) {
        let (mut l, mut r, mut across) = (Side::with_capacity(counts.0), Side::with_capacity(counts.1), Vec::new());
        for f in refs {
            let large = is_large(f);
            let (lo, hi) = (f.min()[axis], f.max()[axis]);
            let to_left = if large && lo < plane && hi > plane {
                across.push(*f);
                continue;
            } else if large {
                hi <= plane
            } else {
                f.centroid_on(axis) < plane
            };
            if to_left { l.push(*f) } else { r.push(*f) }
        }
        for f in across {
            let whole = f.bounds();
            let v = (self.triangle)(f.index());
            let (cl, cr) = sides(v, whole, axis, plane);
            let (nl, nr) = (l.refs.len() as f32, r.refs.len() as f32);
            let (lb, rb) = (l.bounds.aabb(), r.bounds.aabb());
            let area = |b: Aabb| b.surface_area();
            let both = area(lb.union(&cl)) * (nl + 1.0) + area(rb.union(&cr)) * (nr + 1.0);
            let left = area(lb.union(&whole)) * (nl + 1.0) + area(rb) * nr;
            let right = area(lb) * nl + area(rb.union(&whole)) * (nr + 1.0);
            if cl.is_empty() || (right <= both && right <= left) {
                r.push(f);
            } else if cr.is_empty() || left <= both {
                l.push(f);
            } else {
                l.push(frag(&cl, f.index(), true));
                r.push(frag(&cr, f.index(), true));
            }
        }
        (l, r)
    }
}

/// The boxes of the parts of triangle `v` inside `part` (a box around the triangle or a piece of
/// it) below and above `plane` on `axis`, as [`clip_triangle`] gives them.
fn sides(v: [Vec3; 3], part: Aabb, axis: usize, plane: f32) -> (Aabb, Aabb) {
    let (mut below, mut above) = (part, part);
    below.max[axis] = plane;
    above.min[axis] = plane;
    if part != Aabb::from_points(v) {
        return (clip_triangle(v, &below), clip_triangle(v, &above));
    }
    // The whole triangle: its box's planes cut nothing, and one pass over its edges gives both
    // sides, the same polygons that clipping against the two half-boxes gives in twelve passes.
    let (mut b, mut a) = (Polygon::empty(), Polygon::empty());
    Polygon::triangle(v).split_into(axis, plane as f64, &mut b, &mut a);
    (b.bounds().intersection(&below), a.bounds().intersection(&above))
}

/// One pass over `refs`: object bins by centroid on `cgrid`; spatial bins on `sgrid`, a large
/// triangle's reference in every bin its box crosses (its box cut to each bin's slab: only to
/// choose a plane by; the cut itself clips the triangle), any other reference, which is never cut,
/// whole in its centroid's bin.
fn bin(refs: &[Frag], cgrid: &Grid, sgrid: &Grid) -> Bins {
    let mut bins = Bins::new();
    for r in refs {
        let (lo, hi, c) = (r.min(), r.max(), r.centroid());
        let cb = cgrid.bins(c);
        for (axis, &k) in cb.iter().enumerate() {
            bins.object[axis][k].add(lo, hi);
            bins.counts[axis][k] += 1;
        }
        if !is_large(r) {
            let sb = sgrid.bins(c);
            for (axis, &k) in sb.iter().enumerate() {
                bins.spatial[axis][k].add(lo, hi);
                bins.enter[axis][k] += 1;
                bins.exit[axis][k] += 1;
            }
            continue;
        }
        let (first, last) = (sgrid.bins(lo), sgrid.bins(hi));
        for axis in 0..3 {
            let (a, b) = (first[axis], last[axis]);
            bins.enter[axis][a] += 1;
            bins.exit[axis][b] += 1;
            if a >= b {
                bins.spatial[axis][a].add(lo, hi);
                continue;
            }
            // The part in each bin: the box, its coordinate on `axis` cut to the bin's planes.
            let on = AXIS[axis];
            bins.spatial[axis][a].add(lo, Vec3A::select(on, sgrid.planes[a + 1], hi));
            for k in a + 1..b {
                bins.spatial[axis][k]
                    .add(Vec3A::select(on, sgrid.planes[k], lo), Vec3A::select(on, sgrid.planes[k + 1], hi));
            }
            bins.spatial[axis][b].add(Vec3A::select(on, sgrid.planes[b], lo), hi);
        }
    }
    bins
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An `n` by `n` grid of flat right triangles of legs `size`, one per unit square, in the
    /// plane z = 0.
    fn grid(n: usize, size: f32) -> Vec<[Vec3; 3]> {
        (0..n * n)
            .map(|k| {
                let o = Vec3::new((k % n) as f32, (k / n) as f32, 0.0);
                [o, o + Vec3::new(size, 0.0, 0.0), o + Vec3::new(0.0, size, 0.0)]
            })
            .collect()
    }

    fn cuts(tris: &[[Vec3; 3]], levels: u32) -> Option<Fragments> {
        spatial_cuts(tris.len(), |i| TriangleBox::of(&tris[i]), |i| tris[i as usize], levels)
    }

    #[test]
    fn a_long_triangle_is_cut_and_its_pieces_cover_it() {
        let mut tris = grid(40, 0.5);
        // Corner to corner over the grid, a little above it; alone, it does not waste enough to
        // make the spatial splits run.
        let long = [Vec3::new(0.0, 0.0, 1.0), Vec3::new(40.0, 40.0, 1.0), Vec3::new(40.0, 39.0, 2.0)];
        tris.push(long);
        assert_eq!(cuts(&tris, 6), None);
        // Two more make it.
        let last = (tris.len() - 1) as u32;
        tris.push([Vec3::new(0.0, 40.0, 0.5), Vec3::new(40.0, 0.0, 0.5), Vec3::new(39.0, 0.0, 1.5)]);
        tris.push([Vec3::new(0.0, 20.0, 1.5), Vec3::new(40.0, 21.0, 1.5), Vec3::new(40.0, 22.0, 0.5)]);
        let f = cuts(&tris, 6).expect("the long triangles cut");
        let pieces: Vec<Aabb> = f.owner.iter().zip(&f.boxes).filter(|(o, _)| **o == last).map(|(_, b)| *b).collect();
        assert!(pieces.len() >= 4, "{} pieces", pieces.len());
        let own = Aabb::from_points(long);
        assert!(pieces.iter().all(|p| own.contains_box(p)));
        let area: f32 = pieces.iter().map(Aabb::surface_area).sum();
        assert!(area < 0.5 * own.surface_area(), "{area}");
        // Points sampled on the triangle, edges included, lie in some piece.
        for k in 0..300 {
            let (a, b) = ((k % 20) as f32 / 19.0, (k / 20) as f32 / 14.0);
            let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
            let p = long[0] + (long[1] - long[0]) * a + (long[2] - long[0]) * b;
            assert!(pieces.iter().any(|q| q.contains_point(p)), "{p} in no piece");
        }
        // Every small triangle is there once, whole.
        for i in 0..last {
            let mine: Vec<&Aabb> = f.owner.iter().zip(&f.boxes).filter(|(o, _)| **o == i).map(|(_, b)| b).collect();
            assert_eq!(mine.len(), 1, "triangle {i}");
            assert_eq!(*mine[0], Aabb::from_points(tris[i as usize]), "triangle {i}");
        }
        // The same fragments in the same order, again.
        assert_eq!(cuts(&tris, 6), Some(f));
    }

    #[test]
    fn a_whole_triangle_is_cut_as_clipping_cuts_it() {
        let mut seed = 7u32;
        let mut next = move || {
            seed = seed.wrapping_mul(1664525).wrapping_add(1013904223);
            (seed >> 8) as f32 / (1 << 24) as f32 * 20.0 - 10.0
        };
        for k in 0..2000 {
            let v = [0, 1, 2].map(|_| Vec3::new(next(), next(), next()));
            let own = Aabb::from_points(v);
            let axis = k % 3;
            let plane = own.min[axis] + (own.max[axis] - own.min[axis]) * (next() + 10.0) / 20.0;
            let (mut below, mut above) = (own, own);
            below.max[axis] = plane;
            above.min[axis] = plane;
            assert_eq!(sides(v, own, axis, plane), (clip_triangle(v, &below), clip_triangle(v, &above)), "{v:?}");
        }
    }

    #[test]
    fn nothing_is_cut_without_levels_or_large_triangles() {
        // Tiny triangles: none wastes 1/100 000 of the scene's area.
        let tris = grid(100, 0.1);
        assert_eq!(cuts(&tris, 6), None);
        let mut tris = grid(40, 0.5);
        tris.push([Vec3::ZERO, Vec3::new(40.0, 40.0, 1.0), Vec3::new(40.0, 39.0, 2.0)]);
        assert_eq!(cuts(&tris, 0), None);
    }

    #[test]
    fn the_cuts_stay_within_their_budget() {
        // Long triangles fanned across the whole scene: every split would cut them all, and the
        // budget (80 references for these 160 triangles) runs out after the first.
        let mut tris = grid(10, 0.5);
        for k in 0..60 {
            let y = k as f32 * 0.15;
            tris.push([Vec3::new(0.0, y, 0.5), Vec3::new(10.0, 10.0 - y, 0.5), Vec3::new(10.0, 10.0 - y, 0.7)]);
        }
        let f = cuts(&tris, 12).expect("cuts");
        let limit = tris.len() + (tris.len() as f64 * MAX_EXTRA) as usize;
        assert!(f.boxes.len() <= limit, "{} fragments for {} triangles", f.boxes.len(), tris.len());
        assert!(f.boxes.len() > tris.len());
    }
}
