//! A packet's leaf tests in a [`TriangleBvh`]: with AVX-512 or AVX2, each triangle against the
//! whole packet at once ([`WholePacket`], see [`super::packet_triangles`]); otherwise (the
//! portable walk) each ray against the blocks alone ([`RayByRay`], the single-ray leaf test of
//! [`super::triangle_leaves`]).
//!
//! The whole-packet walk has no call in its loop. x86-64 gives every vector register to the
//! caller to save, so a call anywhere in the loop, even one never made, has the compiler keep the
//! walk's state in memory (see [`super::triangle_leaves`], and `docs/performance.md`: without
//! them, primary packets ran 4-10 % faster on closest hits). So the triangle test is compiled
//! into the walk, and:
//!
//! * the pairs of ray and triangle it leaves undecided (a ray through an edge or a vertex) are
//!   noted, and decided by the scalar test when the walk has ended
//!   ([`TrianglePacket::settle_closest`], [`TrianglePacket::settle_any`]). The answers are those
//!   of deciding each pair when it is met, for the reasons [`super::triangle_leaves`] gives. A
//!   ray that meets more pairs than the list holds is asked again alone;
//! * a packet whose rays do not share the watertight test's axes (which the whole-packet test
//!   needs; the tiles of an image that straddle a change of the rays' largest axis) finds it out
//!   at its first leaf, ends its walk there, and each ray is asked again alone.
//!
//! A ray asked again alone gets the single-ray query's answer, its own, which is the closest of
//! every hit, so of any the packet found for it.

use super::dispatch;
use super::kernels::Portable;
use super::node::{NodeRay, reach};
use super::packet::PacketLeaves;
use super::packet_kernels::{Lanes, PACKET, PacketRays};
#[cfg(target_arch = "x86_64")]
use super::packet_triangles::BlockTest;
use super::packet_triangles::{PacketBest, PacketTriRays};
use super::traverse::{Leaves, take_lowest};
use super::triangle_bvh::TriangleBvh;
use super::triangle_leaves;
#[cfg(target_arch = "x86_64")]
use super::triangles::TriRay;
#[cfg(target_arch = "x86_64")]
use crate::PrimHit;
use crate::accel::{Counters, Hit, NoFilter};
use crate::geom::prefetch::prefetch;
#[cfg(target_arch = "x86_64")]
use std::marker::PhantomData;

/// The undecided pairs a packet notes in its walk.
const DEFERRED: usize = 16;

/// The rays of a packet and their closest hits so far, as structures of arrays, tested at leaves
/// by `T` ([`WholePacket`] or [`RayByRay`]).
pub(super) struct TrianglePacket<'a, T> {
    /// The rays, prepared for node tests (their origins, inverse directions and `t_min` are read
    /// by the whole-packet triangle test too; the single-ray tests take each ray back out).
    packet: &'a PacketRays,
    bvh: &'a TriangleBvh,
    pub(super) best: PacketBest,
    limits: Lanes,
    test: T,
}

/// Each triangle tested against the whole packet (with the block test `B`: AVX-512's or AVX2's),
/// with the pairs the test leaves undecided.
#[cfg(target_arch = "x86_64")]
pub(super) struct WholePacket<B> {
    /// The rays walked.
    active: u32,
    /// Their triangle constants, prepared at the first leaf: a packet that reaches none (as most
    /// of those around a mesh framed by the camera) never pays for them.
    tri: Option<PacketTriRays>,
    /// The undecided pairs noted: a block's index, and `16 * lane + ray`.
    noted: [(u32, u8); DEFERRED],
    /// How many of `noted` are used.
    len: usize,
    /// The rays asked again alone when the walk has ended: those that met more undecided pairs
    /// than `noted` holds, or all of them if they do not share the test's axes.
    again: u32,
    test: PhantomData<B>,
}

/// Each ray tested against the blocks alone, with the single-ray leaf test.
pub(super) struct RayByRay;

impl<'a, T> TrianglePacket<'a, T> {
    /// The state of a packet within `limits` (see [`reach`]): no hit yet.
    pub(super) fn new(bvh: &'a TriangleBvh, packet: &'a PacketRays, limits: Lanes, test: T) -> Self {
        TrianglePacket { packet, bvh, best: PacketBest::new(&packet.t_max), limits, test }
    }

