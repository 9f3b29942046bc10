//! Batches and packets of a [`World`]'s two queries over slices of rays. A packet of up to
//! sixteen rays walks the meshes' triangle tree together ([`TriangleBvh::closest_hit_packet`]),
//! then the top level over the shapes and instances together (`packet.rs`: each ray tests the
//! leaves it reaches alone), then each ray goes on alone through the planes, exactly as its
//! single-ray query does: the same answers, ray for ray. Batches take sixteen rays at a time, in
//! a packet when they are coherent, split across threads when large
//! ([`crate::accel::interface::batch`]); no allocation per ray.
//!
//! [`TriangleBvh::closest_hit_packet`]: crate::TriangleBvh::closest_hit_packet

use super::query::beats;
use super::{World, WorldHit};
use crate::Ray;
use crate::accel::interface::batch::{run_batch_packets, run_packets};
use crate::accel::wide::packet_kernels::PACKET;
use crate::accel::wide::triangle_packet::{coherent, valid_mask};
use crate::accel::{BatchSizeMismatch, Counters, NoCount, NoFilter};

impl World {
    /// The closest hit of every ray, `hits[i]` for `rays[i]` ([`World::closest_hit`]); sixteen
    /// rays at a time, in a packet when they are coherent. The two slices must be as long.
    ///
    /// ```
    /// use englobe::{AccelKind, Ray, Sphere, Vec3, World};
    ///
    /// let world = World::build(vec![Sphere::new(Vec3::new(0.0, 0.0, 5.0), 1.0).into()], AccelKind::BvhWide)?;
    /// let rays: Vec<Ray> = (0..5000).map(|i| Ray::new(Vec3::new(i as f32 * 1e-3, 0.0, 0.0), Vec3::Z)).collect();
    /// let mut hits = vec![None; rays.len()];
    /// world.closest_hits(&rays, &mut hits)?;
    /// assert_eq!(hits[0].map(|h| h.t), Some(4.0));
    /// assert!(hits[4999].is_none(), "x = 5 passes beside the sphere");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn closest_hits(&self, rays: &[Ray], hits: &mut [Option<WorldHit>]) -> Result<(), BatchSizeMismatch> {
        run_batch_packets(
            rays,
            hits,
            PACKET,
            |rays| self.coherent(rays),
            |rays, hits| self.closest_packet_of(rays, hits, &mut NoCount),
            |r| self.closest_hit(r, &mut NoCount),
        )
    }

    /// Whether each ray hits anything within its interval, `mask[i]` for `rays[i]`
    /// ([`World::any_hit`]); sixteen rays at a time, in a packet when they are coherent. The two
    /// slices must be as long.
    pub fn any_hits(&self, rays: &[Ray], mask: &mut [bool]) -> Result<(), BatchSizeMismatch> {
        run_batch_packets(
            rays,
            mask,
            PACKET,
            |rays| self.coherent(rays),
            |rays, mask| self.any_packet_of(rays, mask, &mut NoCount),
            |r| self.any_hit(r, &mut NoCount),
        )
    }

    /// [`World::closest_hit`] of every ray, the meshes' triangles tested in packets of sixteen
    /// consecutive rays (see the module documentation): for coherent rays, such as a camera's
    /// in square tiles. The two slices must be as long.
    pub fn closest_hit_packet<C: Counters>(
        &self,
        rays: &[Ray],
        hits: &mut [Option<WorldHit>],
        counters: &mut C,
    ) -> Result<(), BatchSizeMismatch> {
        run_packets(rays, hits, PACKET, |rays, hits| self.closest_packet_of(rays, hits, counters))
    }

    /// [`World::any_hit`] of every ray, in packets of sixteen (see
    /// [`World::closest_hit_packet`]).
    pub fn any_hit_packet<C: Counters>(
        &self,
        rays: &[Ray],
        mask: &mut [bool],
        counters: &mut C,
    ) -> Result<(), BatchSizeMismatch> {
        run_packets(rays, mask, PACKET, |rays, mask| self.any_packet_of(rays, mask, counters))
    }

    /// Whether packet queries walk a structure of this world with their rays together: the fast
    /// path's triangle tree, or its top level over shapes and instances. Otherwise
    /// [`World::closest_hit_packet`] traces each ray alone, and a renderer may as well.
    pub fn walks_packets(&self) -> bool {
        self.triangles.is_some() || self.packet_top().is_some()
    }

    /// Whether `rays` are worth a packet: the world has a structure packets walk, and the rays
    /// are coherent at its scale.
    fn coherent(&self, rays: &[Ray]) -> bool {
        self.walks_packets() && coherent(rays, &self.bounds())
    }

    /// One packet of at most [`PACKET`] rays. Every step below answers `None` for the rays that
    /// are not valid, and the hits are kept in `hits` from the first step to the last.
    fn closest_packet_of<C: Counters>(&self, rays: &[Ray], hits: &mut [Option<WorldHit>], counters: &mut C) {
        let n = rays.len();
        if n == 0 {
            return;
        }
        let valid = valid_mask(rays);
        match &self.triangles {
            Some(t) => {
                let mut meshes = [None; PACKET];
                t.closest_packet_among(rays, valid, &mut meshes[..n], counters);
                for (h, m) in hits.iter_mut().zip(meshes) {
                    *h = m.map(|m| self.mesh_hit(m));
                }
            }
            None => hits.fill(None),
        }
        let top = self.packet_top();
        if let Some(top) = top {
            // The shapes and instances in a packet too, each ray up to its closest mesh hit.
            let mut t_max = [0.0; PACKET];
            for ((t, h), ray) in t_max.iter_mut().zip(hits.iter()).zip(rays) {
                *t = h.map_or(ray.t_max, |h| h.t);
            }
            let mut found = [None; PACKET];
            self.accel_closest_packet(top, rays, &t_max[..n], valid, &mut found[..n], counters);
            for (h, hit) in hits.iter_mut().zip(found) {
                if let Some(hit) = hit
                    && beats(&hit, h.as_ref())
                {
                    *h = Some(hit);
                }
            }
        } else if self.accel_in_use() {
            // Shapes or instances in a top level too deep for a packet: each ray alone.
            for (i, (h, ray)) in hits.iter_mut().zip(rays).enumerate() {
                if valid >> i & 1 != 0 {
                    *h = self.closest_in_accel(ray, *h, counters, &mut NoFilter);
                }
            }
        }
        self.closest_unbounded_packet(rays, valid, hits, counters);
    }

    /// One packet of at most [`PACKET`] rays: the unbounded shapes first, as [`World::any_hit`]
    /// tests them, then the meshes for the rays still unblocked, then the rest.
    fn any_packet_of<C: Counters>(&self, rays: &[Ray], mask: &mut [bool], counters: &mut C) {
        let valid = valid_mask(rays);
        let mut blocked = self.any_unbounded_packet(rays, valid, counters);
        if let Some(t) = &self.triangles {
            blocked |= t.any_packet_among(rays, valid & !blocked, counters);
        }
        if let Some(top) = self.packet_top() {
            let pending = valid & !blocked;
            if pending != 0 {
                blocked |= self.accel_any_packet(top, rays, pending, counters);
            }
        } else if self.accel_in_use() {
            for (i, ray) in rays.iter().enumerate() {
                if (valid & !blocked) >> i & 1 != 0 && self.any_in_accel(ray, counters, &mut NoFilter) {
                    blocked |= 1 << i;
                }
            }
        }
        for (i, m) in mask.iter_mut().enumerate() {
            *m = blocked >> i & 1 != 0;
        }
    }
}
