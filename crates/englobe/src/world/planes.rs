//! The unbounded shapes (planes), tested beside the structures: for one ray, and for the rays of
//! a packet side by side. A packet computes each plane's parameter for all its rays first, with no
//! branch between them, so that their divisions overlap rather than wait on each other behind the
//! hit-or-miss branches; then each ray's answer is decided plane after plane by the same decision
//! as its single-ray query: the same numbers, the same order, the same work counted.

use super::query::beats;
use super::{World, WorldHit};
use crate::Ray;
use crate::accel::wide::packet_kernels::PACKET;
use crate::accel::{Counters, HitFilter, NoFilter};
use crate::shapes::Plane;

impl World {
    /// The closest hit of a valid `ray`, given `best`, its closest hit on the bounded primitives:
    /// the planes' hits that beat it, among those `filter` accepts.
    #[inline(always)]
    pub(super) fn closest_unbounded<C: Counters, F: HitFilter<WorldHit>>(
        &self,
        ray: &Ray,
        mut best: Option<WorldHit>,
        counters: &mut C,
        filter: &mut F,
    ) -> Option<WorldHit> {
        for &(object, plane) in &self.unbounded {
            counters.exact_test();
            offer(object, plane.parameter(ray), ray, &mut best, filter);
        }
        best
    }

    /// Whether a valid `ray` hits one of the planes, where `filter` accepts.
    #[inline]
    pub(super) fn any_unbounded<C: Counters, F: HitFilter<WorldHit>>(
        &self,
        ray: &Ray,
        counters: &mut C,
        filter: &mut F,
    ) -> bool {
        self.unbounded.iter().any(|&(object, plane)| {
            counters.exact_test();
            blocks(object, plane.parameter(ray), ray, filter)
        })
    }

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
                if valid >> i & 1 != 0 {
                    counters.exact_test();
                    offer(object, t[i], ray, b, &mut NoFilter);
                }
            }
        }
    }

    /// The rays among those whose bit is set in `among` (of a packet of at most [`PACKET`])
    /// that a plane blocks, as a mask: [`World::any_unbounded`] of each, whose tests stop at the
    /// first plane that blocks the ray.
    pub(super) fn any_unbounded_packet<C: Counters>(&self, rays: &[Ray], among: u32, counters: &mut C) -> u32 {
        let mut blocked = 0;
        for &(object, plane) in &self.unbounded {
            let t = parameters(&plane, rays);
            for (i, ray) in rays.iter().enumerate() {
                if (among & !blocked) >> i & 1 != 0 {
                    counters.exact_test();
                    if blocks(object, t[i], ray, &mut NoFilter) {
                        blocked |= 1 << i;
                    }
                }
            }
        }
        blocked
    }
}

/// Keeps in `best`, the closest hit of `ray` so far, the crossing at `t` of the plane that is
/// object `object` if it lies within the ray's interval shrunk to `best`, beats `best` (see
/// [`beats`]) and `filter` accepts it.
#[inline(always)]
fn offer<F: HitFilter<WorldHit>>(object: u32, t: f32, ray: &Ray, best: &mut Option<WorldHit>, filter: &mut F) {
    if Plane::hit_within(t, ray.t_min, best.map_or(ray.t_max, |b| b.t)) {
        let hit = WorldHit { t, object, prim: 0, u: 0.0, v: 0.0 };
        if beats(&hit, best.as_ref()) && (F::ACCEPTS_ALL || filter.accept(&hit)) {
            *best = Some(hit);
        }
    }
}

/// Whether the crossing at `t` of the plane that is object `object` blocks `ray`: within its
/// interval, where `filter` accepts.
#[inline(always)]
fn blocks<F: HitFilter<WorldHit>>(object: u32, t: f32, ray: &Ray, filter: &mut F) -> bool {
    Plane::hit_within(t, ray.t_min, ray.t_max)
        && (F::ACCEPTS_ALL || filter.accept(&WorldHit { t, object, prim: 0, u: 0.0, v: 0.0 }))
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
