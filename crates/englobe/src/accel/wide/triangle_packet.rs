//! Packets of rays on [`TriangleBvh`]: up to [`PACKET`] rays walk the tree together (see
//! [`super::packet`]); at a leaf, each triangle is tested against the whole packet when the
//! processor has AVX-512 or AVX2 (see [`super::packet_triangles`]; a packet whose rays do not
//! share the watertight test's axes is asked again ray by ray, and with AVX2 a leaf that few of
//! its rays reach is tested ray by ray), each ray tests the blocks alone in the portable walk
//! (the leaves' tests are in `triangle_packet_leaves`). Either way every ray gets exactly the
//! answer of its own query. Batches choose, sixteen rays at a time, between a packet (coherent
//! rays: near origins, near directions) and single rays.

use std::marker::PhantomData;

use super::dispatch;
#[cfg(target_arch = "x86_64")]
use super::isa::Isa;
use super::packet;
use super::packet_kernels::{PACKET, PacketRays};
use super::packet_prep::PacketPrep;
use super::packet_triangles::PacketBest;
#[cfg(target_arch = "x86_64")]
use super::packet_triangles::{Avx2Block, Avx512Block};
use super::ray_packet::{PacketHits, RayPacket};
use super::triangle_bvh::TriangleBvh;
#[cfg(target_arch = "x86_64")]
use super::triangle_packet_leaves::WholePacket;
use super::triangle_packet_leaves::{RayByRay, TrianglePacket};
use crate::accel::interface::batch::{run_batch_packets, run_packets};
use crate::accel::{BatchSizeMismatch, Counters, Hit, NoCount, NoFilter};
use crate::{Aabb, Ray};

/// The valid rays of `rays` (at most [`PACKET`]), bit per ray ([`Ray::is_valid`]).
pub(crate) fn valid_mask(rays: &[Ray]) -> u32 {
    rays.iter().enumerate().fold(0, |m, (i, r)| m | (r.is_valid() as u32) << i)
}

/// Whether `rays` are coherent enough to walk the tree together: directions within about 25
/// degrees of the first ray's, and origins within a fiftieth of the tree's diagonal of its origin.
/// Rays that go apart visit the union of their paths, which costs more than walking alone.
pub fn coherent(rays: &[Ray], bounds: &Aabb) -> bool {
    let Some(first) = rays.first() else { return false };
    let d0 = first.dir().normalize_or_zero();
    let reach = 0.02 * (bounds.max - bounds.min).length();
    rays.iter().all(|r| {
        r.dir().normalize_or_zero().dot(d0) >= 0.9 && r.origin().distance(first.origin()) <= reach && r.is_valid()
    })
}

impl TriangleBvh {
    /// The closest hit of every ray, `hits[i]` for `rays[i]`, as [`TriangleBvh::closest_hit`]
    /// gives it, the rays walking the tree in packets of sixteen: for coherent rays (a camera's,
    /// shadow rays from neighbouring points towards one light), each node is tested once per
    /// packet instead of once per ray. The two slices must be as long.
    ///
    /// ```
    /// use englobe::{NoCount, Ray, TriangleBvh, Vec3};
    ///
    /// let bvh = TriangleBvh::from_triangles(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
    /// let rays: Vec<Ray> = (0..16).map(|i| Ray::new(Vec3::new(0.01 * i as f32, 0.1, 1.0), -Vec3::Z)).collect();
    /// let mut hits = vec![None; rays.len()];
    /// bvh.closest_hit_packet(&rays, &mut hits, &mut NoCount).unwrap();
    /// assert!(hits.iter().all(|h| h.is_some_and(|h| h.t == 1.0)));
    /// ```
    pub fn closest_hit_packet<C: Counters>(
        &self,
        rays: &[Ray],
        hits: &mut [Option<Hit>],
        counters: &mut C,
    ) -> Result<(), BatchSizeMismatch> {
        run_packets(rays, hits, PACKET, |rays, hits| self.closest_packet_of(rays, hits, counters))
    }

    /// Whether each ray hits anything, `mask[i]` for `rays[i]`, in packets of sixteen (see
    /// [`TriangleBvh::closest_hit_packet`]).
    pub fn any_hit_packet<C: Counters>(
        &self,
        rays: &[Ray],
        mask: &mut [bool],
        counters: &mut C,
    ) -> Result<(), BatchSizeMismatch> {
        run_packets(rays, mask, PACKET, |rays, mask| self.any_packet_of(rays, mask, counters))
    }