    /// Walks the subtree of `reference` with each ray of `rays` alone (see
    /// [`PacketLeaves::alone`]).
    #[inline(never)]
    fn alone_walks<C: Counters>(&mut self, reference: u32, mut rays: u32, closest: bool, counters: &mut C) -> u32 {
        let bvh = self.bvh;
        let mut found = 0;
        while rays != 0 {
            let i = take_lowest(&mut rays);
            let source = &self.packet.ray(i);
            let node_ray = NodeRay::new(source);
            let (blocks, t_max) = (bvh.blocks(), self.best.t.0[i]);
            if closest {
                let best = triangle_leaves::closest_hit(blocks, source, t_max, NoFilter, |lane| {
                    dispatch::closest(bvh.isa(), bvh.nodes(), bvh.depth(), reference, &node_ray, lane, counters)
                });
                if let Some(hit) = best {
                    self.best.offer(i, hit);
                }
                self.limits.0[i] = reach(self.best.t.0[i]);
            } else {
                let limit = reach(source.t_max);
                if triangle_leaves::any_hit(blocks, source, t_max, NoFilter, |lane| {
                    dispatch::any(bvh.isa(), bvh.nodes(), bvh.depth(), reference, &node_ray, limit, lane, counters)
                }) {
                    found |= 1 << i;
                }
            }
        }
        found
    }
}

#[cfg(target_arch = "x86_64")]
impl<B: BlockTest> WholePacket<B> {
    /// The whole-packet test of the rays of `active`.
    pub(super) fn new(active: u32) -> Self {
        WholePacket { active, tri: None, noted: [(0, 0); DEFERRED], len: 0, again: 0, test: PhantomData }
    }
}

