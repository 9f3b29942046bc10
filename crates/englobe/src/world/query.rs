//! The two queries of a [`World`], closest hit and any hit, over its structures in turn: on the
//! fast path the plain meshes' triangles first (their closest hit bounds what follows), then the
//! structure over the other bounded primitives, whose closure tests shapes exactly and sends
//! instances down to their bottom level, then the unbounded shapes.
//!
//! Each step keeps the closest hit under one rule: closer, or as close on a lower object, or on
//! the same object a lower primitive. Primitives are numbered object after object, so that is the
//! rule every structure applies to primitive numbers ([`crate::accel::HitRecord::offer`]), and the
//! answer is brute force's whichever structure holds which primitive.

use super::bottom::ClosestInstance;
use super::{Object, World, WorldHit};
use crate::PrimHit;
use crate::Ray;
use crate::accel::{Accel, Counters, Hit};
use crate::shapes::{Instance, Intersect, WatertightRay};

/// Whether `hit` beats `best` under the rule of the module.
#[inline(always)]
fn beats(hit: &WorldHit, best: Option<&WorldHit>) -> bool {
    best.is_none_or(|b| hit.t < b.t || (hit.t == b.t && (hit.object, hit.prim) < (b.object, b.prim)))
}

impl World {
    /// The world's primitive number of primitive `i` of [`World::accel`].
    #[inline(always)]
    fn accel_prim(&self, i: u32) -> u32 {
        self.accel_prims.as_ref().map_or(i, |p| p[i as usize])
    }

    /// The closest hit of `ray` (in world space) with the mesh of `inst`, object `object`: `prim`
    /// of the answer is the triangle, `t` is the world ray's parameter.
    #[inline]
    fn instance_closest_hit<C: Counters>(&self, object: u32, inst: &Instance, ray: &Ray, c: &mut C) -> Option<Hit> {
        self.bottom[self.object_bottom[object as usize] as usize].closest_hit(&inst.local_ray(ray), c)
    }

    /// Whether `ray` hits the mesh of `inst` within its interval.
    #[inline]
    fn instance_any_hit<C: Counters>(&self, object: u32, inst: &Instance, ray: &Ray, c: &mut C) -> bool {
        self.bottom[self.object_bottom[object as usize] as usize].any_hit(&inst.local_ray(ray), c)
    }

    /// The closest hit, or `None`. Ties at equal `t` go to the lower object (then primitive) index.
    pub fn closest_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> Option<WorldHit> {
        if !ray.is_valid() {
            return None;
        }
        let mut best = self.triangles.as_ref().and_then(|t| t.closest_hit(ray, counters)).map(|h| {
            let (object, prim) = self.locate(h.prim);
            WorldHit { t: h.t, object, prim, u: h.u, v: h.v }
        });
        // Work inside instances is counted apart (the structure holds `counters` during its query)
        // and merged afterwards.
        let mut nested = C::default();
        let mut instance_hits = ClosestInstance::default();
        // Only the teaching structures test mesh triangles through their closure.
        let mut watertight = None;
        let bounded = ray.with_range(ray.t_min, best.map_or(ray.t_max, |b| b.t));
        let found = self.accel.closest_hit(&bounded, counters, |i, r| {
            let (object, local) = self.locate(self.accel_prim(i));
            match &self.objects[object as usize] {
                Object::Shape(s) => s.intersect(r),
                Object::Mesh(m) => {
                    m.intersect_with(local, r, watertight.get_or_insert_with(|| WatertightRay::new(ray)))
                }
                Object::Instance(inst) => {
                    let hit = self.instance_closest_hit(object, inst, r, &mut nested)?;
                    instance_hits.offer(i, &hit);
                    Some(PrimHit { t: hit.t, u: hit.u, v: hit.v })
                }
            }
        });
        counters.merge(&nested);
        if let Some(h) = found {
            let (object, local) = self.locate(self.accel_prim(h.prim));
            let prim = match &self.objects[object as usize] {
                Object::Instance(inst) => instance_hits.triangle(h.prim, h.t).unwrap_or_else(|| {
                    // Only a structure that breaks the tie rule of `HitRecord::offer` gets here:
                    // ask the instance again, up to the hit.
                    let r = ray.with_range(ray.t_min, h.t);
                    self.instance_closest_hit(object, inst, &r, &mut C::default()).map_or(0, |x| x.prim)
                }),
                _ => local,
            };
            let hit = WorldHit { t: h.t, object, prim, u: h.u, v: h.v };
            if beats(&hit, best.as_ref()) {
                best = Some(hit);
            }
        }
        let mut bounded = ray.with_range(ray.t_min, best.map_or(ray.t_max, |b| b.t));
        for &object in &self.unbounded {
            counters.exact_test();
            let Object::Shape(shape) = &self.objects[object as usize] else { continue };
            if let Some(h) = shape.intersect(&bounded) {
                let hit = WorldHit { t: h.t, object, prim: 0, u: h.u, v: h.v };
                if beats(&hit, best.as_ref()) {
                    bounded.t_max = h.t;
                    best = Some(hit);
                }
            }
        }
        best
    }

    /// Whether anything is hit within the ray's interval (shadow rays).
    pub fn any_hit<C: Counters>(&self, ray: &Ray, counters: &mut C) -> bool {
        if !ray.is_valid() {
            return false;
        }
        let unbounded_hit = self.unbounded.iter().any(|&object| {
            counters.exact_test();
            match &self.objects[object as usize] {
                Object::Shape(s) => s.intersect(ray).is_some(),
                Object::Mesh(_) | Object::Instance(_) => false,
            }
        });
        if unbounded_hit || self.triangles.as_ref().is_some_and(|t| t.any_hit(ray, counters)) {
            return true;
        }
        let mut nested = C::default();
        let mut watertight = None;
        let hit = self.accel.any_hit(ray, counters, |i, r| {
            let (object, local) = self.locate(self.accel_prim(i));
            match &self.objects[object as usize] {
                Object::Shape(s) => s.intersect(r).is_some(),
                Object::Mesh(m) => {
                    m.intersect_with(local, r, watertight.get_or_insert_with(|| WatertightRay::new(ray))).is_some()
                }
                Object::Instance(inst) => self.instance_any_hit(object, inst, r, &mut nested),
            }
        });
        counters.merge(&nested);
        hit
    }
}
