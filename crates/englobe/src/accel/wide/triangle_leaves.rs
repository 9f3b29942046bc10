//! One ray's leaf tests in a [`TriangleBvh`](super::triangle_bvh::TriangleBvh): blocks of four
//! triangles tested at once ([`super::triangles`]), the closest hit kept, the caller's filter
//! asked.
//!
//! The lanes the SIMD test leaves undecided (a ray through an edge or a vertex, a scene at an
//! extreme scale) need the scalar test, and that is a call. A call anywhere in the walk's loop
//! costs every query, not only the rare ones that make it: x86-64 gives every vector register to
//! the caller to save, so the compiler keeps the walk's ray constants in memory for the whole loop
//! and reloads them at every node (5-10 % of the closest-hit rays' speed, see
//! `docs/performance.md`). So the leaves only note such lanes, in a list of [`DEFERRED`], and the
//! walk has them decided once it has ended ([`Leaves::settle_closest`], [`Leaves::settle_any`]).
//! A query that meets more than its list holds walks again ([`closest_hit`], [`any_hit`]), from
//! where the first walk left its interval, with a list as long as the number it met: the second
//! walk meets no more of them, since it visits a part of what the first visited (its interval is
//! never longer) and whether a lane is decided does not depend on the interval. That list is kept
//! per thread and grown once, as the deep trees' stack is (see [`super::traverse`]): no query
//! allocates in the steady state.
//!
//! The answers are those of deciding each lane when it is met. A closest-hit walk that has not
//! decided a lane keeps a longer interval, so it visits every node it would have visited, and
//! perhaps more; those it would have skipped, the ray enters beyond the lane's hit, and every hit
//! in them lies beyond it too (a hit lies in its triangle's box, see [`super::triangles`]): none is
//! closer. An any-hit walk that meets a hit it can decide needs no other.

use std::cell::Cell;
use std::mem::MaybeUninit;

use super::kernels::NodeKernel;
use super::traverse::Leaves;
use super::triangles::{BlockHits, TriBlock, TriRay, UNUSED, intersect_block};
use crate::accel::{Counters, Hit, HitFilter};
use crate::geom::prefetch::prefetch;
use crate::{PrimHit, Ray};

/// The undecided lanes a query notes in its first walk.
pub const DEFERRED: usize = 8;

/// An undecided lane: its block's index and the lane.
type Noted = (u32, u8);

thread_local! {
    /// The list of the walks after a first one that met too many undecided lanes, reused from
    /// query to query. A query nested inside another's filter finds it taken and uses a fresh one.
    static LONG_LIST: Cell<Vec<MaybeUninit<Noted>>> = const { Cell::new(Vec::new()) };
}

/// A query's view of the triangle blocks, its closest hit so far, the caller's filter, and the
/// lanes it has not decided yet.
pub(super) struct TriangleLeaves<'a, F> {
    blocks: &'a [TriBlock],
    source: &'a Ray,
    /// The closest hit so far.
    best: Option<Hit>,
    t_max: f32,
    filter: F,
    /// The list of undecided lanes, its first `min(met, list.len())` entries written; the rest
    /// are left as they were (a query does not clear its list: most never note a lane).
    list: &'a mut [MaybeUninit<Noted>],
    /// The undecided lanes met, noted or not.
    met: usize,
}

/// [`intersect_block`] of `block` within `ray.t_min..=t_max`, its used lanes counted as exact
/// tests.
#[inline(always)]
pub(super) fn counted_block_test<C: Counters>(
    block: &TriBlock,
    ray: &TriRay,
    t_max: f32,
    counters: &mut C,
) -> Option<BlockHits> {
    for _ in 0..block.used() {
        counters.exact_test();
    }
    intersect_block(block, ray, t_max)
}

