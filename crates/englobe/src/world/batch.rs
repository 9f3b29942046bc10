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
use crate::accel::wide::triangle_packet::coherent;
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

    /// One packet of at most [`PACKET`] rays.
    fn closest_packet_of<C: Counters>(&self, rays: &[Ray], hits: &mut [Option<WorldHit>], counters: &mut C) {
        let mut meshes = [None; PACKET];
        let meshes = &mut meshes[..rays.len()];
        if let Some(t) = &self.triangles {
            t.closest_hit_packet(rays, meshes, counters).expect("as many places as rays");
        }
        let Some(top) = self.packet_top() else {
            for ((h, ray), mesh) in hits.iter_mut().zip(rays).zip(meshes.iter()) {
                *h = if ray.is_valid() {
                    self.closest_beyond_meshes(ray, mesh.map(|m| self.mesh_hit(m)), counters, &mut NoFilter)
                } else {
                    None
                };
            }
            return;
        };
        // The shapes and instances in a packet too, each ray up to its closest mesh hit.
        let mut best = [None; PACKET];
        let mut t_max = [0.0; PACKET];
        for (i, (ray, mesh)) in rays.iter().zip(meshes.iter()).enumerate() {
            best[i] = mesh.map(|m| self.mesh_hit(m));
            t_max[i] = best[i].map_or(ray.t_max, |b: WorldHit| b.t);
        }
        let valid = valid_mask(rays);
        let mut found = [None; PACKET];
        let n = rays.len();
        self.accel_closest_packet(top, rays, &t_max[..n], valid, &mut found[..n], counters);
        for (i, (h, ray)) in hits.iter_mut().zip(rays).enumerate() {
            if let Some(hit) = found[i]
                && beats(&hit, best[i].as_ref())
            {
                best[i] = Some(hit);
            }
            *h = if valid >> i & 1 != 0 { self.closest_unbounded(ray, best[i], counters, &mut NoFilter) } else { None };
        }
    }

    /// One packet of at most [`PACKET`] rays: the unbounded shapes first, as [`World::any_hit`]
    /// tests them, then the meshes for the rays still unblocked, then the rest.
    fn any_packet_of<C: Counters>(&self, rays: &[Ray], mask: &mut [bool], counters: &mut C) {
        for (m, ray) in mask.iter_mut().zip(rays) {
            *m = ray.is_valid() && self.any_unbounded(ray, counters, &mut NoFilter);
        }
        if let Some(t) = &self.triangles {
            let mut meshes = [false; PACKET];
            t.any_hit_packet(rays, &mut meshes[..rays.len()], counters).expect("as many places as rays");
            for (m, hit) in mask.iter_mut().zip(meshes) {
                *m |= hit;
            }
        }
        if let Some(top) = self.packet_top() {
            let pending = mask.iter().enumerate().fold(valid_mask(rays), |p, (i, &m)| p & !((m as u32) << i));
            if pending != 0 {
                let hit = self.accel_any_packet(top, rays, pending, counters);
                for (i, m) in mask.iter_mut().enumerate() {
                    *m |= hit >> i & 1 != 0;
                }
            }
            return;
        }
        for (m, ray) in mask.iter_mut().zip(rays) {
            *m = *m || (ray.is_valid() && self.any_in_accel(ray, counters, &mut NoFilter));
        }
    }
}

/// The valid rays of `rays` (at most [`PACKET`]), bit per ray.
fn valid_mask(rays: &[Ray]) -> u32 {
    rays.iter().enumerate().fold(0, |m, (i, r)| m | (r.is_valid() as u32) << i)
}
