//! Mailboxing: the memory, within one query, of the primitives already tested, so that a spatial
//! subdivision (grid, kd-tree), which references a primitive from every cell it overlaps, does not
//! test it again in the next cell the ray enters.
//!
//! The classic mailbox of Amanatides and Woo (1987), "A Fast Voxel Traversal Algorithm for Ray
//! Tracing" (Eurographics), stores a ray number in every primitive; that needs a write to shared
//! data per test, which a parallel renderer cannot afford. This one is the per-query alternative,
//! "hashed mailboxing" (Wald 2004, "Realtime Ray Tracing and Interactive Global Illumination", PhD
//! thesis, Saarland University): a small direct-mapped table on the query's stack, indexed by a
//! hash of the primitive index. A collision only forgets an earlier primitive, which is then
//! tested again: the answer never changes, only the work. Nothing is allocated and nothing is
//! shared between threads.
//!
//! Skipping a repeated test is exact for both queries: the ray's origin, direction and `t_min`
//! never change during a query and its `t_max` only shrinks, so a primitive that missed once
//! misses again, and one that was hit has already been offered to the query's record.

use std::ops::ControlFlow;

use super::contract::HitRecord;
use super::counters::Counters;
use crate::PrimHit;
use crate::Ray;

/// Entries of the table (a power of two).
pub const MAILBOX_SLOTS: usize = 64;

/// No primitive: indices are below `2^31` (see [`crate::accel::MAX_PRIMITIVES`]).
const VACANT: u32 = u32::MAX;

/// The primitives one query has tested recently.
#[derive(Clone, Debug)]
pub struct Mailbox {
    slots: [u32; MAILBOX_SLOTS],
    enabled: bool,
}

impl Mailbox {
    /// An empty mailbox; a disabled one remembers nothing (every reference is tested), for
    /// measuring what mailboxing saves.
    #[inline(always)]
    pub fn new(enabled: bool) -> Self {
        Mailbox { slots: [VACANT; MAILBOX_SLOTS], enabled }
    }

    /// True if `prim` was already tested in this query; otherwise remembers it and returns false.
    #[inline(always)]
    pub fn already_tested(&mut self, prim: u32) -> bool {
        if !self.enabled {
            return false;
        }
        // Fibonacci hashing spreads neighbouring indices (a mesh's neighbouring triangles, which a
        // cell holds together) over the table.
        let slot = (prim.wrapping_mul(0x9E37_79B9) >> (32 - MAILBOX_SLOTS.trailing_zeros())) as usize;
        let entry = &mut self.slots[slot];
        if *entry == prim {
            true
        } else {
            *entry = prim;
            false
        }
    }

    /// The closest-hit query's work in one leaf or cell: offers every primitive of `prims` not
    /// yet tested to `record`, and returns how far the walk must go on (the closest hit so far).
    #[inline(always)]
    pub fn closest_in<C: Counters>(
        &mut self,
        prims: &[u32],
        record: &mut HitRecord,
        counters: &mut C,
        intersect: &mut impl FnMut(u32, &Ray) -> Option<PrimHit>,
    ) -> ControlFlow<(), f32> {
        for &prim in prims {
            if self.already_tested(prim) {
                continue;
            }
            counters.exact_test();
            if let Some(hit) = intersect(prim, &record.ray) {
                record.offer(prim, hit);
            }
        }
        ControlFlow::Continue(record.ray.t_max)
    }

    /// The any-hit query's work in one leaf or cell: breaks at the first primitive of `prims`
    /// not yet tested that occludes `ray`.
    #[inline(always)]
    pub fn any_in<C: Counters>(
        &mut self,
        prims: &[u32],
        ray: &Ray,
        counters: &mut C,
        occludes: &mut impl FnMut(u32, &Ray) -> bool,
    ) -> ControlFlow<(), f32> {
        for &prim in prims {
            if self.already_tested(prim) {
                continue;
            }
            counters.exact_test();
            if occludes(prim, ray) {
                return ControlFlow::Break(());
            }
        }
        ControlFlow::Continue(ray.t_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn remembers_and_forgets_only_on_collision() {
        let mut m = Mailbox::new(true);
        assert!(!m.already_tested(7));
        assert!(m.already_tested(7));
        for p in 0..MAILBOX_SLOTS as u32 {
            m.already_tested(p + 1000);
        }
        // 64 other primitives later, 7 may have been evicted, never reported for another index.
        let mut other = Mailbox::new(true);
        assert!(!other.already_tested(8));
        let mut off = Mailbox::new(false);
        assert!(!off.already_tested(7) && !off.already_tested(7));
    }

    #[test]
    fn a_run_of_neighbouring_indices_fits() {
        let mut m = Mailbox::new(true);
        for p in 5000..5000 + 32u32 {
            assert!(!m.already_tested(p));
        }
        let kept = (5000..5000 + 32u32).filter(|&p| m.already_tested(p)).count();
        assert!(kept >= 28, "only {kept} of 32 neighbours kept");
    }
}