    /// The closest hit of every ray (see [`TriangleBvh::closest_hit`]), on several threads for
    /// large batches (see [`crate::accel::interface::batch`]); sixteen rays at a time, in a packet
    /// when they are coherent, one by one otherwise. The two slices must be as long.
    pub fn closest_hits(&self, rays: &[Ray], hits: &mut [Option<Hit>]) -> Result<(), BatchSizeMismatch> {
        run_batch_packets(
            rays,
            hits,
            PACKET,
            |rays| coherent(rays, &self.bounds()),
            |rays, hits| self.closest_packet_of(rays, hits, &mut NoCount),
            |r| self.closest_hit(r, &mut NoCount),
        )
    }

    /// Whether each ray hits anything, `mask[i]` for `rays[i]` (see [`TriangleBvh::closest_hits`]).
    pub fn any_hits(&self, rays: &[Ray], mask: &mut [bool]) -> Result<(), BatchSizeMismatch> {
        run_batch_packets(
            rays,
            mask,
            PACKET,
            |rays| coherent(rays, &self.bounds()),
            |rays, mask| self.any_packet_of(rays, mask, &mut NoCount),
            |r| self.any_hit(r, &mut NoCount),
        )
    }

    /// One packet of 1 to [`PACKET`] rays.
    fn closest_packet_of<C: Counters>(&self, rays: &[Ray], hits: &mut [Option<Hit>], counters: &mut C) {
        self.closest_packet_among(rays, u32::MAX, hits, counters);
    }

    /// One packet of 1 to [`PACKET`] rays, of which the valid ones of `among` (bit per ray) are
    /// traced; the others get no hit.
    pub(crate) fn closest_packet_among<C: Counters>(
        &self,
        rays: &[Ray],
        among: u32,
        hits: &mut [Option<Hit>],
        counters: &mut C,
    ) {
        debug_assert!(rays.len() <= PACKET && rays.len() == hits.len());
        let best = self.closest_query(PacketSource::Slice(rays), among, counters);
        for (i, h) in hits.iter_mut().enumerate() {
            *h = best.hit(i);
        }
    }

    /// The closest hits of the valid rays of `among` in `packet` (the others get none), the
    /// packet bounded with `prep`.
    ///
    /// # Safety
    /// As [`PacketPrep::prepare_rows`].
    #[inline(always)]
    unsafe fn closest_of_packet<P: PacketPrep, C: Counters>(
        &self,
        prep: P,
        packet: &mut PacketRays,
        among: u32,
        counters: &mut C,
    ) -> PacketBest {
        let mut best = PacketBest::new(&packet.t_max);
        let among = among & packet.valid;
        if among == 0 || self.nodes().is_empty() {
            return best;
        }
        if !packet::fits(self.depth()) {
            for i in (0..PACKET).filter(|&i| among >> i & 1 != 0) {
                if let Some(hit) = self.closest_hit_of_valid(&packet.ray(i), counters, NoFilter) {
                    best.offer(i, hit);
                }
            }
            return best;
        }
        // The rays that pass beside the tree's box are dropped first, as a single ray is: a
        // packet none of whose rays enters costs that test and no node.
        // SAFETY (the three preparation steps): the caller's guarantee.
        let limits = unsafe { prep.limits(packet) };
        let active = among & unsafe { prep.may_enter(packet, &self.bounds(), &limits) };
        if active == 0 {
            return best;
        }
        unsafe { prep.bound(packet, active) };
        #[cfg(target_arch = "x86_64")]
        match self.isa() {
            Isa::Avx512 => {
                let mut leaves = TrianglePacket::new(self, packet, limits, WholePacket::<Avx512Block>::new(active));
                // SAFETY: the structure's instruction set is one the processor has (see `Isa`).
                unsafe { dispatch::closest_packet_avx512(self.nodes(), packet, active, &mut leaves, counters) };
                leaves.settle_closest(counters);
                return leaves.best;
            }
            Isa::Avx2 => {
                let mut leaves = TrianglePacket::new(self, packet, limits, WholePacket::<Avx2Block>::new(active));
                dispatch::closest_packet(Isa::Avx2, self.nodes(), packet, active, &mut leaves, counters);
                leaves.settle_closest(counters);
                return leaves.best;
            }
            Isa::Portable => {}
        }
        let mut leaves = TrianglePacket::new(self, packet, limits, RayByRay);
        dispatch::closest_packet(self.isa(), self.nodes(), packet, active, &mut leaves, counters);
        leaves.best
    }

