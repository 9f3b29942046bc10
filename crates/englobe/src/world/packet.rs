//! Packets through the top level of the fast path: up to sixteen rays walk [`World::accel`], the
//! wide BVH over the shapes and instances, together ([`crate::accel::wide::packet`]), one node
//! test for the whole packet. At a leaf, each ray that reached it tests the leaf's shapes and
//! instances alone, an instance's bottom-level tree walked by the single-ray query. This is the
//! two-level hierarchy of Wald, Benthin and Slusallek (2003), "A Simple and Practical Method for
//! Interactive Ray Tracing of Dynamic Scenes", with packets at its top.
//!
//! Why not packets below as well: an instance is small beside the packet's spread. On the bunny
//! field (1000 instances, 320x180 pixels to 960x540) the rays of a 4x4 packet that reach a bunny
//! part at its first nodes, so a bottom packet walk paid its set-up (the rays moved into the
//! mesh's space together, their packet state) for nothing: measured, it executed 7-19 % more
//! instructions (AVX2) than rays walking the bottom level alone, and ran no faster.
//!
//! Each ray keeps what its single-ray query keeps, its [`HitRecord`] and its instance's triangle
//! ([`ClosestInstance`]), and is offered the same hits under the same rule, so its answer is its
//! own query's, bit for bit, whatever order the packet visits the leaves in.

use super::bottom::ClosestInstance;
use super::{World, WorldHit};
use crate::Ray;
use crate::accel::wide::dispatch;
use crate::accel::wide::node::reach;
use crate::accel::wide::packet::{self, PacketLeaves};
use crate::accel::wide::packet_kernels::{Lanes, PACKET, PacketRays};
use crate::accel::{AnyAccel, Counters, HitRecord, NoFilter, WideBvh};

/// The rays of a packet on the top level, each with its single-ray query's state.
struct TopPacket<'a> {
    world: &'a World,
    top: &'a WideBvh,
    /// Each ray, shrunk to its closest hit so far, and that hit (on a primitive of the top level).
    records: [HitRecord; PACKET],
    /// Each ray's closest instance hit, with its triangle.
    instances: [ClosestInstance; PACKET],
    /// How far each ray may still enter a box ([`reach`] of its closest hit so far).
    limits: Lanes,
}

/// The lanes of `mask`, lowest first.
#[inline(always)]
fn lanes(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            i
        })
    })
}

impl<'a> TopPacket<'a> {
    /// The state of 1 to [`PACKET`] rays (the lanes beyond hold copies of the last, never asked
    /// for): no hit yet. Inlined, so that the state (over a kilobyte) is built where the query
    /// keeps it rather than copied there.
    #[inline(always)]
    fn new(world: &'a World, top: &'a WideBvh, rays: &[Ray]) -> Self {
        let len = rays.len();
        debug_assert!((1..=PACKET).contains(&len), "a packet holds 1 to {PACKET} rays");
        // Filled by plain copies, the last ray first in every lane: `std::array::from_fn` was
        // not inlined here and built each record in a temporary first, one partly overlapping
        // store and load after another.
        let last = rays[len - 1];
        let mut packet = TopPacket {
            world,
            top,
            records: [HitRecord::new(last); PACKET],
            instances: [ClosestInstance::default(); PACKET],
            limits: Lanes([reach(last.t_max); PACKET]),
        };
        for (i, ray) in rays.iter().enumerate() {
            packet.records[i] = HitRecord::new(*ray);
            packet.limits.0[i] = reach(ray.t_max);
        }
        packet
    }
}