#[cfg(target_arch = "x86_64")]
impl<B: BlockTest> TrianglePacket<'_, WholePacket<B>> {
    /// Tests the blocks from `first` against the rays of `rays` a whole packet at a time; returns
    /// the rays that hit one (with `closest`, their closest hits are kept). Notes the pairs left
    /// undecided.
    ///
    /// # Safety
    /// The processor has `B`'s instruction set (the test is compiled into the caller, which
    /// should enable it).
    #[inline(always)]
    unsafe fn test_blocks<C: Counters>(
        &mut self,
        first: u32,
        count: u32,
        rays: u32,
        closest: bool,
        counters: &mut C,
    ) -> u32 {
        // (`ALONE` 0 leaves the other test out of the walk altogether.)
        if B::ALONE > 0 && rays.count_ones() <= B::ALONE {
            // SAFETY: the caller's guarantee: `B`'s instruction set, which has AVX.
            return unsafe { self.test_blocks_each(first, count, rays, closest, counters) };
        }
        if self.test.tri.is_none() {
            // SAFETY: the caller's guarantee: `B`'s instruction set.
            match unsafe { B::shared_axes(self.packet, self.test.active) } {
                Some(axes) => self.test.tri = Some(PacketTriRays::new(self.packet, self.test.active, axes)),
                None => return self.give_up(),
            }
        }
        // Borrowed field by field: the constants are read where they lie, not copied per leaf.
        let TrianglePacket { packet, bvh, best, test: WholePacket { tri: Some(tri), noted, len, again, .. }, .. } =
            self
        else {
            unreachable!("prepared above")
        };
        let mut found = 0;
        for (b, block) in bvh.blocks()[first as usize..(first + count) as usize].iter().enumerate() {
            for _ in 0..block.used() * rays.count_ones() {
                counters.exact_test();
            }
            // Any hit: the rays that found an occluder are done.
            let pending = if closest { rays } else { rays & !found };
            // SAFETY: the caller's guarantee.
            let (hit, mut special) = unsafe { B::block(block, packet, tri, pending, best, closest) };
            found |= hit;
            while special != 0 {
                let bit = special.trailing_zeros();
                special &= special - 1;
                note((noted, len, again), first + b as u32, bit as u8);
            }
            if !closest && found == rays {
                break;
            }
        }
        found
    }

    /// [`Self::test_blocks`] for a leaf that few rays reach ([`BlockTest::ALONE`]): each ray
    /// against the blocks with the single-ray block test, four triangles at once, where the
    /// whole-packet test would run a vector of rays per triangle, most of its lanes idle. Both
    /// tests compute the scalar test's answer lane by lane, the hits are offered by the same
    /// rule and the undecided pairs noted alike, so a ray's answer does not depend on which test
    /// a leaf took.
    ///
    /// # Safety
    /// The processor has AVX (the test is compiled into the caller, which should enable it).
    #[inline(always)]
    unsafe fn test_blocks_each<C: Counters>(
        &mut self,
        first: u32,
        count: u32,
        rays: u32,
        closest: bool,
        counters: &mut C,
    ) -> u32 {
        let (mut found, mut rest) = (0, rays);
        while rest != 0 {
            let i = take_lowest(&mut rest);
            // SAFETY: the caller's guarantee.
            let r = unsafe { TriRay::new_avx(&self.packet.ray(i)) };
            for (b, block) in self.bvh.blocks()[first as usize..(first + count) as usize].iter().enumerate() {
                let Some(hits) = triangle_leaves::counted_block_test(block, &r, self.best.t.0[i], counters) else {
                    continue;
                };
                // An unused lane repeats the first: the whole-packet test skips it.
                let used = block.used_lanes();
                let mut special = hits.special & used;
                while special != 0 {
                    let lane = take_lowest(&mut special);
                    let WholePacket { noted, len, again, .. } = &mut self.test;
                    note((noted, len, again), first + b as u32, (PACKET * lane + i) as u8);
                }
                let mut hit = hits.hit & used;
                if hit == 0 {
                    continue;
                }
                found |= 1 << i;
                if !closest {
                    break;
                }
                while hit != 0 {
                    let lane = take_lowest(&mut hit);
                    let PrimHit { t, u, v } = hits.lane(lane);
                    self.best.offer(i, Hit { t, prim: block.ids[lane], u, v });
                }
            }
        }
        found
    }

    /// Ends the walk of a packet whose rays do not share the test's axes (the tiles of an image
    /// that straddle a change of the rays' largest axis; rare): no box is entered any more, and
    /// every ray is asked again alone. Returns every ray as if it had hit, which ends an any-hit
    /// walk (the settling leaves them out of the answer).
    #[inline(always)]
    fn give_up(&mut self) -> u32 {
        self.test.again = self.test.active;
        self.limits = Lanes([f32::NEG_INFINITY; PACKET]);
        self.test.active
    }

    /// The scalar hit of a noted pair, with its ray's index, if that ray is one of `rays` and not
    /// asked again.
    fn noted_hit(&self, (block, bit): (u32, u8), rays: u32) -> Option<(usize, Hit)> {
        let (lane, i) = (bit as usize / PACKET, bit as usize % PACKET);
        if (rays & !self.test.again) >> i & 1 == 0 {
            return None;
        }
        let hit = triangle_leaves::scalar_hit(self.bvh.blocks(), &self.packet.ray(i), block, lane, self.best.t.0[i]);
        hit.map(|hit| (i, hit))
    }

    /// Decides the pairs the walk noted, and asks the rays that met too many again: each ray's
    /// closest hit is then its own query's.
    pub(super) fn settle_closest<C: Counters>(&mut self, counters: &mut C) {
        for k in 0..self.test.len {
            if let Some((i, hit)) = self.noted_hit(self.test.noted[k], u32::MAX) {
                self.best.offer(i, hit);
            }
        }
        let mut again = self.test.again;
        while again != 0 {
            let i = take_lowest(&mut again);
            // The query's answer is the closest of every hit, so of those the walk found too.
            if let Some(hit) = self.bvh.closest_hit_of_valid(&self.packet.ray(i), counters, NoFilter) {
                self.best.offer(i, hit);
            }
        }
    }

    /// The rays that hit something, from those the walk reports (`walked`): those it found a hit
    /// for and does not ask again, those that hit one of the pairs it noted, and those asked
    /// again that hit anything.
    pub(super) fn settle_any<C: Counters>(&self, walked: u32, counters: &mut C) -> u32 {
        let mut found = walked & !self.test.again;
        for &pair in &self.test.noted[..self.test.len] {
            if let Some((i, _)) = self.noted_hit(pair, !found) {
                found |= 1 << i;
            }
        }
        let mut again = self.test.again;
        while again != 0 {
            let i = take_lowest(&mut again);
            if self.bvh.any_hit_of_valid(&self.packet.ray(i), counters, NoFilter) {
                found |= 1 << i;
            }
        }
        found
    }
}

/// Notes the undecided pair `bit` (`16 * lane + ray`) of the block at `block` in a
/// [`WholePacket`]'s list (its pairs, how many it holds, and the rays asked again), or asks the
/// pair's ray again if the list is full.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn note((noted, len, again): (&mut [(u32, u8); DEFERRED], &mut usize, &mut u32), block: u32, bit: u8) {
    if *len < DEFERRED {
        noted[*len] = (block, bit);
        *len += 1;
    } else {
        *again |= 1 << (bit as usize % PACKET);
    }
}