    /// The closest hit of each ray of `rays` in the lanes of `active` (bit per lane), as
    /// [`TriangleBvh::closest_hit`] gives it for that lane's ray ([`RayPacket::ray`]): the rays
    /// walk the tree as one packet (see [`TriangleBvh::closest_hit_packet`]), straight from
    /// their rows. Lanes outside `active`, and lanes whose rays are not valid, get no hit.
    ///
    /// ```
    /// use englobe::{NoCount, RayPacket, TriangleBvh, Vec3};
    ///
    /// let bvh = TriangleBvh::from_triangles(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
    /// let mut rays = RayPacket::default();
    /// for lane in 0..4 {
    ///     rays.set(lane, Vec3::new(0.1 * lane as f32, 0.1, 1.0), -Vec3::Z, 0.0, f32::INFINITY);
    /// }
    /// let hits = bvh.closest_hit_ray_packet(&rays, 0b1111, &mut NoCount);
    /// assert_eq!(hits.mask(), 0b1111);
    /// assert_eq!(hits.t[2], 1.0);
    /// ```
    pub fn closest_hit_ray_packet<C: Counters>(&self, rays: &RayPacket, active: u32, counters: &mut C) -> PacketHits {
        let best = self.closest_query(PacketSource::Rows(rays), active, counters);
        PacketHits { t: best.t.0, u: best.u.0, v: best.v.0, prim: best.prim.0.map(f32::to_bits) }
    }

    /// The lanes of `active` whose rays hit anything, as [`TriangleBvh::any_hit`] tells it for
    /// each (see [`TriangleBvh::closest_hit_ray_packet`]).
    pub fn any_hit_ray_packet<C: Counters>(&self, rays: &RayPacket, active: u32, counters: &mut C) -> u32 {
        self.any_query(PacketSource::Rows(rays), active, counters)
    }

    /// One packet of 1 to [`PACKET`] rays.
    fn any_packet_of<C: Counters>(&self, rays: &[Ray], mask: &mut [bool], counters: &mut C) {
        debug_assert!(rays.len() <= PACKET && rays.len() == mask.len());
        let hit = self.any_packet_among(rays, u32::MAX, counters);
        for (i, m) in mask.iter_mut().enumerate() {
            *m = hit >> i & 1 != 0;
        }
    }

    /// The valid rays of `among` (bits of a packet of 1 to [`PACKET`] rays) that hit something.
    pub(crate) fn any_packet_among<C: Counters>(&self, rays: &[Ray], among: u32, counters: &mut C) -> u32 {
        debug_assert!(rays.len() <= PACKET);
        self.any_query(PacketSource::Slice(rays), among, counters)
    }

    /// The closest hits of the valid rays of `among` in `source`, the whole query (the rays'
    /// preparation included) compiled for the structure's instruction set (see
    /// [`dispatch::packet_query`]).
    fn closest_query<C: Counters>(&self, source: PacketSource, among: u32, counters: &mut C) -> PacketBest {
        dispatch::packet_query(self.isa(), PacketJob::<C, ClosestHits>::new(self, source, among, counters))
    }

    /// The valid rays of `among` in `source` that hit something (see [`TriangleBvh::closest_query`]).
    fn any_query<C: Counters>(&self, source: PacketSource, among: u32, counters: &mut C) -> u32 {
        dispatch::packet_query(self.isa(), PacketJob::<C, AnyHit>::new(self, source, among, counters))
    }

