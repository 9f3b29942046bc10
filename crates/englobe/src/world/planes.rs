//! The unbounded shapes (planes) of a packet's rays. Each plane's parameter is computed for all
//! the rays first, with no branch between them, so that their divisions overlap rather than wait
//! on each other behind the hit-or-miss branches; then each ray's answer is decided plane after
//! plane exactly as its single-ray query decides it (`query.rs`): the same numbers, the same
//! order, the same work counted.

use super::query::beats;
use super::{World, WorldHit};
use crate::Ray;
use crate::accel::Counters;
use crate::accel::wide::packet_kernels::PACKET;
use crate::shapes::Plane;

impl World {
    /// [`World::closest_unbounded`] of every ray of a packet of at most [`PACKET`] rays whose
    /// bit is set in `valid`: `best[i]`, the closest hit of `rays[i]` so far, becomes a plane's
    /// hit where one beats it.
    pub(super) fn closest_unbounded_packet<C: Counters>(
        &self,
        rays: &[Ray],
        valid: u32,
        best: &mut [Option<WorldHit>],
        counters: &mut C,
    ) {
        for &(object, plane) in &self.unbounded {
            let t = parameters(&plane, rays);
            for (i, (b, ray)) in best.iter_mut().zip(rays).enumerate() {
                if valid >> i & 1 == 0 {
                    continue;
                }
                counters.exact_test();
                // Within the ray's interval shrunk to its closest hit so far, as the single ray's.
                if Plane::hit_within(t[i], ray.t_min, b.map_or(ray.t_max, |b| b.t)) {
                    let hit = WorldHit { t: t[i], object, prim: 0, u: 0.0, v: 0.0 };
                    if beats(&hit, b.as_ref()) {
                        *b = Some(hit);
                    }
                }
            }
        }
    }

    /// The rays among those whose bit is set in `among` (of a packet of at most [`PACKET`])
    /// that a plane blocks, as a mask: [`World::any_unbounded`] of each, whose tests stop at the
    /// first plane that blocks the ray.
    pub(super) fn any_unbounded_packet<C: Counters>(&self, rays: &[Ray], among: u32, counters: &mut C) -> u32 {
        let mut blocked = 0;
        for (_, plane) in &self.unbounded {
            let t = parameters(plane, rays);
            for (i, ray) in rays.iter().enumerate() {
                if (among & !blocked) >> i & 1 != 0 {
                    counters.exact_test();
                    if Plane::hit_within(t[i], ray.t_min, ray.t_max) {
                        blocked |= 1 << i;
                    }
                }
            }
        }
        blocked
    }
}

/// The parameter of each ray's crossing of `plane` (see [`Plane::parameter`]).
#[inline(always)]
fn parameters(plane: &Plane, rays: &[Ray]) -> [f32; PACKET] {
    let mut t = [f32::NAN; PACKET];
    for (t, ray) in t.iter_mut().zip(rays) {
        *t = plane.parameter(ray);
    }
    t
}