/// How a [`TrianglePacket`]'s leaves are tested: [`WholePacket`] or [`RayByRay`].
pub(super) trait LeafTest: Sized {
    /// [`PacketLeaves::closest`].
    fn closest<C: Counters>(leaves: &mut TrianglePacket<'_, Self>, first: u32, count: u32, rays: u32, counters: &mut C);
    /// [`PacketLeaves::any`].
    fn any<C: Counters>(
        leaves: &mut TrianglePacket<'_, Self>,
        first: u32,
        count: u32,
        rays: u32,
        counters: &mut C,
    ) -> u32;
}

impl<C: Counters, T: LeafTest> PacketLeaves<C> for TrianglePacket<'_, T> {
    #[inline(always)]
    fn closest(&mut self, first: u32, count: u32, rays: u32, counters: &mut C) {
        T::closest(self, first, count, rays, counters);
    }

    #[inline(always)]
    fn any(&mut self, first: u32, count: u32, rays: u32, counters: &mut C) -> u32 {
        T::any(self, first, count, rays, counters)
    }

    #[inline(always)]
    fn limits(&self) -> &Lanes {
        &self.limits
    }

    #[inline(always)]
    fn prefetch(&self, first: u32) {
        prefetch(self.bvh.blocks(), first);
    }

    #[inline(always)]
    fn alone(&mut self, reference: u32, rays: u32, closest: bool, counters: &mut C) -> u32 {
        self.alone_walks(reference, rays, closest, counters)
    }
}

#[cfg(target_arch = "x86_64")]
impl<B: BlockTest> LeafTest for WholePacket<B> {
    #[inline(always)]
    fn closest<C: Counters>(
        leaves: &mut TrianglePacket<'_, Self>,
        first: u32,
        count: u32,
        mut rays: u32,
        counters: &mut C,
    ) {
        // SAFETY: a `WholePacket<B>` is only made for structures whose instruction set is `B`'s,
        // which the processor has (see `Isa`).
        unsafe { leaves.test_blocks(first, count, rays, true, counters) };
        // Every ray asked again (the packet gave up): its limits stay below zero, which ends
        // the walk.
        if leaves.test.again == leaves.test.active {
            return;
        }
        while rays != 0 {
            let i = take_lowest(&mut rays);
            leaves.limits.0[i] = reach(leaves.best.t.0[i]);
        }
    }

    #[inline(always)]
    fn any<C: Counters>(
        leaves: &mut TrianglePacket<'_, Self>,
        first: u32,
        count: u32,
        rays: u32,
        counters: &mut C,
    ) -> u32 {
        // SAFETY: as in `closest`.
        unsafe { leaves.test_blocks(first, count, rays, false, counters) }
    }
}

impl LeafTest for RayByRay {
    #[inline(always)]
    fn closest<C: Counters>(
        leaves: &mut TrianglePacket<'_, Self>,
        first: u32,
        count: u32,
        mut rays: u32,
        counters: &mut C,
    ) {
        // The rays' triangle constants are prepared at each leaf, in the portable form (a
        // closure is compiled without the walk's target features): only the portable walk
        // (processors without AVX2, and other architectures) comes here.
        while rays != 0 {
            let i = take_lowest(&mut rays);
            let source = leaves.packet.ray(i);
            let t_max = leaves.best.t.0[i];
            let best = triangle_leaves::closest_hit(leaves.bvh.blocks(), &source, t_max, NoFilter, |lane| {
                let ray = Leaves::<C>::prepare::<Portable>(lane);
                Leaves::<C>::closest(lane, &ray, first, count, counters);
                Leaves::<C>::settle_closest(lane);
            });
            if let Some(hit) = best {
                leaves.best.offer(i, hit);
            }
            leaves.limits.0[i] = reach(leaves.best.t.0[i]);
        }
    }

    #[inline(always)]
    fn any<C: Counters>(
        leaves: &mut TrianglePacket<'_, Self>,
        first: u32,
        count: u32,
        mut rays: u32,
        counters: &mut C,
    ) -> u32 {
        let mut found = 0;
        while rays != 0 {
            let i = take_lowest(&mut rays);
            let source = leaves.packet.ray(i);
            if triangle_leaves::any_hit(leaves.bvh.blocks(), &source, leaves.best.t.0[i], NoFilter, |lane| {
                let ray = Leaves::<C>::prepare::<Portable>(lane);
                Leaves::<C>::any(lane, &ray, first, count, counters) || Leaves::<C>::settle_any(lane)
            }) {
                found |= 1 << i;
            }
        }
        found
    }
}