    /// The valid rays of `among` in `packet` that hit something (see
    /// [`TriangleBvh::closest_of_packet`]).
    ///
    /// # Safety
    /// As [`PacketPrep::prepare_rows`].
    #[inline(always)]
    unsafe fn any_of_packet<P: PacketPrep, C: Counters>(
        &self,
        prep: P,
        packet: &mut PacketRays,
        among: u32,
        counters: &mut C,
    ) -> u32 {
        let among = among & packet.valid;
        if among == 0 || self.nodes().is_empty() {
            return 0;
        }
        if !packet::fits(self.depth()) {
            return (0..PACKET)
                .filter(|&i| among >> i & 1 != 0 && self.any_hit_of_valid(&packet.ray(i), counters, NoFilter))
                .fold(0, |m, i| m | 1 << i);
        }
        // The rays that pass beside the tree's box are dropped first, as a single ray is: a
        // packet none of whose rays enters costs that test and no node.
        // SAFETY (the three preparation steps): the caller's guarantee.
        let limits = unsafe { prep.limits(packet) };
        let active = among & unsafe { prep.may_enter(packet, &self.bounds(), &limits) };
        if active == 0 {
            return 0;
        }
        unsafe { prep.bound(packet, active) };
        #[cfg(target_arch = "x86_64")]
        match self.isa() {
            Isa::Avx512 => {
                let mut leaves = TrianglePacket::new(self, packet, limits, WholePacket::<Avx512Block>::new(active));
                // SAFETY: the structure's instruction set is one the processor has (see `Isa`).
                let found = unsafe { dispatch::any_packet_avx512(self.nodes(), packet, active, &mut leaves, counters) };
                return leaves.settle_any(found, counters);
            }
            Isa::Avx2 => {
                let mut leaves = TrianglePacket::new(self, packet, limits, WholePacket::<Avx2Block>::new(active));
                let found = dispatch::any_packet(Isa::Avx2, self.nodes(), packet, active, &mut leaves, counters);
                return leaves.settle_any(found, counters);
            }
            Isa::Portable => {}
        }
        let mut leaves = TrianglePacket::new(self, packet, limits, RayByRay);
        dispatch::any_packet(self.isa(), self.nodes(), packet, active, &mut leaves, counters)
    }
}

/// Where a packet's rays come from.
#[derive(Clone, Copy)]
enum PacketSource<'a> {
    /// Rows, as [`RayPacket`] holds them.
    Rows(&'a RayPacket),
    /// One to [`PACKET`] rays.
    Slice(&'a [Ray]),
}

impl PacketSource<'_> {
    /// The rays prepared for the walk, valid only in `among`, written into `packet`, which is
    /// [`PacketRays::EMPTY`]. (In place: a packet made and then moved there was copied, a kilobyte
    /// per query, by a call to `memcpy` that waited for the stores just made.)
    ///
    /// # Safety
    /// As [`PacketPrep::prepare_rows`].
    #[inline(always)]
    unsafe fn prepare_into<P: PacketPrep>(self, prep: P, among: u32, packet: &mut PacketRays) {
        match self {
            // SAFETY: the caller's guarantee.
            PacketSource::Rows(rows) => unsafe { prep.prepare_rows(rows, among, packet) },
            // The rays' checks come with their transposition, four at a time.
            PacketSource::Slice(rays) => packet.fill(rays),
        }
    }
}

/// A packet query as [`dispatch::packet_query`] runs it: the rays prepared (checked, inverted,
/// bounded), then walked for their closest hits ([`ClosestHits`]) or for any hit ([`AnyHit`]).
struct PacketJob<'a, C, K> {
    bvh: &'a TriangleBvh,
    source: PacketSource<'a>,
    among: u32,
    counters: &'a mut C,
    kind: PhantomData<K>,
}

/// A [`PacketJob`] for the closest hits.
struct ClosestHits;

/// A [`PacketJob`] for the rays that hit anything.
struct AnyHit;

impl<'a, C, K> PacketJob<'a, C, K> {
    fn new(bvh: &'a TriangleBvh, source: PacketSource<'a>, among: u32, counters: &'a mut C) -> Self {
        PacketJob { bvh, source, among, counters, kind: PhantomData }
    }
}

impl<C: Counters> dispatch::PacketQuery for PacketJob<'_, C, ClosestHits> {
    type Output = PacketBest;

    #[inline(always)]
    unsafe fn run<P: PacketPrep>(self, prep: P) -> PacketBest {
        let mut packet = PacketRays::EMPTY;
        // SAFETY: `run`'s guarantee.
        unsafe {
            self.source.prepare_into(prep, self.among, &mut packet);
            self.bvh.closest_of_packet(prep, &mut packet, self.among, self.counters)
        }
    }
}

impl<C: Counters> dispatch::PacketQuery for PacketJob<'_, C, AnyHit> {
    type Output = u32;

    #[inline(always)]
    unsafe fn run<P: PacketPrep>(self, prep: P) -> u32 {
        let mut packet = PacketRays::EMPTY;
        // SAFETY: `run`'s guarantee.
        unsafe {
            self.source.prepare_into(prep, self.among, &mut packet);
            self.bvh.any_of_packet(prep, &mut packet, self.among, self.counters)
        }
    }
}