impl<C: Counters> PacketLeaves<C> for TopPacket<'_> {
    #[inline(always)]
    fn closest(&mut self, first: u32, count: u32, rays: u32, counters: &mut C) {
        let world = self.world;
        for &i in &self.top.prim_indices()[first as usize..(first + count) as usize] {
            for l in lanes(rays) {
                counters.exact_test();
                let (record, instances) = (&mut self.records[l], &mut self.instances[l]);
                if let Some(hit) =
                    world.accel_item_closest(i, &record.ray, &mut None, counters, instances, &mut NoFilter)
                    && record.offer(i, hit)
                {
                    self.limits.0[l] = reach(hit.t);
                }
            }
        }
    }

    #[inline(always)]
    fn any(&mut self, first: u32, count: u32, rays: u32, counters: &mut C) -> u32 {
        let world = self.world;
        let mut found = 0;
        for &i in &self.top.prim_indices()[first as usize..(first + count) as usize] {
            let pending = rays & !found;
            if pending == 0 {
                break;
            }
            for l in lanes(pending) {
                counters.exact_test();
                if world.accel_item_any(i, &self.records[l].ray, &mut None, counters, &mut NoFilter) {
                    found |= 1 << l;
                }
            }
        }
        found
    }

    #[inline(always)]
    fn limits(&self) -> &Lanes {
        &self.limits
    }

    #[inline(always)]
    fn prefetch(&self, _first: u32) {}

    #[inline(never)]
    fn alone(&mut self, reference: u32, rays: u32, closest: bool, counters: &mut C) -> u32 {
        let (world, top) = (self.world, self.top);
        let mut found = 0;
        for l in lanes(rays) {
            // Work inside instances is counted apart while the walk holds `counters`, as the
            // single-ray query does.
            let mut nested = C::default();
            let mut watertight = None;
            if closest {
                let instances = &mut self.instances[l];
                self.records[l] = top.closest_from(reference, self.records[l], counters, |i, r| {
                    world.accel_item_closest(i, r, &mut watertight, &mut nested, instances, &mut NoFilter)
                });
                self.limits.0[l] = reach(self.records[l].ray.t_max);
            } else if top.any_from(reference, &self.records[l].ray, counters, |i, r| {
                world.accel_item_any(i, r, &mut watertight, &mut nested, &mut NoFilter)
            }) {
                found |= 1 << l;
            }
            counters.merge(&nested);
        }
        found
    }
}

impl World {
    /// The top level's wide BVH, if packets can walk it: the fast path, with shapes or instances
    /// beside the plain meshes, in a tree shallow enough for a packet's stack.
    pub(super) fn packet_top(&self) -> Option<&WideBvh> {
        match &self.accel {
            AnyAccel::BvhWide(top) if self.accel_in_use() && !top.nodes().is_empty() && packet::fits(top.depth()) => {
                Some(top)
            }
            _ => None,
        }
    }

    /// The closest hit on the top level `top` of each ray of `among` (valid rays of 1 to
    /// [`PACKET`]), within `t_max[i]` for ray `i`: `out[i]`, as [`World::accel_closest_hit`]
    /// gives it. The others get `None`.
    pub(super) fn accel_closest_packet<C: Counters>(
        &self,
        top: &WideBvh,
        rays: &[Ray],
        t_max: &[f32],
        among: u32,
        out: &mut [Option<WorldHit>],
        counters: &mut C,
    ) {
        let len = rays.len();
        let bounded: [Ray; PACKET] = std::array::from_fn(|i| {
            let i = i.min(len - 1);
            rays[i].with_range(rays[i].t_min, t_max[i])
        });
        let bounded = &bounded[..len];
        let mut leaves = TopPacket::new(self, top, bounded);
        let mut packet = PacketRays::new(bounded);
        packet.bound(among);
        dispatch::closest_packet(top.isa(), top.nodes(), &packet, among, &mut leaves, counters);
        for (i, o) in out.iter_mut().enumerate() {
            let record = &leaves.records[i];
            *o = record
                .hit
                .filter(|_| among >> i & 1 != 0)
                .map(|h| self.accel_world_hit(&bounded[i], h, &leaves.instances[i], &mut NoFilter));
        }
    }

    /// The rays of `among` (valid rays of 1 to [`PACKET`]) that hit a primitive of the top level
    /// `top`, as [`World::any_in_accel`] tells it.
    pub(super) fn accel_any_packet<C: Counters>(
        &self,
        top: &WideBvh,
        rays: &[Ray],
        among: u32,
        counters: &mut C,
    ) -> u32 {
        let mut leaves = TopPacket::new(self, top, rays);
        let mut packet = PacketRays::new(rays);
        packet.bound(among);
        dispatch::any_packet(top.isa(), top.nodes(), &packet, among, &mut leaves, counters)
    }
}