/// The closest hit of `source` within `source.t_min..=t_max` among `blocks`, accepted by `filter`,
/// as `walk` finds it (a walk of the tree that ends with [`Leaves::settle_closest`]).
#[inline(always)]
pub(super) fn closest_hit<F: HitFilter<Hit>>(
    blocks: &[TriBlock],
    source: &Ray,
    t_max: f32,
    filter: F,
    mut walk: impl FnMut(&mut TriangleLeaves<'_, F>),
) -> Option<Hit> {
    let mut list = [MaybeUninit::uninit(); DEFERRED];
    let mut leaves = TriangleLeaves::new(blocks, source, t_max, filter, &mut list);
    walk(&mut leaves);
    if leaves.met <= DEFERRED {
        return leaves.best;
    }
    let TriangleLeaves { best, t_max, filter, met, .. } = leaves;
    closest_hit_again(blocks, source, (best, t_max, filter), met, &mut walk)
}

/// The walks that follow one that met `met` undecided lanes, more than its list held, from where
/// it left the closest hit, the interval and the filter: each with a list as long as the number
/// the walk before met, on the thread's long list. A second walk never meets more (see the module
/// documentation); the loop would go on if it did.
#[cold]
#[inline(never)]
fn closest_hit_again<F: HitFilter<Hit>>(
    blocks: &[TriBlock],
    source: &Ray,
    (mut best, mut t_max, mut filter): (Option<Hit>, f32, F),
    mut met: usize,
    walk: &mut impl FnMut(&mut TriangleLeaves<'_, F>),
) -> Option<Hit> {
    let mut list = LONG_LIST.with(Cell::take);
    loop {
        if list.len() < met {
            list.resize(met, MaybeUninit::uninit());
        }
        let mut leaves = TriangleLeaves::new(blocks, source, t_max, filter, &mut list[..met]);
        leaves.best = best;
        walk(&mut leaves);
        let room = met;
        (best, t_max, filter, met) = (leaves.best, leaves.t_max, leaves.filter, leaves.met);
        if met <= room {
            break;
        }
    }
    LONG_LIST.with(|kept| kept.set(list));
    best
}

/// An any-hit walk of the tree for [`any_hit_with`]: one that ends with [`Leaves::settle_any`].
/// A trait rather than a closure, so that a walk compiled with the caller's instruction set can
/// be inlined into it (a closure's body is compiled without the caller's `#[target_feature]`s, see
/// [`super::traverse`]): how [`super::triangle_query`] walks.
pub(super) trait AnyWalk<F> {
    /// Whether the walk finds a hit.
    fn walk(&mut self, leaves: &mut TriangleLeaves<'_, F>) -> bool;
    /// The same walk, made again by [`any_hit_again`], a function compiled apart from the one that
    /// made the first: a walk inlined into its caller has it call a compiled copy instead.
    #[inline(always)]
    fn walk_again(&mut self, leaves: &mut TriangleLeaves<'_, F>) -> bool {
        self.walk(leaves)
    }
}

/// A closure as an [`AnyWalk`].
struct Closure<W>(W);

impl<F, W: FnMut(&mut TriangleLeaves<'_, F>) -> bool> AnyWalk<F> for Closure<W> {
    #[inline(always)]
    fn walk(&mut self, leaves: &mut TriangleLeaves<'_, F>) -> bool {
        (self.0)(leaves)
    }
}

/// Whether `source` hits one of `blocks` within `source.t_min..=t_max`, the hit accepted by
/// `filter`, as `walk` finds it (a walk of the tree that ends with [`Leaves::settle_any`]).
#[inline(always)]
pub(super) fn any_hit<F: HitFilter<Hit>>(
    blocks: &[TriBlock],
    source: &Ray,
    t_max: f32,
    filter: F,
    walk: impl FnMut(&mut TriangleLeaves<'_, F>) -> bool,
) -> bool {
    any_hit_with(blocks, source, t_max, filter, &mut Closure(walk))
}

/// [`any_hit`] with the walk an [`AnyWalk`].
#[inline(always)]
pub(super) fn any_hit_with<F: HitFilter<Hit>>(
    blocks: &[TriBlock],
    source: &Ray,
    t_max: f32,
    filter: F,
    walk: &mut impl AnyWalk<F>,
) -> bool {
    let mut list = [MaybeUninit::uninit(); DEFERRED];
    let mut leaves = TriangleLeaves::new(blocks, source, t_max, filter, &mut list);
    if walk.walk(&mut leaves) {
        return true;
    }
    if leaves.met <= DEFERRED {
        return false;
    }
    let TriangleLeaves { filter, met, .. } = leaves;
    any_hit_again(blocks, source, t_max, filter, met, walk)
}

/// The walks that follow an any-hit walk that found no hit and met `met` undecided lanes, more
/// than its list held: as in [`closest_hit_again`].
#[cold]
#[inline(never)]
fn any_hit_again<F: HitFilter<Hit>>(
    blocks: &[TriBlock],
    source: &Ray,
    t_max: f32,
    mut filter: F,
    mut met: usize,
    walk: &mut impl AnyWalk<F>,
) -> bool {
    let mut list = LONG_LIST.with(Cell::take);
    let hit = loop {
        if list.len() < met {
            list.resize(met, MaybeUninit::uninit());
        }
        let mut leaves = TriangleLeaves::new(blocks, source, t_max, filter, &mut list[..met]);
        if walk.walk_again(&mut leaves) {
            break true;
        }
        let room = met;
        (filter, met) = (leaves.filter, leaves.met);
        if met <= room {
            break false;
        }
    };
    LONG_LIST.with(|kept| kept.set(list));
    hit
}

impl<'a, F: HitFilter<Hit>> TriangleLeaves<'a, F> {
    /// The leaf tests of `source` in `blocks`, within `source.t_min..=t_max`, noting undecided
    /// lanes in `list`.
    #[inline(always)]
    fn new(blocks: &'a [TriBlock], source: &'a Ray, t_max: f32, filter: F, list: &'a mut [MaybeUninit<Noted>]) -> Self {
        TriangleLeaves { blocks, source, best: None, t_max, filter, list, met: 0 }
    }

    /// The undecided lanes the list holds.
    #[inline(always)]
    fn noted(&self) -> usize {
        self.met.min(self.list.len())
    }

    /// `block` tested (its used lanes counted as exact tests) within the interval: `None` if no
    /// lane passed its edge tests.
    #[inline(always)]
    fn test<C: Counters>(&self, block: &TriBlock, ray: &TriRay, counters: &mut C) -> Option<BlockHits> {
        counted_block_test(block, ray, self.t_max, counters)
    }

    /// Notes the undecided lanes `special` of the block at `index`, as far as the list holds them.
    #[inline(always)]
    fn defer(&mut self, index: usize, block: &TriBlock, special: u32) {
        let mut mask = special;
        while mask != 0 {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            // An unused lane repeats the first, which is undecided too.
            if block.ids[lane] == UNUSED {
                continue;
            }
            if let Some(slot) = self.list.get_mut(self.met) {
                slot.write((index as u32, lane as u8));
            }
            self.met += 1;
        }
    }

    /// The scalar test's hit of noted lane `i` (below [`TriangleLeaves::noted`]) within the
    /// interval, if any.
    #[inline(always)]
    fn scalar_hit(&self, i: usize) -> Option<Hit> {
        assert!(i < self.noted());
        // SAFETY: `defer` wrote every entry below `noted()`, in order, before counting it.
        let (index, lane) = unsafe { self.list[i].assume_init() };
        scalar_hit(self.blocks, self.source, index, lane as usize, self.t_max)
    }

    /// Offers the noted lanes' hits.
    #[cold]
    #[inline(never)]
    fn decide_closest(&mut self) {
        for i in 0..self.noted() {
            if let Some(hit) = self.scalar_hit(i) {
                offer(&mut self.best, &mut self.t_max, &mut self.filter, hit);
            }
        }
    }

    /// Whether a noted lane is hit (and its hit accepted).
    #[cold]
    #[inline(never)]
    fn decide_any(&mut self) -> bool {
        for i in 0..self.noted() {
            if let Some(hit) = self.scalar_hit(i)
                && (F::ACCEPTS_ALL || self.filter.accept(&hit))
            {
                return true;
            }
        }
        false
    }
}

/// The scalar test's hit of `source` on lane `lane` of block `index` within
/// `source.t_min..=t_max`, if any: how a lane the SIMD test leaves undecided is decided.
#[inline(always)]
pub(super) fn scalar_hit(blocks: &[TriBlock], source: &Ray, index: u32, lane: usize, t_max: f32) -> Option<Hit> {
    let block = &blocks[index as usize];
    TriRay::scalar(source, block, lane, t_max).map(|h| Hit { t: h.t, prim: block.ids[lane], u: h.u, v: h.v })
}

/// Keeps the hit on triangle `prim` in `best` if it is closer, or as close with a lower index
/// (the rule of [`crate::accel::HitRecord::offer`]), and the filter accepts it; shrinks `t_max`
/// to it.
#[inline(always)]
fn offer<F: HitFilter<Hit>>(best: &mut Option<Hit>, t_max: &mut f32, filter: &mut F, hit: Hit) {
    let better = match *best {
        None => true,
        Some(b) => hit.t < b.t || (hit.t == b.t && hit.prim < b.prim),
    };
    if better && (F::ACCEPTS_ALL || filter.accept(&hit)) {
        *best = Some(hit);
        *t_max = hit.t;
    }
}

impl<C: Counters, F: HitFilter<Hit>> Leaves<C> for TriangleLeaves<'_, F> {
    /// The triangle test's constants of the ray.
    type Prepared = TriRay;

    #[inline(always)]
    fn prepare<K: NodeKernel>(&self) -> TriRay {
        #[cfg(target_arch = "x86_64")]
        if K::AVX {
            // SAFETY: a kernel that says so runs only where AVX is (`NodeKernel::AVX`).
            return unsafe { TriRay::new_avx(self.source) };
        }
        TriRay::new(self.source)
    }

    #[inline(always)]
    fn closest(&mut self, ray: &TriRay, first: u32, count: u32, counters: &mut C) {
        let blocks = self.blocks;
        let first = first as usize;
        for (i, block) in blocks[first..first + count as usize].iter().enumerate() {
            let Some(hits) = self.test(block, ray, counters) else { continue };
            let mut mask = hits.hit;
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if block.ids[lane] != UNUSED {
                    let PrimHit { t, u, v } = hits.lane(lane);
                    let hit = Hit { t, prim: block.ids[lane], u, v };
                    offer(&mut self.best, &mut self.t_max, &mut self.filter, hit);
                }
            }
            if hits.special != 0 {
                self.defer(first + i, block, hits.special);
            }
        }
    }

    #[inline(always)]
    fn settle_closest(&mut self) {
        if self.met != 0 {
            self.decide_closest();
        }
    }

    #[inline(always)]
    fn t_max(&self) -> f32 {
        self.t_max
    }

    #[inline(always)]
    fn prefetch(&self, first: u32) {
        prefetch(self.blocks, first);
    }

    #[inline(always)]
    fn any(&mut self, ray: &TriRay, first: u32, count: u32, counters: &mut C) -> bool {
        let blocks = self.blocks;
        let first = first as usize;
        for (i, block) in blocks[first..first + count as usize].iter().enumerate() {
            let Some(hits) = self.test(block, ray, counters) else { continue };
            if F::ACCEPTS_ALL {
                // An unused lane repeats a used one: its hit is that lane's.
                if hits.hit != 0 {
                    return true;
                }
            } else {
                let mut mask = hits.hit;
                while mask != 0 {
                    let lane = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let PrimHit { t, u, v } = hits.lane(lane);
                    let hit = Hit { t, prim: block.ids[lane], u, v };
                    if block.ids[lane] != UNUSED && self.filter.accept(&hit) {
                        return true;
                    }
                }
            }
            if hits.special != 0 {
                self.defer(first + i, block, hits.special);
            }
        }
        false
    }

    #[inline(always)]
    fn settle_any(&mut self) -> bool {
        self.met != 0 && self.decide_any()
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::wide::kernels::Portable;
    use crate::accel::{NoCount, NoFilter};
    use crate::shapes::{WatertightRay, intersect_triangle};

    /// Fans of triangles around the vertical line through the origin, each fan at its own height,
    /// in blocks of four: a ray down that line meets their shared vertices, every lane undecided.
    fn fans(triangles: usize) -> (Vec<[Vec3; 3]>, Vec<TriBlock>) {
        let tris: Vec<[Vec3; 3]> = (0..triangles)
            .map(|k| {
                let z = -0.25 * ((k * 7) % 5) as f32;
                let at = |i: usize| {
                    let a = i as f32 * std::f32::consts::TAU / 6.0;
                    Vec3::new(a.cos(), a.sin(), z)
                };
                [Vec3::new(0.0, 0.0, z), at(k), at(k + 1)]
            })
            .collect();
        let indexed: Vec<(u32, [Vec3; 3])> = tris.iter().enumerate().map(|(i, v)| (i as u32, *v)).collect();
        (tris, indexed.chunks(4).map(TriBlock::new).collect())
    }

    /// The scalar test's closest hit among `tris`, the lower index first among equal distances.
    fn brute_force(tris: &[[Vec3; 3]], ray: &Ray) -> Option<(f32, u32)> {
        let w = WatertightRay::new(ray);
        let hits = tris
            .iter()
            .enumerate()
            .filter_map(|(i, [a, b, c])| intersect_triangle(ray, &w, *a, *b, *c).map(|h| (h.t, i as u32)));
        hits.min_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)))
    }

    #[test]
    fn more_undecided_lanes_than_the_list_holds_take_a_second_walk_with_the_same_answer() {
        for triangles in [3, 8, 9, 20, 41] {
            let (tris, blocks) = fans(triangles);
            let ray = Ray::new(Vec3::new(0.0, 0.0, 1.0), -Vec3::Z);
            // The walk: every block of the "tree" in one leaf.
            let mut walks = 0;
            let best = closest_hit(&blocks, &ray, ray.t_max, NoFilter, |leaves| {
                walks += 1;
                let prepared = Leaves::<NoCount>::prepare::<Portable>(leaves);
                Leaves::<NoCount>::closest(leaves, &prepared, 0, blocks.len() as u32, &mut NoCount);
                Leaves::<NoCount>::settle_closest(leaves);
            });
            assert_eq!(best.map(|h| (h.t, h.prim)), brute_force(&tris, &ray), "{triangles} triangles");
            assert_eq!(walks, if triangles > DEFERRED { 2 } else { 1 }, "{triangles} triangles");

            for (t_max, expected) in [(f32::INFINITY, true), (0.5, false)] {
                let short = Ray::segment(ray.origin(), ray.dir(), 0.0, t_max);
                let mut walks = 0;
                let hit = any_hit(&blocks, &short, t_max, NoFilter, |leaves| {
                    walks += 1;
                    let prepared = Leaves::<NoCount>::prepare::<Portable>(leaves);
                    Leaves::<NoCount>::any(leaves, &prepared, 0, blocks.len() as u32, &mut NoCount)
                        || Leaves::<NoCount>::settle_any(leaves)
                });
                assert_eq!(hit, expected, "{triangles} triangles, t_max {t_max}");
                assert_eq!(walks, if !expected && triangles > DEFERRED { 2 } else { 1 }, "{triangles}, {t_max}");
            }
        }
    }
}
